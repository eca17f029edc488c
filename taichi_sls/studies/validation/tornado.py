"""The held pulsed pair's sensitivity to its inputs within their published ranges (issue 54,
item 2): ``taichi-sls bench tornado [--end-s 1] [--out renders] [--runs out/bench_tornado]``.

Each input is set to the low and to the high end of its range, one at a time, the rest as
``cases/validation/pulse_pair_temperature.toml`` has them, and the run's a / R is read at
``REPORT_S`` beside the measured neck (linear between the measured points). Every variant is
a ``--set`` of the case: the material preset is not changed, and nothing is fitted. Each
bound names where it comes from (``Variant.source``; docs/validation.md, the tornado). Writes
validation_tornado.csv and validation_tornado.png.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...config.loading import bundled_root
from ...io.atomic import write_rows
from .measured import NeckPoint, load_pulse_neck

# the measured times read (s): 0.9682 s is the last measured point of the record's first second
REPORT_S = (0.1, 0.5, 0.9682)
CASE_PATH = Path("validation") / "pulse_pair_temperature.toml"


@dataclass(frozen=True)
class Variant:
    """One bar end: the input, which end of its range, the ``--set`` that makes it, where the
    bound comes from."""

    name: str
    parameter: str
    end: str  # "low", "high" or "case"
    overrides: tuple[str, ...]
    source: str


# the case itself, then each input at its published bounds (docs/record/pa12_process.md)
VARIANTS = (
    Variant("case", "-", "case", (), "pulse_pair_temperature.toml: pa12_process unchanged"),
    Variant(
        "viscosity_low",
        "zero-shear viscosity eta_ref",
        "low",
        ("materials.PA12.viscosity_ref_Pas=2087.5",),
        "MKZ's reading of Zhao15's law as the Perzyna eta (2 eta_0): a melt half as viscous",
    ),
    Variant(
        "viscosity_high",
        "zero-shear viscosity eta_ref",
        "high",
        ("materials.PA12.viscosity_ref_Pas=4175.0",),
        "Zhao15's law itself at 172 C (the case's value: no virgin-powder source is higher)",
    ),
    Variant(
        "activation_low",
        "viscosity activation E",
        "low",
        ("materials.PA12.viscosity_activation_J_mol=32500.0",),
        "MDPM-MM Initialization.h l.49 (the case's value)",
    ),
    Variant(
        "activation_high",
        "viscosity activation E",
        "high",
        ("materials.PA12.viscosity_activation_J_mol=37200.0",),
        "Zhao15's local slope 0.02 R T^2 at 200 C (derived)",
    ),
    Variant(
        "surface_tension_low",
        "surface tension gamma",
        "low",
        ("materials.PA12.surface_tension_N_m=0.0343",),
        "MDPM-SLS l.82 (the case's value)",
    ),
    Variant(
        "surface_tension_high",
        "surface tension gamma",
        "high",
        ("materials.PA12.surface_tension_N_m=0.0363",),
        "MKZ Table 3 (after Zhao15)",
    ),
    Variant(
        "contact_low",
        "initial contact (fillet radius)",
        "low",
        ("contact.fillet_radius_um=0.25",),
        "a point contact (a / R = 0.06 as drawn; on this grid it seeds the case's points)",
    ),
    Variant(
        "contact_high",
        "initial contact (fillet radius)",
        "high",
        ("contact.fillet_radius_um=3.0",),
        "a / R = 0.195 as drawn: the measured neck at 26 ms, its first point, bounds it above",
    ),
)
COLUMNS = ["name", "parameter", "end", "overrides", "t_s", "computed", "measured", "error"]


def measured_at(points: list[NeckPoint], t_s: float) -> float:
    """The measured a / R at ``t_s``, linear between the measured points (NaN outside them)."""
    t = np.array([p.t_s for p in points])
    if not t[0] <= t_s <= t[-1]:
        return math.nan
    return float(np.interp(t_s, t, [p.neck_over_radius for p in points]))


def run_variant(
    variant: Variant, runs: str | Path, end_s: float, extra: tuple[str, ...] = ()
) -> tuple[np.ndarray, np.ndarray]:
    """Run the held pair under ``variant`` (and the overrides ``extra``) to ``end_s``; its
    frames' times (s) and a / R."""
    from ...config import load_case
    from ...jobs.case_run import run_case
    from .neck import NeckValidation

    case = load_case(
        bundled_root() / CASE_PATH, [*variant.overrides, f"time.end_s={end_s}", *extra]
    )
    out = Path(runs) / variant.name
    obs = NeckValidation(case, out)
    summary = run_case(case, out, progress=False, observers=[obs])
    if summary["status"] != "complete":
        raise RuntimeError(f"{variant.name}: the run ended {summary['status']}")
    print(f"{variant.name}: {summary['steps']} steps in {summary['wall_s']:.0f} s", file=sys.stderr)
    return np.array(obs.t), np.array(obs.a_over_R)


def rows_of(variant: Variant, t: np.ndarray, a: np.ndarray, measured: list[NeckPoint]) -> list:
    """The variant's a / R at each of ``REPORT_S`` the run reached, beside the measured one."""
    rows = []
    for ts in REPORT_S:
        computed = float(np.interp(ts, t, a)) if t[0] <= ts <= t[-1] else math.nan
        m = measured_at(measured, ts)
        rows.append(
            {
                "name": variant.name,
                "parameter": variant.parameter,
                "end": variant.end,
                "overrides": " ".join(variant.overrides),
                "t_s": ts,
                "computed": computed,
                "measured": m,
                "error": computed - m,
            }
        )
    return rows


def plot_tornado(rows: list[dict], path: Path) -> None:
    """One panel per reported time: each input's bar from its low to its high end, the case's
    a / R and the measured one as vertical lines."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from ...io.frame_panels import save_png

    params = list(dict.fromkeys(r["parameter"] for r in rows if r["end"] != "case"))
    fig = Figure(figsize=(11, 3.6))
    axes = fig.subplots(1, len(REPORT_S), sharey=True)
    for ax, ts in zip(axes, REPORT_S, strict=True):
        at = [r for r in rows if r["t_s"] == ts]
        base = next(r["computed"] for r in at if r["end"] == "case")
        meas = at[0]["measured"]
        for i, p in enumerate(params):
            lo = next(r["computed"] for r in at if r["parameter"] == p and r["end"] == "low")
            hi = next(r["computed"] for r in at if r["parameter"] == p and r["end"] == "high")
            ax.barh(i, hi - lo, left=lo, height=0.5, color="#1f77b4", alpha=0.7)
            ax.plot([lo], [i], "<", color="#1f77b4")
            ax.plot([hi], [i], ">", color="#1f77b4")
        ax.axvline(base, color="k", lw=1, label="the case")
        ax.axvline(meas, color="#d62728", ls="--", label="measured (digitised)")
        ax.set_title(f"t = {ts:g} s", fontsize=10)
        ax.set_xlabel("a / R")
        ax.set_xlim(0.15, 0.8)
        ax.grid(alpha=0.3)
    axes[0].set_yticks(range(len(params)), params, fontsize=8)
    axes[0].invert_yaxis()
    axes[-1].legend(loc="lower right", fontsize=8)
    fig.suptitle(
        "held pulsed pair (2D, R = 125 um): each input across its published range "
        "(< low end, > high end)",
        fontsize=10,
    )
    fig.tight_layout()
    save_png(fig, path, 90)


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("tornado", help="the held pulsed pair's a / R across published ranges")
    ap.add_argument("--end-s", type=float, default=1.0, help="process time of each run (s)")
    ap.add_argument("--out", default="renders", help="folder for validation_tornado.csv, .png")
    ap.add_argument("--runs", default="out/bench_tornado", help="folder of the runs")
    ap.add_argument("--only", nargs="*", default=None, help="variant names (default: all)")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    measured = load_pulse_neck()
    chosen = [v for v in VARIANTS if args.only is None or v.name in args.only]
    rows = []
    for v in chosen:
        t, a = run_variant(v, args.runs, args.end_s)
        rows += rows_of(v, t, a, measured)
    write_rows(out / "validation_tornado.csv", rows, COLUMNS)
    for r in rows:
        print(
            f"{r['name']:>22} t = {r['t_s']:<6g} a/R {r['computed']:.3f} "
            f"measured {r['measured']:.3f} error {r['error']:+.3f}"
        )
    if args.only is None:
        plot_tornado(rows, out / "validation_tornado.png")
    return 0
