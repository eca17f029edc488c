"""A melt that lives for a second (cases/sinter_hold.toml) against Hopper's coalescence at the
temperature the run records: ``taichi-sls bench hold [--out renders] [--set KEY=VALUE]``.

Hopper's dimensionless time for a Newtonian liquid of viscosity eta_N is tau = gamma t /
(eta_N R0) (references.hopper); the zero-yield Perzyna melt is Newtonian with eta_N = eta(T) / 2
(Table 3's law). At a varying temperature the clock runs at gamma / (eta_N(T(t)) R0), integrated
(trapezoids) over the time series' rows at the pair's mean temperature. The clocks are aligned
at ``align_s``, after the pulse and the melting: there Hopper's neck is the run's, and from there
on the prediction is Hopper's neck at tau_align + the integral. Writes sinter_hold.csv (the
series with the prediction beside it) and sinter_hold.png, and prints the neck against the
prediction at 0.1, 0.3 and 1 s.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from ..config import Material, load_case
from ..config.loading import add_set_argument
from ..io.atomic import write_rows
from ..io.series import read_series
from ..jobs.case_run import complete_summary, run_case
from ..physics.materials import KELVIN
from . import references as ref

CASE = "sinter_hold"
ALIGN_S = 1e-3  # the pulse is over and the pair molten through by then
REPORT_S = (0.1, 0.3, 1.0)


def newtonian_viscosity(m: Material, T_C: np.ndarray) -> np.ndarray:
    """eta_N = eta(T) / 2 of the zero-yield Perzyna melt (Pa s) at temperatures T_C."""
    T_C = np.asarray(T_C, dtype=float)
    if m.viscosity_model == "constant":
        return np.full_like(T_C, 0.5 * m.viscosity_Pas)
    if m.viscosity_model == "arrhenius":  # the law is eta_N itself (config/materials.py)
        T_ref = m.viscosity_ref_C + KELVIN
        E = m.viscosity_activation_J_mol
        return ref.arrhenius_viscosity(T_C + KELVIN, m.viscosity_ref_Pas, T_ref, E)
    return 0.5 * m.viscosity_A_Pas * np.exp(-m.viscosity_b_1_C * T_C)


def hopper_clock(
    t_s: np.ndarray, T_C: np.ndarray, neck_um: np.ndarray, m: Material, R0_um: float, align_s: float
) -> np.ndarray:
    """Hopper's time tau at each row from align_s on (NaN before): tau_align, where Hopper's
    neck is the run's at align_s, plus int gamma dt / (eta_N(T(t)) R0) at the recorded
    temperature (trapezoids over the rows; module docstring)."""
    rate = m.surface_tension_N_m / (newtonian_viscosity(m, T_C) * R0_um * 1e-6)
    tau = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t_s))])
    neck0 = float(np.interp(align_s, t_s, neck_um))
    tau_rel = tau - float(np.interp(align_s, t_s, tau))
    tau_align = ref.hopper_tau_at_neck(0.5 * neck0 / R0_um)
    return np.where(t_s >= align_s, tau_align + tau_rel, math.nan)


def hopper_at_history(
    t_s: np.ndarray, T_C: np.ndarray, neck_um: np.ndarray, m: Material, R0_um: float, align_s: float
) -> np.ndarray:
    """Hopper's neck (um) at each row from align_s on (NaN before) on :func:`hopper_clock`."""
    tau = hopper_clock(t_s, T_C, neck_um, m, R0_um, align_s)
    out = np.full_like(t_s, math.nan, dtype=float)
    after = t_s >= align_s
    out[after] = 2.0 * R0_um * ref.hopper_neck_at(tau[after])
    return out


def compare(out_dir: Path, align_s: float = ALIGN_S) -> list[dict]:
    """The rows of a finished hold run in out_dir with Hopper's prediction beside them."""
    case = load_case(str(out_dir / "case.toml"))
    s = read_series(out_dir / "timeseries.csv")
    m = next(iter(case.materials.values()))
    R0 = case.bodies[0].radius_um
    tau = hopper_clock(s["t_s"], s["T_mean_C"], s["contact_line_um"], m, R0, align_s)
    pred = hopper_at_history(s["t_s"], s["T_mean_C"], s["contact_line_um"], m, R0, align_s)
    eta_N = newtonian_viscosity(m, s["T_mean_C"])
    return [
        {
            "t_s": float(t),
            "dt_s": float(dt),
            "T_mean_C": float(T),
            "eta_N_Pa_s": float(e),
            "tau": float(c),
            "molten_fraction": float(f),
            "neck_um": float(n),
            "hopper_neck_um": float(p),
            "difference": float(n / p - 1.0) if p == p else math.nan,
        }
        for t, dt, T, e, c, f, n, p in zip(
            s["t_s"],
            s["dt_s"],
            s["T_mean_C"],
            eta_N,
            tau,
            s["molten_fraction"],
            s["contact_line_um"],
            pred,
            strict=True,
        )
    ]


def plot(rows: list[dict], path: Path) -> None:
    """Neck against time beside Hopper's at the recorded temperature, and the temperature."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.array([r["t_s"] for r in rows])
    keep = t > 0
    fig, (a, b) = plt.subplots(2, 1, figsize=(6.4, 5.6), sharex=True)
    a.semilogx(t[keep], [r["neck_um"] for r in rows if r["t_s"] > 0], "o-", ms=3, label="run")
    a.semilogx(t[keep], [r["hopper_neck_um"] for r in rows if r["t_s"] > 0], "k--", label="Hopper")
    a.set_ylabel("neck (um)")
    a.legend(title="at the recorded temperature")
    b.semilogx(t[keep], [r["T_mean_C"] for r in rows if r["t_s"] > 0], "r-")
    b.set_ylabel("mean temperature (C)")
    b.set_xlabel("time (s)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("hold", help="a laser-melted pair sintering for a second, against Hopper")
    ap.add_argument("--out", default="renders", help="folder for sinter_hold.csv and .png")
    ap.add_argument("--runs", default="out/bench_hold", help="folder of the run")
    add_set_argument(ap, "override of the case")
    ap.set_defaults(func=main)


def run_or_reuse(case: str, overrides: list[str], runs: str) -> tuple[Path, dict]:
    """The run of ``case`` under ``runs``: its folder and summary, run only if not complete."""
    run_dir = Path(runs) / case
    summary = complete_summary(run_dir)
    if summary is None:
        summary = run_case(load_case(case, overrides), run_dir)
    return run_dir, summary


def print_against_hopper(rows: list[dict], key: str, at: tuple[float, ...], label: str) -> None:
    """The neck against Hopper's at each of ``at`` (of the column ``key``) that the rows reach,
    each line headed by ``label`` formatted with the value (``"t = {:g} s"``)."""
    x = np.array([r[key] for r in rows])
    for xq in at:
        if xq <= x[-1] * (1 + 1e-9):
            T, neck, hopper = (
                float(np.interp(xq, x, [r[k] for r in rows]))
                for k in ("T_mean_C", "neck_um", "hopper_neck_um")
            )
            print(
                f"{label.format(xq)}: T_mean {T:.1f} C, neck {neck:.2f} um, Hopper {hopper:.2f} um "
                f"({neck / hopper - 1:+.2%})"
            )


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    run_dir, summary = run_or_reuse(CASE, args.set, args.runs)
    rows = compare(run_dir)
    write_rows(out / "sinter_hold.csv", rows)
    plot(rows, out / "sinter_hold.png")
    print(
        f"{CASE}: {summary['steps']} steps ({summary.get('refused_steps', 0)} redone) to "
        f"{summary['simulated_s']:g} s in {summary['step_wall_s']:.1f} s of stepping",
        file=sys.stderr,
    )
    print_against_hopper(rows, "t_s", REPORT_S, "t = {:g} s")
    return 0
