"""Speed of the explicit 3D step (issue #39 item 11): ``taichi-sls bench speed3d [--sizes
100000,1000000] [--arch gpu] [--out renders]``.

The scene: one layer of touching PA12 spheres of 40 um (the paper's particles, R/h = 10 at
h = 2 um) on the 140 C plate under a stationary 25 W beam at its centre, full physics (surface
energy, heat, plasticity); about n points. Each size runs in the layout ``solver.layout =
"auto"`` picks, then the serial layout (one thread) and the parallel layout (every core) side
by side, and the serial layout without surface tension (the surface energy's share of a step).
Each row gives wall (the fastest call's) and process CPU seconds per step, point-steps per
second of each, and the bytes of Taichi fields per point. On a GPU (``--arch gpu``) the
parallel layout alone runs (the serial one is a CPU layout). Writes speed3d.csv and speed3d.json.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

from bench.speed import build, field_bytes, peak_rss_mb
from taichi_sls.backend import ti
from taichi_sls.config import Case, case_from_dict
from taichi_sls.io.atomic import atomic_write_text, write_rows
from taichi_sls.solver.step import advance

DIAMETER_UM = 40.0
SPACING_UM = 2.0
POINTS_PER_SPHERE = 33_510  # 2x2x2 points per cell filling a sphere of R/h = 10


def layer_case_3d(n_target: int, arch: str = "cpu", overrides: dict | None = None) -> Case:
    """A square layer of touching spheres, about n_target points, the beam at its centre."""
    n = max(1, round(n_target / POINTS_PER_SPHERE))
    cols = max(1, math.ceil(math.sqrt(n)))
    rows = math.ceil(n / cols)
    d = DIAMETER_UM
    centres = [(d / 2 + d * i, d / 2, d / 2 + d * k) for k in range(rows) for i in range(cols)]
    W, H, D = cols * d, d + 8.0, rows * d
    data = {
        "case": {"name": f"layer3d_{n_target}"},
        "grid": {"spacing_um": SPACING_UM},
        "domain": {"dim": 3, "width_um": W, "height_um": H, "depth_um": D},
        "bodies": [{"center_um": list(c), "radius_um": d / 2} for c in centres[:n]],
        "time": {"dt_s": 5e-8},
        "lasers": [{"power_W": 25.0, "x_start_um": W / 2, "z_start_um": D / 2, "off_s": 1e-3}],
        "solver": {"arch": arch},
    }
    for key, value in (overrides or {}).items():
        section, name = key.split(".")
        data.setdefault(section, {})[name] = value
    return case_from_dict(data)


def time_steps(sim, seconds: float) -> dict:
    """Steps in calls of a few until ``seconds`` of wall time pass (after one warm cycle of the
        heat clock, which compiles every variant): wall and process CPU seconds per step, from the
        totals (the CPU time of every core a step keeps busy); the wall time of the fastest call (on
    a shared machine a slow call measures the neighbours, not the step)."""
    st = sim.state
    per_call = max(1, min(50, 300_000 // st.n_points))
    advance(st, st.cfg.heat_every + 1)
    ti.sync()
    steps, wall, cpu, best = 0, 0.0, 0.0, math.inf
    while wall < seconds or steps < 3 * per_call:
        w0, c0 = time.perf_counter(), time.process_time()
        advance(st, per_call)
        ti.sync()
        call = time.perf_counter() - w0
        best = min(best, call / per_call)
        wall += call
        cpu += time.process_time() - c0
        steps += per_call
    return {"wall_s_per_step": best, "cpu_s_per_step": cpu / steps, "steps": steps}


VARIANTS_CPU = (
    ("auto", {}),
    ("serial, 1 thread", {"solver.layout": "serial", "solver.threads": 1}),
    ("parallel, every core", {"solver.layout": "parallel", "solver.threads": 0}),
    (
        "serial, no surface tension",
        {"solver.layout": "serial", "solver.threads": 1, "physics.surface_tension": False},
    ),
)
VARIANTS_GPU = (
    ("parallel (auto)", {}),
    ("parallel, no surface tension", {"physics.surface_tension": False}),
)


def measure(n_target: int, arch: str, seconds: float) -> list[dict]:
    rows = []
    for name, over in VARIANTS_GPU if arch == "gpu" else VARIANTS_CPU:
        sim = build(layer_case_3d(n_target, arch, over))
        st = sim.state
        t = time_steps(sim, seconds)
        n = st.n_points
        rows.append(
            {
                "points": n,
                "arch": arch,
                "variant": name,
                "layout": st.cfg.layout.name.lower(),
                "us_per_step": t["wall_s_per_step"] * 1e6,
                "point_steps_per_s": n / t["wall_s_per_step"],
                "point_steps_per_cpu_s": n / t["cpu_s_per_step"],
                "bytes_per_point": field_bytes(st) / n,
                "compile_s": sim.compile_s,
                "peak_rss_MB": peak_rss_mb(),
                "steps": t["steps"],
            }
        )
        print(
            f"{n:>8d} {arch} {name:<28s} ({rows[-1]['layout']}) "
            f"{rows[-1]['us_per_step']:>11.0f} us/step "
            f"{rows[-1]['point_steps_per_s'] / 1e6:6.2f} M pt-steps/s wall, "
            f"{rows[-1]['point_steps_per_cpu_s'] / 1e6:6.2f} per CPU-s, "
            f"{rows[-1]['bytes_per_point']:.0f} B/point",
            flush=True,
        )
    return rows


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("speed3d", help="explicit 3D point-steps per second and bytes per point")
    ap.add_argument("--sizes", default="100000,1000000", help="points of the 3D layers")
    ap.add_argument("--arch", choices=("cpu", "gpu"), default="cpu", help="Taichi backend")
    ap.add_argument("--seconds", type=float, default=3.0, help="wall time per measurement")
    ap.add_argument("--out", default="renders", help="folder for speed3d.csv and .json")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows: list[dict] = []
    for n in (int(s) for s in args.sizes.split(",") if s):
        rows.extend(measure(n, args.arch, args.seconds))
    write_rows(out / "speed3d.csv", rows)
    atomic_write_text(out / "speed3d.json", json.dumps(rows, indent=1) + "\n")
    print(f"wrote {out / 'speed3d.csv'}, {out / 'speed3d.json'}")
    return 0
