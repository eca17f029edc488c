"""Run time against error: ``taichi-sls bench cost [--quick] [--out renders]``.

For the paper's 25 W case run to solidification (contact line at 1 ms and at the end, peak
temperature; explicit over the step, the inertia scale and the grid, and the implicit
integrator: adaptive, and hybrid) and for two verification cases in the Stokes regime
(Hopper's coalescence at R0/h = 10, the viscous decay of a disc mode at R/h = 20), each
setting is run, timed (stepping only, after compilation) and compared with a reference: for the
paper case a converged run (a quarter of the paper's step, physical inertia), for the
verification cases the exact solution. Writes
``cost_error.csv`` and ``cost_error.png`` (error against wall time) and prints the table.
A paper run already complete under OUT/cost_runs/ is read, not run again (delete it to rerun).

Inertia scaling is honest where inertia does not matter: in a slow viscous flow (Ohnesorge
>> 1) the kinetic energy is a vanishing fraction of the surface and elastic energies, and
scaling the mass by s changes nothing but the stable step (larger by sqrt(s)). The
``kinetic_ratio`` monitor (scaled kinetic energy over the surface energy) says when it does.
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
from taichi_sls.config.loading import add_set_argument

IMPLICIT = ["time.integrator=implicit", "time.heat_integrator=implicit"]
HYBRID = "time.integrator=hybrid"
PAPER = [
    ("reference: dt 1.25e-8 s, s = 1", ["time.dt_s=1.25e-8"]),
    ("dt 2.5e-8 s, s = 1", ["time.dt_s=2.5e-8"]),
    ("paper: dt 5e-8 s, s = 1", ["time.dt_s=5e-8"]),
    *[
        (f"auto dt, s = {s}", ["time.dt_s=auto", f"solver.mass_scale={s}"])
        for s in (1, 4, 16, 64, 256, 1024)
    ],
    *[
        (
            f"h = 4 um, auto dt, s = {s}",
            ["grid.spacing_um=4", "time.dt_s=auto", f"solver.mass_scale={s}"],
        )
        for s in (1, 16, 256)
    ],
    # the implicit integrator (docs/record/implicit.md): adaptive steps with backward-Euler heat,
    # and explicit steps through the melting collapse handing over to them
    *[
        (
            f"implicit, adaptive, strain {e:g}",
            [*IMPLICIT, "time.adaptive=true", f"time.max_strain_increment={e}"],
        )
        for e in (0.02, 0.005)
    ],
    *[
        (
            f"hybrid: explicit dt {dt:g} s",
            ["time.integrator=hybrid", *IMPLICIT[1:], f"time.dt_s={dt}"],
        )
        for dt in (5e-8, 1.25e-8)
    ],
]
QUICK = {
    "reference: dt 1.25e-8 s, s = 1",
    "paper: dt 5e-8 s, s = 1",
    "auto dt, s = 16",
    "implicit, adaptive, strain 0.02",
    "hybrid: explicit dt 5e-08 s",
    "hybrid: explicit dt 1.25e-08 s",
}
SCALES = (1, 4, 16, 64, 256)
COLUMNS = [
    "scenario",
    "setting",
    "dt_s",
    "mass_scale",
    "steps",
    "wall_s",
    "status",
    "neck_1ms_um",
    "neck_final_um",
    "T_peak_C",
    "err_1ms",
    "err_final",
    "err_T",
    "error",
    "kinetic_ratio_max",
]


def _paper_row(label: str, sets: list[str], out: Path) -> dict:
    from taichi_sls.io.series import read_series
    from taichi_sls.jobs.case_run import complete_summary, run_case

    sets = [
        *sets,
        "time.stop=solidified",
        "time.max_s=0.2",
        "output.png=false",
        "output.gif=false",
    ]
    case = load_case("power25W", sets)
    folder = out / "cost_runs" / label.replace(" ", "_").replace(",", "").replace(":", "")
    s = complete_summary(folder) or run_case(case, folder, progress=False)
    o = s["outcome"]
    series = read_series(folder / "timeseries.csv")
    return {
        "scenario": "paper 25 W to solidification",
        "setting": label,
        "dt_s": s["dt_s"],
        "mass_scale": case.solver.mass_scale,
        "steps": s["steps"],
        "wall_s": round(s["step_wall_s"], 2),
        "status": s["status"],
        "neck_1ms_um": o["neck_1ms_um"],
        "neck_final_um": o["neck_final_um"],
        "T_peak_C": o["T_peak_C"],
        "kinetic_ratio_max": float(max(series.get("kinetic_ratio", [math.nan]))),
    }


def _verification_rows(quick: bool) -> list[dict]:
    from taichi_sls.studies import verification as ver

    rows = []
    for name, res, measure, sets in (
        ("hopper", 10, "neck_tau1", {}),
        ("viscous_decay", 20, "decay_rate", {}),
    ):
        for s in (1, 16) if quick else SCALES:
            extra = {**sets, "solver": {"mass_scale": float(s)}}
            t0 = time.perf_counter()
            r = ver.run(ver.load(name, res, extra))
            rows.append(
                {
                    "scenario": f"{name} R/h = {res}",
                    "setting": f"auto dt, s = {s}",
                    "dt_s": r.dt_s,
                    "mass_scale": s,
                    "steps": r.steps,
                    "wall_s": round(time.perf_counter() - t0, 2),
                    "status": "complete",
                    "error": abs(r.errors[measure]),
                }
            )
            print(rows[-1], file=sys.stderr, flush=True)
    return rows


def errors(rows: list[dict]) -> None:
    """The paper rows' errors against the reference row (relative)."""
    ref = next(r for r in rows if r["setting"].startswith("reference"))
    for r in rows:
        if r["scenario"] != ref["scenario"]:
            continue
        for key, err in (
            ("neck_1ms_um", "err_1ms"),
            ("neck_final_um", "err_final"),
            ("T_peak_C", "err_T"),
        ):
            a, b = r.get(key), ref.get(key)
            ok = a is not None and b is not None and b != 0
            r[err] = abs(a / b - 1) if ok else math.nan
        r["error"] = max(r["err_1ms"], r["err_final"], r["err_T"])


def plot(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scen = list(dict.fromkeys(r["scenario"] for r in rows))
    fig, axes = plt.subplots(1, len(scen), figsize=(5 * len(scen), 4), squeeze=False)
    for ax, sc in zip(axes.flat, scen, strict=False):
        pts = [r for r in rows if r["scenario"] == sc and r.get("error", 0) == r.get("error", 0)]
        for r in pts:
            e = max(float(r.get("error", math.nan)), 1e-6)
            ax.loglog(float(r["wall_s"]), e, "o", color="C3" if r["status"] != "complete" else "C0")
            ax.annotate(r["setting"], (float(r["wall_s"]), e), fontsize=6)
        ax.axhline(0.01, color="0.5", lw=0.8, ls=":")
        ax.set_xlabel("wall time of the stepping (s)")
        ax.set_ylabel("largest relative error" if "paper" in sc else "|error| vs exact")
        ax.set_title(sc, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("cost", help="run time against error over dt, inertia scale and grid")
    ap.add_argument("--out", default="renders", help="folder for cost_error.csv and .png")
    ap.add_argument("--quick", action="store_true", help="three paper settings, two scales")
    ap.add_argument("--skip-verification", action="store_true", help="only the paper case")
    add_set_argument(ap, "case override for every paper run")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for label, sets in PAPER:
        if args.quick and label not in QUICK:
            continue
        rows.append(_paper_row(label, [*sets, *args.set], out))
        print(rows[-1], file=sys.stderr, flush=True)
    errors(rows)
    if not args.skip_verification:
        rows += _verification_rows(args.quick)
    with (out / "cost_error.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    (out / "cost_error.json").write_text(json.dumps(rows, indent=1))
    plot(rows, out / "cost_error.png")
    for r in rows:
        print(
            f"{r['scenario'][:28]:28s} {r['setting']:34s} dt {r['dt_s']:.3g} s "
            f"{r['wall_s']:8.1f} s  error {r.get('error', math.nan):.3g}  {r['status']}"
        )
    return 0
