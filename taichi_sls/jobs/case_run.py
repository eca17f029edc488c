"""The main job: run one case to its end (``time.stop``), writing every output.

Writes to the output folder (default ``out/<case name>/``): ``frames/*.png``, ``animation.gif``,
``timeseries.csv`` (one row per output frame), ``timeseries.png``, ``outcome.png``,
``summary.json`` (with the fusion ``outcome``), ``case.toml`` (as given) and ``resolved.toml``
(as run), with ``output.vtu = true``, ParaView point data. A case of more than two bodies (a bed)
adds ``contacts.csv`` and ``contacts.png``, the summary's ``bed`` record (jobs/bed_outcome.py),
the bed's own columns of the time series and plots (the layer's density, melt and contacts
over time: io/series.BED_PANELS; the contacts map and necks: io/bed_outcome_plot.py),
its verdict per contact, and ``layer.npz``, its points at the end (``bed.previous_layer`` of a
next layer). Every file is written atomically; an interrupted or
failed run still leaves valid files and a summary that says so.
"""

from __future__ import annotations

import json
import math
import sys
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..config import Case, case_to_toml
from ..config.layer_file import CARRIED_STATE, OPTIONAL_STATE
from ..io.bed_outcome_plot import plot_bed_outcome
from ..io.contacts_plot import plot_contacts
from ..io.contacts_table import read_contacts, write_contacts
from ..io.frames3d import section_layer, view_3d
from ..io.layer_output import write_layer
from ..io.outcome_plot import plot_outcome
from ..io.vtu import point_data
from ..io.writer import OutputWriter
from ..physics.materials import KELVIN
from ..solver import compile_clock
from ..solver.guard import SimulationError
from ..solver.scene import Scene
from ..solver.simulation import Simulation
from .bed_outcome import ContactHistory, bed_monitors, bed_summary, describe_bed, is_bed
from .outcome import NeckHistory, describe, laser_acted, neck_region, outcome
from .progress import Progress
from .schedule import SETTLED_FRAMES, frame_steps, settled
from .settle import settle
from .unheated import needs_baseline, unheated_neck_um

# statuses: complete (end_s reached, or solidified and settled), max_time (stop = solidified
# gave up at time.max_s), failed (the guard), interrupted (Ctrl-C, SIGTERM)
STATUSES = ("complete", "max_time", "failed", "interrupted")
LAYER_FILE = "layer.npz"  # a bed run's points at its end: the next layer's base


def _writer(case: Case, out_dir: Path) -> OutputWriter:
    o, g = case.output, case.grid
    return OutputWriter(
        out_dir,
        domain_um=(
            -g.ghost_cells * g.spacing_um,
            case.domain.width_um + g.ghost_cells * g.spacing_um,
            -g.ghost_cells * g.spacing_um,
            case.domain.height_um,
        ),
        melt_C=min(m.melt_C for m in case.materials.values()),
        png=o.png,
        gif=o.gif,
        vtu=o.vtu,
        dpi=o.dpi,
        deformation=o.deformation,
        bed=is_bed(case),
        view3d=view_3d(case) if case.domain.dim == 3 else None,
    )


def vtu_point_data(snap: dict[str, Any]) -> dict[str, Any]:
    """The VTU fields of a full :meth:`Simulation.snapshot`."""
    return point_data(
        body_id=snap["body_id"],
        velocity_m_s=snap["velocity_m_s"],
        displacement_um=snap["displacement_vector_um"],
        stress_Pa=snap["stress_Pa"],
        equivalent_plastic_strain=snap["plastic_strain"],
        J=snap["J"],
    )


def run_case(
    case: Case,
    out_dir: str | Path,
    *,
    progress: bool = True,
    checkpoint_every: int = 0,
    resume: Path | None = None,
    scene: Scene | None = None,
    before_step: Callable[[Simulation], None] | None = None,
) -> dict[str, Any]:
    """Run one case to its end (``time.stop``), writing every output. Returns the summary.

    ``checkpoint_every`` > 0 writes ``checkpoint.npz`` every that many frames; ``resume``
    continues from such a checkpoint into the same output folder (bitwise the same result as an
    uninterrupted run on the CPU). ``scene`` and ``before_step`` pass to :class:`Simulation`
    (a study's initial fields and time-dependent load)."""
    out_dir = Path(out_dir)
    wall0 = time.perf_counter()
    clock0 = compile_clock.reading()
    baseline_um = None
    if needs_baseline(case) and scene is None and not case.contact.settle:
        print(
            f"{case.case.name}: the unheated baseline ({case.fusion.baseline_s:g} s without "
            "laser heat)",
            file=sys.stderr,
        )
        baseline_um = unheated_neck_um(case)
    sim = Simulation(case, scene=scene, before_step=before_step)
    sc = sim.scene
    writer = _writer(case, out_dir)
    writer.write_case(case_to_toml(getattr(case, "given", None) or case))
    writer.write_case(case_to_toml(case), "resolved.toml")
    schedule = list(frame_steps(case, sim.dt))
    solidify = case.time.stop == "solidified"
    horizon = case.time.max_s if solidify else schedule[-1] * sim.dt
    print(
        f"{case.case.name}: {sc.n_points} points, {sc.table1_nodes} nodes "
        f"(domain + ghost layer; {sc.nx * sc.ny * sc.nz} in the arrays), dt = {sim.dt:.3g} s, "
        + (
            f"until solidified (at most {case.time.max_s:g} s, {schedule[-1]} steps)"
            if solidify
            else f"{schedule[-1]} steps"
        )
        + f", compile {sim.compile_s:.1f} s so far",
        file=sys.stderr,
    )
    summary: dict[str, Any] = {
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
    history = NeckHistory()
    bed = ContactHistory(sim) if is_bed(case) else None
    warnings: list[str] = []

    def frame(index: int, guard: bool = True) -> dict[str, float]:
        mon = sim.monitors(guard=guard)
        if bed is not None and guard:  # not on the blown-up state of a failed run
            bed.add(sim)
            rows = bed.rows(sim)
            write_contacts(out_dir / "contacts.csv", rows)
            mon.update(bed_monitors(sim, rows))  # the bed's series (timeseries.png)
        writer.row(mon)
        history.add(mon)
        snap = sim.snapshot(full=writer.vtu)
        deform = snap[
            "displacement_um" if case.output.deformation == "displacement" else "plastic_strain"
        ]
        extra = vtu_point_data(snap) if writer.vtu else None
        writer.frame(
            index, sim.t, snap["x_um"], snap["T_C"], deform, snap["liquid_fraction"], extra
        )
        return mon

    k0 = 0
    if resume is not None:
        extra = sim.load_checkpoint(resume)
        k0 = int(extra["frame"])
        writer.resume()
        for row in writer.series.rows():
            history.add(row)
        prev = out_dir / "summary.json"
        old = json.loads(prev.read_text()) if prev.is_file() else {}
        first = old["initial"] if "initial" in old else sim.monitors()
        if bed is not None and (out_dir / "contacts.csv").is_file():
            d = old.get("bed", {}).get("relative_density", {})
            bed.restore(
                read_contacts(out_dir / "contacts.csv"),
                {
                    "relative_density": d.get("initial") or math.nan,
                    "mean_top_m": (d.get("mean_top_initial_um") or math.nan) * 1e-6,
                },
            )
        print(f"resumed from {resume} at frame {k0}, t = {sim.t:.6g} s", file=sys.stderr)
        if "settle" in old:
            summary["settle"] = old["settle"]
    else:
        if case.contact.settle:
            try:
                summary["settle"] = settle(sim, case, progress)
            except SimulationError as e:  # never settled, or the guard stopped it
                summary.update(status="failed", error=str(e), wall_s=time.perf_counter() - wall0)
                summary.update(_compiled(clock0))
                writer.summary(summary)
                writer.finish()
                return summary
        first = frame(0)
    if "settle" in summary and needs_baseline(case):  # the settled pair is the unheated one
        baseline_um = summary["settle"]["neck_um"]
    summary["initial"] = first
    last, before = first, deque(maxlen=SETTLED_FRAMES)  # the frames before last
    walls = [w.temperature_C for w in case.boundary.walls(case.domain.dim) if w.thermal == "fixed"]
    bar = Progress(
        horizon,
        sim.t,
        enabled=progress,
        solidify=solidify,
        T_c=min(m.solid_below_C() for m in case.materials.values()),
        T_wall=min(walls) if walls else math.nan,
        adaptive=sim.adaptive is not None,
        lasers_off_s=case.lasers_off_s() if laser_acted(case) else math.nan,
    )
    step_wall = 0.0
    steps0 = sim.steps

    solid = False
    try:
        for k in range(k0 + 1, len(schedule) + 1):
            t0 = time.perf_counter()
            sim.advance_to(schedule[k - 1] * sim.dt)
            step_wall += time.perf_counter() - t0
            pace = (sim.steps - steps0) / step_wall if step_wall > 0 else 0.0
            bar.update(sim.t, pace, sim.step_dt)
            before.append(last)
            last = frame(k)
            bar.note(last)
            if checkpoint_every and k % checkpoint_every == 0:
                sim.save_checkpoint(out_dir / "checkpoint.npz", {"frame": k})
            if last.get("kinetic_ratio", 0.0) > 1e-2 and case.solver.mass_scale > 1.0:
                warnings.append(
                    f"t = {sim.t:.3g} s: kinetic energy {last['kinetic_ratio']:.2g} of the "
                    "surface energy with solver.mass_scale = "
                    f"{case.solver.mass_scale:g}: inertia matters, the scale is too large"
                )
            if solidify and settled(last, case, sim.t, before):
                break
        solid = last["molten_fraction"] == 0.0
        summary["status"] = (
            "max_time" if solidify and not settled(last, case, sim.t, before) else "complete"
        )
    except SimulationError as e:
        summary["status"] = "failed"
        summary["error"] = str(e)
        # the offending state beside the last good frame: full state and one more image
        sim.save_checkpoint(out_dir / "failed_state.npz", {"frame": len(schedule)})
        last = frame(writer.next_index, guard=False)
        solid = False
    except KeyboardInterrupt:
        summary["status"] = "interrupted"
        solid = False
    finally:
        bar.close()
        arrays = sim.point_arrays()
        in_neck = neck_region(case, arrays["x0"], sc.body, arrays["mass"])
        summary["outcome"] = outcome(
            case,
            history,
            last,
            arrays["time_molten"],
            in_neck,
            solidified=solid and summary["status"] == "complete",
            baseline_um=baseline_um,
        )
        if bed is not None and case.domain.dim == 3:  # the 3D generator's own report
            summary["bed_generator"] = case.bed_report
        if bed is not None:
            summary["outcome"].update(
                fused=None,
                no_verdict=f"{len(case.bodies)} bodies: the verdict is per contact (summary "
                "bed, contacts.csv)",
            )
            try:
                rows = bed.rows(sim)
                write_contacts(out_dir / "contacts.csv", rows)
                summary["bed"] = bed_summary(sim, rows, bed.density_initial)
                xy_um = arrays["x"][:, :2] * 1e6  # 3D: projected onto x-y (a view along z)
                plot_contacts(out_dir, rows, xy_um)
                density = summary["bed"]["relative_density"]
                plot_bed_outcome(
                    out_dir,
                    rows,
                    xy_um,
                    time_molten=arrays["time_molten"],
                    density=(density["initial"], density["final"]),
                    neck_growth=case.fusion.neck_growth,
                    spacing_um=case.grid.spacing_um / case.grid.points_per_cell
                    if case.domain.dim == 3
                    else None,
                )
                # the layer a next one is deposited on
                if summary["status"] != "failed":
                    write_layer_file(out_dir / LAYER_FILE, sim, summary["status"])
                    summary["layer_file"] = LAYER_FILE
            except Exception as e:  # noqa: BLE001 -- never cost the run's other outputs
                warnings.append(f"bed outcome not made ({type(e).__name__}: {e})")
        if summary["status"] == "max_time":
            warnings.append(
                f"time.max_s = {case.time.max_s:g} s reached before the pair solidified and "
                "settled: the outcome is not final"
            )
        summary.update(
            steps=sim.steps,
            simulated_s=sim.t,
            wall_s=time.perf_counter() - wall0,
            step_wall_s=step_wall,
            steps_per_s=(sim.steps - steps0) / step_wall if step_wall > 0 else math.nan,
            final=last,
            refused_steps=sim.adaptive.refused if sim.adaptive is not None else 0,
            handover_s=sim.handover.at_s if sim.handover is not None else None,
            handbacks=sim.handover.handbacks if sim.handover is not None else 0,
            extrapolation_kept_points=getattr(sim.implicit, "kept", 0),
            T_peak_C=last.get("T_peak_C"),
            warnings=list(dict.fromkeys(warnings)),
        )
        summary.update(_compiled(clock0))
        writer.summary(summary)
        writer.finish(beam_off(case) if bed is not None else None)
        try:
            # a bed's outcome.png is drawn with its contacts above; a 3D run's from one layer
            if bed is None and (case.domain.dim == 2 or len(case.bodies) <= 2):
                x_end = sim.point_arrays()["x"]
                plot_outcome(out_dir, *section_layer(case, sc.x, x_end, sc.body))
        except Exception as e:  # noqa: BLE001 -- a plot must never cost the run's outputs
            print(f"warning: outcome.png not drawn ({type(e).__name__}: {e})", file=sys.stderr)
    return summary


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


def write_layer_file(path: Path, sim: Simulation, status: str) -> None:
    """The points as they are now, for a case that deposits a layer on them (bed.previous_layer)."""
    carried = (*CARRIED_STATE, *OPTIONAL_STATE)
    pt, sc = sim.point_arrays(("x", "volume0", "J", "T", *carried)), sim.scene
    dim = sim.state.cfg.dim
    write_layer(
        path,
        x_um=pt["x"] * 1e6,
        volume=pt["volume0"] * pt["J"] * 1e6**dim,
        body=sc.body,
        material=sc.material,
        material_names=sc.material_names,
        T_C=pt["T"] - KELVIN,
        info={"case": sim.case.case.name, "t_s": sim.t, "status": status},
        volume0=pt["volume0"] * 1e6**dim,
        state={k: pt[k] for k in carried},
    )


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
    if "bed" in summary:  # the pair outcome reads bodies 0 and 1, which means nothing in a bed
        print(describe_bed(summary["bed"]), file=sys.stderr)
    else:
        print(describe(summary["outcome"]), file=sys.stderr)
    for w in summary.get("warnings", []):
        print(f"warning: {w}", file=sys.stderr)
