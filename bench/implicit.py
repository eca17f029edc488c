"""Both integrators side by side: ``taichi-sls bench implicit [--quick] [--out renders]``.

Rows, each run, timed (wall time of the whole run with a warm kernel cache: the first call of a
configuration compiles it, 10-20 s, later calls load it) and compared with its reference:

- verification cases against their exact solutions (Hopper's coalescence from his outline at
  R0/h = 20, the viscous decay of a disc mode and the Laplace pressure at R/h = 10), explicit and
  implicit at steps 10x and 100x the explicit capillary limit (the Laplace run ends within 100
  such steps), Hopper and the vibrating bar also by the extrapolated (second-order) step; the
  vibrating bar (16 cells, its inertia the whole physics) at 1x and 10x the explicit elastic
  limit;
- a second of viscous sintering of a PA12 pair (cases/verification/hopper_pa12.toml, out of the
  explicit integrator's reach: 3e8 steps) at R0/h = 10 and 20;
- the paper's 25 W case to 1 ms (and, ``--refrozen``, until it has refrozen): explicit, implicit
  at the "auto" step (coarse grid) and implicit with the adaptive step and backward-Euler heat,
  on the coarse and the fine grid; neck and peak temperature against the explicit run, and the
  stepping time of each (the main job's ``step_wall_s``: compilation and output excluded);
- the same pair in the reading that converges (``cases/power25W_resolved.toml``): its hybrid
  as the reference, adaptive implicit steps at the default controls and at twice them, the
  settle's wall time (the laser-free start every power shares) in a column of its own.

Writes ``implicit.csv`` and ``implicit.json`` and prints the table.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from pathlib import Path

from taichi_sls.config import load_case
from taichi_sls.jobs.case_run import complete_summary, run_case
from taichi_sls.solver.time_step import time_step_limits
from taichi_sls.studies import verification as ver

IMPLICIT = {"integrator": "implicit"}
COLUMNS = [
    "row",
    "integrator",
    "dt_s",
    "steps",
    "wall_s",
    "settle_wall_s",
    "measure",
    "value",
    "error",
]


def _limit_multiple(name: str, res: float, k: float, limit: str) -> dict:
    """The implicit time table at k times the explicit ``limit`` (surface_tension, elastic) of
    case ``name``."""
    return {**IMPLICIT, "dt_s": k * time_step_limits(ver.load(name, res).case)[limit]}


def verification_rows(quick: bool) -> list[dict]:
    """(row, resolution, time table or None for the case's own) of the verification rows."""
    be, ex = "backward_euler", "extrapolated"
    rows = [
        ("hopper_shape", 20, None, be),
        ("hopper_shape", 20, 10.0, be),
        ("hopper_shape", 20, 100.0, be),
        ("hopper_shape", 20, 100.0, ex),
        ("hopper_shape", 20, 200.0, ex),
        ("viscous_decay", 10, None, be),
        ("viscous_decay", 10, 100.0, be),
        ("laplace", 10, None, be),
        ("laplace", 10, 10.0, be),
        ("hopper_pa12", 10, "case", be),
        ("hopper_pa12", 20, "case", be),
        ("bar", 16, None, be),
        ("bar", 16, 1.0, be),
        ("bar", 16, 1.0, ex),
        ("bar", 16, 10.0, be),
        ("bar", 16, 10.0, ex),
    ]
    if quick:
        rows = [r for r in rows if r[0] != "hopper_shape" or r[2] == 100.0]
    out = []
    for name, res, k, scheme in rows:
        sets = None
        limit = "elastic" if name == "bar" else "surface_tension"
        if isinstance(k, float):
            sets = {"time": {**_limit_multiple(name, res, k, limit), "implicit_scheme": scheme}}
        t0 = time.perf_counter()
        r = ver.run(ver.load(name, res, sets))
        wall = time.perf_counter() - t0
        integrator = "explicit" if k is None else "implicit"
        if k is not None and scheme == ex:
            integrator = "implicit, extrapolated"
        label = f"{name} R/h = {res:g}" + (
            f", {k:g}x {limit.replace('_', ' ')} limit" if isinstance(k, float) else ""
        )
        for measure, err in r.errors.items():
            out.append(
                {
                    "row": label,
                    "integrator": integrator,
                    "dt_s": r.dt_s,
                    "steps": r.steps,
                    "wall_s": round(wall, 2),
                    "measure": measure,
                    "value": r.info.get(measure.replace("neck_", "neck_sim_"), math.nan),
                    "error": err,
                }
            )
        print(out[-1], file=sys.stderr, flush=True)
    return out


# the 25 W pair by each integrator: (case, label, overrides)
ADAPTIVE = ["time.integrator=implicit", "time.adaptive=true"]
PAPER_RUNS = (
    ("power25W_coarse", "explicit", ["time.dt_s=auto"]),
    ("power25W_coarse", "implicit", ["time.integrator=implicit", "time.dt_s=auto"]),
    ("power25W_coarse", "implicit, adaptive", ADAPTIVE),
    ("power25W_coarse", "hybrid", ["time.integrator=hybrid"]),
    ("power25W", "explicit", []),
    ("power25W", "implicit, adaptive", ADAPTIVE),
    ("power25W", "hybrid", ["time.integrator=hybrid"]),
    # the reading that converges (docs/record/convergence.md): its own hybrid is the reference
    # (halving its explicit step moves the neck by 0.06 %); the adaptive controls at twice their
    # defaults
    ("power25W_resolved", "hybrid", []),
    ("power25W_resolved", "implicit, adaptive", ADAPTIVE),
    (
        "power25W_resolved",
        "implicit, adaptive, controls x2",
        [*ADAPTIVE, "time.max_temperature_change_K=10", "time.max_strain_increment=0.04"],
    ),
)


def paper_rows(runs_dir: Path, refrozen: bool, end_s: float = 1e-3) -> list[dict]:
    """The 25 W pair to end_s (and, ``refrozen``, until it has refrozen) by each integrator as
    the main job runs it (no images): neck and peak temperature against the first run of the
    same case and stop (the explicit run; for the resolved case its hybrid), the stepping time
    alone (compilation, the settle and output excluded; the settle's own wall time apart)."""
    out = []
    stops = [("1 ms", [f"time.end_s={end_s}", "time.stop=end"])]
    if refrozen:
        stops.append(("refrozen", ["time.stop=solidified"]))
    for stop, stop_sets in stops:
        for name, label, sets in PAPER_RUNS:
            case = load_case(name, [*sets, *stop_sets, "output.png=false", "output.gif=false"])
            folder = runs_dir / f"{name}_{stop}_{label}".replace(" ", "_").replace(",", "")
            summary = complete_summary(folder) or run_case(case, folder, progress=False)
            for measure in ("contact_line_um", "T_peak_C"):
                out.append(
                    {
                        "row": f"{name} to {stop}",
                        "integrator": label,
                        "dt_s": summary["dt_s"],
                        "steps": summary["steps"],
                        "wall_s": round(summary["step_wall_s"], 2),
                        "settle_wall_s": round(summary.get("settle", {}).get("wall_s", 0.0), 2),
                        "measure": measure,
                        "value": summary["final"][measure],
                        "error": math.nan,
                    }
                )
            print(out[-2:], file=sys.stderr, flush=True)
    for r in out:  # against the first run of the same case and stop
        ref = next(q for q in out if q["row"] == r["row"] and q["measure"] == r["measure"])
        r["error"] = r["value"] / ref["value"] - 1.0
    return out


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("implicit", help="explicit and implicit integrators side by side")
    ap.add_argument("--out", default="renders", help="folder for implicit.csv and .json")
    ap.add_argument("--quick", action="store_true", help="fewer Hopper rows")
    ap.add_argument(
        "--refrozen", action="store_true", help="the 25 W runs also until refrozen (some 10 min)"
    )
    ap.add_argument("--runs", default="out/bench_implicit", help="folder of the 25 W runs")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = verification_rows(args.quick) + paper_rows(Path(args.runs), args.refrozen)
    with (out / "implicit.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        w.writerows(rows)
    (out / "implicit.json").write_text(json.dumps(rows, indent=1))
    for r in rows:
        print(
            f"{r['row'][:44]:44s} {r['integrator']:22s} dt {r['dt_s']:9.3g} s {r['steps']:8d} "
            f"steps {r['wall_s']:7.1f} s  {r['measure']:16s} {r['value']:10.4g} "
            f"error {r['error']:+.4f}"
        )
    return 0
