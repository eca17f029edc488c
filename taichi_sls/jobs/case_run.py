"""The main job: run one case to its end (``time.stop``), writing every output.

A short pipeline: build the simulation, settle or resume, then the run loop
(jobs/run_loop.py: ``advance_to`` each frame time, hand the frame to each observer), then each
observer's ``finish``. The observers (jobs/observers/) write the output folder (default
``out/<case name>/``): ``frames/*.png``, ``animation.gif``, ``timeseries.csv`` (one row per
output frame), ``timeseries.png``, ``outcome.png``, ``summary.json`` (with the pair's fusion
``outcome``), the resolved ``case.toml`` and, with ``output.vtu = true``, ParaView point data.
A case of more than two bodies (a bed) has its verdict per contact instead: ``contacts.csv``
and ``contacts.png``, the summary's ``bed`` record (jobs/bed_outcome.py), the bed's own columns
of the time series and plots (io/series.BED_PANELS, io/bed_outcome_plot.py), and
``layer.npz``, its points at the end (``bed.previous_layer`` of a next layer). Every file is
written atomically; an interrupted or failed run still leaves valid files and a summary that
says so. An interrupted run draws nothing more (no GIF, plots or layer file).
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ..config import Case, case_to_toml
from ..io.painter import frame_painter
from ..io.writer import OutputWriter
from ..solver import compile_clock
from ..solver.guard import SimulationError
from ..solver.scene import Scene
from ..solver.simulation import Simulation
from .bed_outcome import describe_bed, is_bed
from .observers.checkpoints import CHECKPOINT, Checkpoints, resume
from .observers.contacts import Contacts
from .observers.frames import Frames
from .observers.layer_file import LayerFile
from .observers.progress import ProgressBar
from .observers.record import Record
from .observers.series import TimeSeries
from .observers.stop_rule import StopRule
from .observers.verdict import PairVerdict
from .observers.warnings import InertiaWarning
from .outcome import describe
from .run_loop import Frame, Observer, Pacer, RunEnd, StopRequests, named_monitors, run_frames
from .schedule import frame_times
from .settle import settle
from .unheated import needs_baseline, unheated_neck_um

# statuses: complete (end_s reached, or solidified and settled), max_time (stop = solidified
# gave up at time.max_s), failed (the guard), interrupted (Ctrl-C, SIGTERM)
STATUSES = ("complete", "max_time", "failed", "interrupted")


def run_case(
    case: Case,
    out_dir: str | Path,
    *,
    progress: bool = True,
    checkpoint_every: int = 0,
    resume: Path | None = None,
    scene: Scene | None = None,
    before_step: Callable[[Simulation], None] | None = None,
    observers: Sequence[Observer] = (),
) -> dict[str, Any]:
    """Run one case to its end (``time.stop``), writing every output. Returns the summary.

    ``checkpoint_every`` > 0 writes ``checkpoint.npz`` every that many frames; ``resume``
    continues from such a checkpoint (bitwise the same result as an uninterrupted run on the
    CPU, its summary the same but for wall times). ``scene`` and ``before_step`` pass to
    :class:`Simulation` (a study's initial fields and time-dependent load); ``observers`` see
    every frame after the run's own."""
    out_dir, wall0, clock0 = Path(out_dir), time.perf_counter(), compile_clock.reading()
    baseline_um = unheated_baseline(case) if resume is None and scene is None else None
    baseline_wall = time.perf_counter() - wall0
    sim = Simulation(case, scene=scene, before_step=before_step)
    writer = output_writer(case, out_dir)
    times = frame_times(case, sim.dt)
    summary, warnings = announce(case, sim, times), []
    record, rule = Record(), StopRule(case)
    horizon = case.time.max_s if rule.solidify else times[-1]
    obs = case_observers(case, sim, writer, baseline_um, warnings)
    obs += [record, rule, ProgressBar(case, horizon, progress), *observers]
    obs.append(Checkpoints(out_dir / CHECKPOINT, checkpoint_every, obs))
    status, pacer, lead_s = "failed", Pacer(sim, StopRequests()), 0.0
    with StopRequests() as stops:
        try:
            lead0 = time.perf_counter()
            first = (
                resume_run(sim, resume, obs)
                if resume
                else settle_run(case, sim, obs, record, progress, stops)
            )
            lead_s = time.perf_counter() - lead0
            pacer = Pacer(sim, stops, [o.tick for o in obs if isinstance(o, ProgressBar)])
            for o in obs:
                o.start(sim)
            schedule = list(enumerate([sim.t, *times]))[first:]
            run_frames(pacer, schedule, obs)
            status = rule.ended
        except SimulationError as e:
            summary["error"] = str(e)
            record_failure(sim, pacer.index, len(times), obs, out_dir)
        except KeyboardInterrupt:
            status = "interrupted"
        finally:
            stops.hold()  # a further signal only marks it: the outputs are being closed
            finished = finish(obs, RunEnd(status, sim, summary, warnings, stops))
            summary.update(status=status, wall_s=time.perf_counter() - wall0)
            summary.update(step_wall_s=pacer.step_wall, steps_per_s=pacer.steps_per_s)
            summary.update(warnings=list(dict.fromkeys(warnings)), **_compiled(clock0))
            summary["wall_breakdown_s"] = wall_breakdown(
                summary, baseline_wall, lead_s, pacer, finished
            )
            writer.summary(summary)
    return summary


def unheated_baseline(case: Case) -> float | None:
    """The unheated run's neck, where the verdict needs one and no settling gives it."""
    if not needs_baseline(case) or case.contact.settle:
        return None
    print(
        f"{case.case.name}: the unheated baseline ({case.fusion.baseline_s:g} s without "
        "laser heat)",
        file=sys.stderr,
    )
    return unheated_neck_um(case)


def output_writer(case: Case, out_dir: Path) -> OutputWriter:
    """The run's output folder, with the case as given (case.toml) and as resolved
    (resolved.toml: the bed's bodies, the fitted domain, the laser depths)."""
    o, bed = case.output, is_bed(case)
    writer = OutputWriter(
        out_dir,
        painter=frame_painter(case, bed),
        png=o.png,
        gif=o.gif,
        vtu=o.vtu,
        deformation=o.deformation,
        bed=bed,
    )
    writer.write_case(case_to_toml(getattr(case, "given", None) or case))
    writer.write_case(case_to_toml(case), "resolved.toml")
    return writer


def announce(case: Case, sim: Simulation, times: list[float]) -> dict[str, Any]:
    """Prints what will run; returns the summary's head."""
    sc, steps = sim.scene, round(times[-1] / sim.dt)
    print(
        f"{case.case.name}: {sc.n_points} points, {sc.table1_nodes} nodes "
        f"(domain + ghost layer; {sc.nx * sc.ny * sc.nz} in the arrays), dt = {sim.dt:.3g} s, "
        + (
            f"until solidified (at most {case.time.max_s:g} s, {steps} steps)"
            if case.time.stop == "solidified"
            else f"{steps} steps"
        )
        + f", compile {sim.compile_s:.1f} s so far",
        file=sys.stderr,
    )
    return {
        "case": case.case.name,
        "status": "running",
        "points": sc.n_points,
        "nodes": sc.table1_nodes,
        "nodes_in_arrays": sc.nx * sc.ny * sc.nz,
        "dt_s": sim.dt,
        "dt_limits_s": sim.dt_limits,
        "mass_scale": case.solver.mass_scale,
        "compile_s": sim.compile_s,
    }


def case_observers(
    case: Case,
    sim: Simulation,
    writer: OutputWriter,
    baseline_um: float | None,
    warnings: list[str],
) -> list[Observer]:
    """The observers of a case's outputs, in the order each frame visits them: a bed's
    contacts first (their columns join the frame's monitors), then the series, the frames,
    the verdict (the pair's, or per contact in a bed's table) and the warnings."""
    out = writer.out_dir
    if is_bed(case):
        verdict: list[Observer] = [Contacts(sim, out), LayerFile(out)]
        series = TimeSeries(writer, beam_off(case))
    else:
        verdict, series = [PairVerdict(case, out, baseline_um)], TimeSeries(writer)
    return [*verdict[:1], series, Frames(writer), *verdict[1:], InertiaWarning(case, warnings)]


def settle_run(
    case: Case,
    sim: Simulation,
    observers: Sequence[Observer],
    record: Record,
    progress: bool,
    stops: StopRequests,
) -> int:
    """``contact.settle``: settle first; the settled neck is then the unheated one. Returns the
    first frame's index (0)."""
    if case.contact.settle:
        record.settle = settle(sim, case, progress, stops)
        if needs_baseline(case):
            for o in observers:
                if isinstance(o, PairVerdict):
                    o.baseline_um = record.settle["neck_um"]
    return 0


def resume_run(sim: Simulation, path: Path, observers: Sequence[Observer]) -> int:
    """Continue from a checkpoint; returns the index of the first frame still to make."""
    index = resume(sim, path, observers)
    print(f"resumed from {path} at frame {index}, t = {sim.t:.6g} s", file=sys.stderr)
    return index + 1


def finish(observers: Sequence[Observer], end: RunEnd) -> dict[str, float]:
    """Each observer's end, in order; one that fails costs only its own outputs. Returns the
    wall time (s) each took, by class name."""
    spent: dict[str, float] = {}
    for o in observers:
        w0 = time.perf_counter()
        try:
            o.finish(end)
        except Exception as e:  # noqa: BLE001 -- the summary is still written
            end.warnings.append(f"{type(o).__name__} not finished ({type(e).__name__}: {e})")
        name = type(o).__name__
        spent[name] = spent.get(name, 0.0) + time.perf_counter() - w0
    return spent


def wall_breakdown(
    summary: dict[str, Any],
    baseline_s: float,
    settle_s: float,
    pacer: Pacer,
    finished: dict[str, float],
) -> dict[str, Any]:
    """Where the run's wall time went (s): the unheated baseline, settling (a resumed run:
    reading its checkpoint), stepping, the observers' work on the frames and at the end (each
    by name, and their sums), and the rest (building the scene, compiling outside the steps,
    the first outputs). ``compile_s`` is part of the others (a kernel compiles when it first
    runs), shown for comparison."""
    frames_s, end_s = sum(pacer.observer_wall.values()), sum(finished.values())
    parts = baseline_s + settle_s + pacer.step_wall + frames_s + end_s
    return {
        "baseline_s": baseline_s,
        "settle_s": settle_s,
        "stepping_s": pacer.step_wall,
        "frames_s": frames_s,
        "end_s": end_s,
        "other_s": summary["wall_s"] - parts,
        "compile_s": summary["compile_s"],
        "frames_by_observer_s": dict(pacer.observer_wall),
        "end_by_observer_s": finished,
    }


def describe_wall(b: dict[str, Any]) -> str:
    """One line: the wall time by part, with the share outside the solver's steps."""
    total = b["baseline_s"] + b["settle_s"] + b["stepping_s"] + b["frames_s"]
    total += b["end_s"] + b["other_s"]
    outside = b["frames_s"] + b["end_s"] + b["other_s"]
    share = outside / total if total > 0 else 0.0
    return (
        f"wall time {total:.1f} s: stepping {b['stepping_s']:.1f}, settling {b['settle_s']:.1f}, "
        f"baseline {b['baseline_s']:.1f}, frames {b['frames_s']:.1f}, outputs at the end "
        f"{b['end_s']:.1f}, set-up and the rest {b['other_s']:.1f} ({share:.0%} outside the "
        f"steps); compiling {b['compile_s']:.1f} of it"
    )


def record_failure(
    sim: Simulation, index: int, frames: int, observers: Sequence[Observer], out_dir: Path
) -> None:
    """The guard stopped the run: the offending state beside the last good frame (its full
    state, and one more frame for the record)."""
    sim.save_checkpoint(out_dir / "failed_state.npz", {"frame": frames})
    frame = Frame(index, sim, named_monitors(sim, guard=False), failed=True)
    for o in observers:
        if o.records_failed_frame:
            o.frame(frame)


def beam_off(case: Case) -> dict[str, float]:
    """When the last laser stops heating (switched off or scanned past its end), as an event of
    the bed's time series."""
    off = case.lasers_off_s()
    return {"beam off": off} if off > 0.0 else {}


def _compiled(clock0: dict[str, float]) -> dict[str, float]:
    """The summary's compile record: every kernel compiled since ``clock0``, the unheated
    baseline, settle phase and hand-over included (``compile_s``: front + back end)."""
    c = compile_clock.since(clock0)
    return {
        "compile_s": c["compile_s"],
        "compile_front_end_s": c["front_end_s"],
        "compile_back_end_s": c["back_end_s"],
        "compile_cpu_s": c["compile_cpu_s"],
        "kernels_compiled": int(c["kernels"]),
    }


def complete_summary(
    out_dir: Path, statuses: tuple[str, ...] = ("complete",)
) -> dict[str, Any] | None:
    """The summary of a run already complete in out_dir, else None: the studies run again only
    what is missing (delete the folder to rerun). ``statuses``: the ends that count as done (a
    study may keep a run the guard stopped: on the CPU it would fail the same way again)."""
    path = Path(out_dir) / "summary.json"
    summary = json.loads(path.read_text()) if path.is_file() else None
    return summary if summary is not None and summary.get("status") in statuses else None


def print_outcome(summary: dict[str, Any]) -> None:
    """The outcome lines of a finished run, on stderr."""
    if "bed" in summary:  # a bed's verdict is per contact
        print(describe_bed(summary["bed"]), file=sys.stderr)
    else:
        print(describe(summary["outcome"]), file=sys.stderr)
    for w in summary.get("warnings", []):
        print(f"warning: {w}", file=sys.stderr)
