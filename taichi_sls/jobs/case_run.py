"""The main job: run one case to its end, writing every output.

Writes to the output folder (default ``out/<case name>/``): ``frames/*.png``, ``animation.gif``,
``timeseries.csv`` (one row per output frame), ``timeseries.png``, ``summary.json``, the resolved
``case.toml`` and, with ``output.vtu = true``, ParaView point data. Every file is written
atomically; an interrupted or failed run still leaves valid files and a summary that says so.
"""

from __future__ import annotations

import json
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..config import Case, case_to_toml
from ..io.writer import OutputWriter
from ..solver.guard import SimulationError
from ..solver.scene import Scene
from ..solver.simulation import Simulation


def _progress(total_steps: int, dt: float):
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover - tqdm is a dependency
        return None
    return tqdm(
        total=total_steps,
        unit="step",
        unit_scale=True,
        dynamic_ncols=True,
        desc="t = 0 us",
        file=sys.stderr,
        mininterval=0.5,
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
    """Run one case to its end time, writing every output. Returns the summary.

    ``checkpoint_every`` > 0 writes ``checkpoint.npz`` every that many frames; ``resume``
    continues from such a checkpoint into the same output folder (bitwise the same result as an
    uninterrupted run on the CPU). ``scene`` and ``before_step`` pass to :class:`Simulation`
    (a study's initial fields and time-dependent load)."""
    out_dir = Path(out_dir)
    wall0 = time.perf_counter()
    sim = Simulation(case, scene=scene, before_step=before_step)
    sc = sim.scene
    o = case.output
    writer = OutputWriter(
        out_dir,
        domain_um=(
            -case.grid.ghost_cells * case.grid.spacing_um,
            case.domain.width_um + case.grid.ghost_cells * case.grid.spacing_um,
            -case.grid.ghost_cells * case.grid.spacing_um,
            case.domain.height_um,
        ),
        melt_C=min(m.melt_C for m in case.materials.values()),
        png=o.png,
        gif=o.gif,
        vtu=o.vtu,
        dpi=o.dpi,
        deformation=o.deformation,
    )
    writer.write_case(case_to_toml(case))
    n_frames = o.frames
    # whole steps per frame, rounded up so that the run reaches end_s
    steps_per_frame = max(1, math.ceil(case.time.end_s / n_frames / sim.dt - 1e-9))
    total = steps_per_frame * n_frames
    print(
        f"{case.case.name}: {sc.n_points} points, {sc.table1_nodes} nodes "
        f"(domain + ghost layer; {sc.nx * sc.ny} in the arrays), dt = {sim.dt:.3g} s, "
        f"{total} steps, compile {sim.compile_s:.1f} s",
        file=sys.stderr,
    )
    summary: dict[str, Any] = {
        "case": case.case.name,
        "status": "running",
        "points": sc.n_points,
        "nodes": sc.table1_nodes,
        "nodes_in_arrays": sc.nx * sc.ny,
        "dt_s": sim.dt,
        "dt_limits_s": sim.dt_limits,
        "compile_s": sim.compile_s,
    }

    def frame(index: int) -> dict[str, float]:
        mon = sim.monitors()
        writer.row(mon)
        snap = sim.snapshot()
        deform = snap["displacement_um" if o.deformation == "displacement" else "plastic_strain"]
        writer.frame(index, sim.t, snap["x_um"], snap["T_C"], deform, snap["liquid_fraction"])
        return mon

    k0 = 0
    if resume is not None:
        extra = sim.load_checkpoint(resume)
        k0 = int(extra["frame"])
        writer.resume()
        prev = out_dir / "summary.json"
        first = json.loads(prev.read_text())["initial"] if prev.is_file() else sim.monitors()
        print(f"resumed from {resume} at frame {k0}, t = {sim.t:.6g} s", file=sys.stderr)
    else:
        first = frame(0)
    summary["initial"] = first
    last = first
    bar = _progress(total, sim.dt) if progress else None
    if bar is not None:
        bar.update(sim.steps)
    step_wall = 0.0
    steps0 = sim.steps
    chunk = max(1, min(steps_per_frame, 2000))
    try:
        for k in range(k0 + 1, n_frames + 1):
            done = 0
            while done < steps_per_frame:
                n = min(chunk, steps_per_frame - done)
                t0 = time.perf_counter()
                sim.advance(n)
                step_wall += time.perf_counter() - t0
                done += n
                if bar is not None:
                    bar.update(n)
                    sps = (sim.steps - steps0) / step_wall if step_wall > 0 else 0.0
                    bar.set_description(f"t = {sim.t * 1e6:.1f} us, {sps:,.0f} steps/s")
            last = frame(k)
            if checkpoint_every and k % checkpoint_every == 0:
                sim.save_checkpoint(out_dir / "checkpoint.npz", {"frame": k})
        summary["status"] = "complete"
    except SimulationError as e:
        summary["status"] = "failed"
        summary["error"] = str(e)
        # the offending state beside the last good frame: full state and one more image
        sim.save_checkpoint(out_dir / "failed_state.npz", {"frame": n_frames})
        last = sim.monitors(guard=False)  # the broken state's monitors, for the summary
        snap = sim.snapshot()
        deform = snap["displacement_um" if o.deformation == "displacement" else "plastic_strain"]
        writer.frame(
            writer.next_index, sim.t, snap["x_um"], snap["T_C"], deform, snap["liquid_fraction"]
        )
    except KeyboardInterrupt:
        summary["status"] = "interrupted"
    finally:
        if bar is not None:
            bar.close()
        summary.update(
            steps=sim.steps,
            simulated_s=sim.t,
            wall_s=time.perf_counter() - wall0,
            step_wall_s=step_wall,
            steps_per_s=(sim.steps - steps0) / step_wall if step_wall > 0 else math.nan,
            final=last,
            T_peak_C=last.get("T_peak_C"),
        )
        writer.summary(summary)
        writer.finish()
    return summary
