"""Neck growth against the pair's angle to the grid:
``taichi-sls bench isotropy [--quick] [--out renders]``.

Hopper's fluid pair joined by a fillet (studies/verification/isotropy.py), its line of centres
at 0, 30 and 45 deg to x, the mid-plane through the neck on a node line when along x; at R0/h =
5 (a 2 um fillet, the beds' resolution), 10 (2 um) and 20 (1 um; left out by ``--quick``),
as the case gives it (Poisson ratio 0.45) and with a Poisson ratio of 0.30 (less nearly
incompressible: the lever of the trend, docs/record/verification.md, "Neck growth at any
angle"). Its neck r_n / R0 (the per-contact section on the colour) every
18.75 us to 150 us. Writes isotropy.csv (every sample), isotropy.json (per run: the worst
ratio to the pair along x at the same times, the errors against Hopper at tau = 0.5 / 0.75 / 1
with the clock aligned where r_n / R0 first reaches 0.35, the wall time) and isotropy.png.

``--beds RUN [RUN ...]``: instead, the contacts of finished bed runs (their contacts.csv and
resolved.toml; e.g. ``python -m taichi_sls.run cases/bed_track.toml --set bed.seed=2 --out
RUN``): each melted contact's neck growth (final over initial) against its line of centres'
angle to the grid folded into [0, 45] deg, the least-squares slope per run with its standard
error; isotropy_bed.csv, isotropy_bed.json and isotropy_bed.png.

``--spheres``: instead, the 3D check (studies/verification/isotropy3d.py): two spheres of
R = 20 um at R/h = 5 joined by a 4 um torus fillet, their line of centres along x, (1, 1, 0)
and (1, 1, 1), each point's own dilatation and the cells', explicit and implicit steps; the neck
over the diameter every 15 us to 45 us; isotropy3d.csv and isotropy3d.json (per run the worst
ratio to the pair along x at the same times).

``--golden``: instead, the golden runs of tests/jobs/test_golden_runs.py (their short settings)
with ``solver.dilatation`` "point" (the default) and "cell": the last row of each time series
(neck, median neck, density, contacts fused, J_min, peak temperature) in isotropy_golden.json
(docs/record/verification.md, "The answers that would move").
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from taichi_sls.io.atomic import atomic_write_text, write_rows
from taichi_sls.studies.verification.isotropy import (
    angle_trend,
    contact_growth_by_angle,
    fillet_pair,
    hopper_errors,
    neck_history,
)

TIMES = np.linspace(0.0, 150e-6, 9)
ANGLES = (0.0, 30.0, 45.0)
GRIDS = ((5.0, 2.0), (10.0, 2.0), (20.0, 1.0))  # (R0/h, fillet radius in um)
VARIANTS = {  # name: the case keys it sets
    "nu0.45": {},
    "nu0.30": {"materials": {"fluid": {"poisson": 0.30}}},
}
TAUS = (0.5, 0.75, 1.0)
ALIGN = 0.35  # cases/verification/hopper.toml's hopper_align


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("isotropy", help="a filleted pair's neck growth at 0, 30 and 45 deg")
    ap.add_argument("--quick", action="store_true", help="R0/h = 5 and 10 only")
    ap.add_argument("--out", default="renders", help="folder for the CSV, JSON and plot")
    ap.add_argument("--beds", nargs="+", metavar="RUN", help="bed runs' folders: their contacts")
    ap.add_argument("--spheres", action="store_true", help="the 3D pair along x, xy, xyz")
    ap.add_argument("--golden", action="store_true", help="the golden runs, point and cell")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.beds:
        return beds(args.beds, out)
    if args.spheres:
        return spheres(out)
    if args.golden:
        return golden(out)
    grids = GRIDS[:2] if args.quick else GRIDS
    rows, runs = [], []
    for R0_over_h, fillet_um in grids:
        for variant, sets in VARIANTS.items():
            along_x = None
            for angle in ANGLES:
                vc = fillet_pair(angle, R0_over_h, fillet_um, sets)
                hist = neck_history(vc, TIMES)
                along_x = hist.neck if along_x is None else along_x
                worst = float(np.max(np.abs(hist.neck / along_x - 1.0)))
                errors = hopper_errors(hist, TAUS, ALIGN)
                runs.append(
                    {
                        "R0_over_h": R0_over_h,
                        "fillet_um": fillet_um,
                        "variant": variant,
                        "angle_deg": angle,
                        "worst_ratio_to_along_x": worst,
                        **{f"hopper_error_tau{q:g}": e for q, e in errors.items()},
                        "wall_s": hist.wall_s,
                        "steps": hist.steps,
                    }
                )
                rows += [
                    {
                        "R0_over_h": R0_over_h,
                        "fillet_um": fillet_um,
                        "variant": variant,
                        "angle_deg": angle,
                        "t_us": round(t * 1e6, 3),
                        "neck_over_R0": round(n, 6),
                    }
                    for t, n in zip(hist.times, hist.neck, strict=True)
                ]
                print(
                    f"R0/h {R0_over_h:4g}  {variant:6s}  {angle:4g} deg  r_n/R0 "
                    f"{hist.neck[0]:.4f} -> {hist.neck[-1]:.4f}  worst ratio to 0 deg "
                    f"{worst * 100:5.2f} %  Hopper "
                    + " / ".join(f"{e * 100:+.2f}" for e in errors.values())
                    + f" %  ({hist.wall_s:.0f} s)",
                    flush=True,
                )
    write_rows(out / "isotropy.csv", rows)
    atomic_write_text(out / "isotropy.json", json.dumps(runs, indent=1) + "\n")
    plot(rows, out / "isotropy.png")
    return 0


def plot(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    grids = sorted({r["R0_over_h"] for r in rows})
    fig, axes = plt.subplots(1, len(grids), figsize=(4.2 * len(grids), 3.6), squeeze=False)
    for ax, g in zip(axes[0], grids, strict=True):
        for variant, style in zip(VARIANTS, ("-", "--"), strict=True):
            for angle, colour in zip(ANGLES, ("C0", "C1", "C2"), strict=True):
                sel = [
                    r
                    for r in rows
                    if (r["R0_over_h"], r["variant"], r["angle_deg"]) == (g, variant, angle)
                ]
                t = [r["t_us"] for r in sel]
                n = [r["neck_over_R0"] for r in sel]
                ax.plot(t, n, style, color=colour, label=f"{angle:g} deg, {variant}")
        ax.set_title(f"R0/h = {g:g}")
        ax.set_xlabel("t (us)")
        ax.set_ylabel("r_n / R0")
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def beds(runs: list[str], out: Path) -> int:
    """Neck growth against contact angle in each bed run (module docstring)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows, trends = [], []
    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    for k, run in enumerate(runs):
        contacts = contact_growth_by_angle(Path(run))
        slope, err = angle_trend(contacts)
        growth = [c["growth"] for c in contacts]
        trends.append(
            {
                "run": str(run),
                "contacts": len(contacts),
                "mean_growth": float(np.mean(growth)),
                "slope_per_45deg": slope,
                "slope_standard_error": err,
            }
        )
        rows += [{"run": str(run), **c} for c in contacts]
        ax.plot(
            [c["angle_deg"] for c in contacts],
            growth,
            "o",
            ms=3,
            color=f"C{k}",
            label=Path(run).name,
        )
        print(
            f"{run}: {len(contacts)} melted contacts, mean growth {np.mean(growth):.4f}, slope "
            f"{slope:+.4f} +- {err:.4f} per 45 deg"
        )
    ax.set_xlabel("line of centres to the grid (deg, folded into [0, 45])")
    ax.set_ylabel("neck growth, final / initial")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "isotropy_bed.png", dpi=90)
    plt.close(fig)
    write_rows(out / "isotropy_bed.csv", rows)
    atomic_write_text(out / "isotropy_bed.json", json.dumps(trends, indent=1) + "\n")
    return 0


SPHERE_TIMES = np.linspace(0.0, 45e-6, 4)
SPHERE_RUNS = {  # name: the case keys it sets
    f"{integrator} {dilatation}": {
        "solver": {"dilatation": dilatation, "optimize": False},  # the quick compile
        "time": {"integrator": integrator},
    }
    for integrator, dilatation in (
        ("implicit", "point"),
        ("implicit", "cell"),
        ("explicit", "point"),
        ("explicit", "cell"),
    )
}


def spheres(out: Path) -> int:
    """The 3D pair along x, xy and xyz (module docstring)."""
    from taichi_sls.studies.verification.isotropy3d import (
        DIRECTIONS,
        sphere_neck_history,
        sphere_pair,
        worst_ratio,
    )

    rows, runs = [], []
    for name, sets in SPHERE_RUNS.items():
        hists = []
        for direction in DIRECTIONS:
            hist = sphere_neck_history(sphere_pair(direction, 20.0, 5.0, 4.0, sets), SPHERE_TIMES)
            hists.append(hist)
            worst = worst_ratio([hists[0], hist]) if len(hists) > 1 else 0.0
            runs.append(
                {
                    "run": name,
                    "direction": direction,
                    "worst_ratio_to_along_x": worst,
                    "wall_s": hist.wall_s,
                    "steps": hist.steps,
                }
            )
            rows += [
                {
                    "run": name,
                    "direction": direction,
                    "t_us": round(t * 1e6, 3),
                    "neck": round(n, 6),
                }
                for t, n in zip(hist.times, hist.neck, strict=True)
            ]
            print(
                f"{name:14s} {direction:4s} neck / 2R {' '.join(f'{n:.4f}' for n in hist.neck)}"
                f"  worst ratio to x {worst * 100:5.2f} %  ({hist.steps} steps, "
                f"{hist.wall_s:.0f} s)",
                flush=True,
            )
    write_rows(out / "isotropy3d.csv", rows)
    atomic_write_text(out / "isotropy3d.json", json.dumps(runs, indent=1) + "\n")
    return 0


GOLDEN_KEYS = (
    "contact_line_um",
    "neck_median_um",
    "relative_density",
    "contacts_fused",
    "contacts_melted_through",
    "J_min",
    "T_peak_C",
)


def golden(out: Path) -> int:
    """The golden runs with each dilatation (module docstring)."""
    import importlib.util
    import tempfile

    import taichi_sls as sls

    path = Path(__file__).resolve().parents[1] / "tests" / "jobs" / "test_golden_runs.py"
    spec = importlib.util.spec_from_file_location("golden_runs", path)
    runs = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(runs)
    rows = []
    for name, (case_name, overrides, _) in runs.RUNS.items():
        for dilatation in ("point", "cell"):
            sets = runs.COMMON + overrides + [f"solver.dilatation={dilatation}"]
            with tempfile.TemporaryDirectory() as folder:
                summary = sls.run_case(sls.load_case(case_name, sets), Path(folder), progress=False)
                last = runs._table(Path(folder) / "timeseries.csv")[-1]
            row = {"run": name, "case": case_name, "dilatation": dilatation}
            row |= {k: float(last[k]) for k in GOLDEN_KEYS if k in last}
            row["fused"] = summary.get("outcome", {}).get("fused")
            rows.append(row)
            print(json.dumps(row), flush=True)
    atomic_write_text(out / "isotropy_golden.json", json.dumps(rows, indent=1) + "\n")
    return 0
