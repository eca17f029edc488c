"""The hot-stage pairs (issue 54, item 3): ``taichi-sls bench hotstage [--out renders]``.

The eleven measured series (virgin PA12 pairs, R = 25.8-37.9 um, a / R against time; the stage
temperature is not recorded) beside a 2D pair of the sourced process material held at one
constant temperature. **A calibration, said so**: one temperature is found at which the sourced
viscosity law (``pa12_process``) reproduces one series (``CALIBRATION_SERIES``) at a / R =
``CALIBRATION_NECK``; the other ten are then predicted from their radii alone.

No root-find of many runs: a Newtonian viscous pair's a / R is a function of
tau = gamma t / (eta_0(T) R) alone (inertia and the melt's Maxwell time negligible, the
geometry and grid self-similar: every length of the case scales with R), so one run's a / R
against tau serves every radius and temperature. A second run at another radius and
temperature checks that (:func:`scaling_gap`). The run starts from a grid-seeded neck
(a / R about 0.24 at R / h = 20), not from a point: its tau is shifted by Hopper's time to
that neck (:func:`shifted_tau`), the exact 2D solution's, so that tau = 0 is a point contact
as in the measured series.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ...config.loading import bundled_root
from ...io.atomic import write_rows
from ...jobs.run_loop import Frame, Observer
from ..references.hopper import hopper_tau_at_neck
from ..references.viscosity import GAS_CONSTANT, arrhenius_viscosity
from .measured import NeckPoint, load_hot_stage
from .neck import pair_radius_um

CASE_PATH = Path("validation") / "pulse_pair_temperature.toml"
CALIBRATION_SERIES = "Exp21"  # the median radius of the ten Exp series; crosses 0.5 at 1.5-2 s
CALIBRATION_NECK = 0.5
PREDICTED_NECKS = (0.5, 1.0)
KELVIN = 273.15
FRAMES = 200  # a / R read between frames, linear in time
# the calibration run and the scaling check: radius (um), held temperature (C), process time (s)
CALIBRATION_RUN = (32.16, 200.0, 5.0)
SCALING_RUN = (25.84, 220.0, 3.0)


@dataclass(frozen=True)
class PairRun:
    """One held 2D pair: its radius (um), held temperature (C), eta_0 there (Pa s), gamma
    (N/m), and a / R against time (s)."""

    radius_um: float
    T_C: float
    eta_Pas: float
    gamma_N_m: float
    t_s: np.ndarray
    a_over_R: np.ndarray

    def tau(self) -> np.ndarray:
        """gamma t / (eta_0 R): the dimensionless time."""
        return self.gamma_N_m * self.t_s / (self.eta_Pas * self.radius_um * 1e-6)


class NeckSeries(Observer):
    """a / R of a pair (bodies 0 and 1 of radius ``radius_um``) at every frame."""

    def __init__(self, radius_um: float) -> None:
        self.radius_um = radius_um
        self.t: list[float] = []
        self.a: list[float] = []

    def frame(self, frame: Frame) -> None:
        self.t.append(float(frame.sim.t))
        self.a.append(0.5 * frame.monitors["contact_line_um"] / self.radius_um)

    def state(self) -> dict[str, Any]:
        return {"t": self.t, "a": self.a}

    def restore(self, state: dict[str, Any]) -> None:
        self.t, self.a = list(state.get("t", [])), list(state.get("a", []))


def pair_overrides(radius_um: float, T_C: float, table: Path, end_s: float) -> list[str]:
    """The held pulsed pair (``CASE_PATH``) scaled to ``radius_um``, every length with R (grid,
    domain, centres, fillet), held at ``T_C``."""
    from ...config import load_case

    base = load_case(bundled_root() / CASE_PATH)
    s = radius_um / pair_radius_um(base)
    b0, b1 = (list(b.center_um) for b in base.bodies[:2])
    return [
        f"grid.spacing_um={base.grid.spacing_um * s!r}",
        f"domain.width_um={base.domain.width_um * s!r}",
        f"domain.height_um={base.domain.height_um * s!r}",
        f"bodies.0.radius_um={radius_um!r}",
        f"bodies.1.radius_um={radius_um!r}",
        f"bodies.0.center_um=[{b0[0] * s!r}, {b0[1] * s!r}]",
        f"bodies.1.center_um=[{b1[0] * s!r}, {b1[1] * s!r}]",
        f"contact.fillet_radius_um={base.contact.fillet_radius_um * s!r}",
        f"thermal.initial_C={T_C!r}",
        f'thermal.imposed_temperature_csv="{table}"',
        f"time.end_s={end_s!r}",
        'output.validation="none"',
        "output.spacing=linear",
        f"output.frames={FRAMES}",
        "output.png=false",
    ]


def run_pair(radius_um: float, T_C: float, end_s: float, runs: str | Path) -> PairRun:
    """Run the 2D pair of ``radius_um`` held at ``T_C`` to ``end_s``."""
    from ...config import load_case
    from ...jobs.case_run import run_case

    out = Path(runs) / f"R{radius_um:g}_T{T_C:g}"
    out.mkdir(parents=True, exist_ok=True)
    table = (out / "held.csv").resolve()
    table.write_text(f"t_s,T_C\n0.0,{T_C!r}\n{end_s!r},{T_C!r}\n")
    case = load_case(bundled_root() / CASE_PATH, pair_overrides(radius_um, T_C, table, end_s))
    obs = NeckSeries(radius_um)
    summary = run_case(case, out, progress=False, observers=[obs])
    if summary["status"] != "complete":
        raise RuntimeError(f"R = {radius_um} um at {T_C} C: the run ended {summary['status']}")
    mat = case.materials["PA12"]
    steps, wall = summary["steps"], summary["wall_s"]
    print(f"R = {radius_um:g} um at {T_C:g} C: {steps} steps, {wall:.0f} s", file=sys.stderr)
    eta = arrhenius_viscosity(
        T_C + KELVIN,
        mat.viscosity_ref_Pas,
        mat.viscosity_ref_C + KELVIN,
        mat.viscosity_activation_J_mol,
    )
    return PairRun(
        radius_um,
        T_C,
        float(eta),
        mat.surface_tension_N_m,
        np.array(obs.t),
        np.array(obs.a),
    )


def shifted_tau(run: PairRun) -> np.ndarray:
    """The run's tau, its origin moved back by Hopper's time to the run's first (seeded) neck:
    tau = 0 is then a point contact, as at the start of a measured series."""
    return run.tau() + hopper_tau_at_neck(float(run.a_over_R[0]))


def first_crossing(x: np.ndarray, a: np.ndarray, neck: float) -> float:
    """The first x at which ``a`` reaches ``neck``, linear between samples (NaN if never)."""
    above = np.nonzero(a >= neck)[0]
    if len(above) == 0:
        return math.nan
    i = int(above[0])
    if i == 0:
        return float(x[0])
    return float(np.interp(neck, [a[i - 1], a[i]], [x[i - 1], x[i]]))


def measured_time(points: list[NeckPoint], neck: float) -> float:
    """When a measured series first reaches ``neck`` (linear between its points; NaN if not)."""
    return first_crossing(
        np.array([p.t_s for p in points]), np.array([p.neck_over_radius for p in points]), neck
    )


@dataclass(frozen=True)
class Calibration:
    """The viscosity at which the run's a / R(tau) meets the calibration series at
    ``CALIBRATION_NECK``, and the temperature the sourced law gives it."""

    series: str
    radius_um: float
    t_measured_s: float
    tau: float
    eta_Pas: float
    T_C: float


def calibrate(
    run: PairRun, points: list[NeckPoint], eta_ref: float, T_ref_C: float, E_J_mol: float
) -> Calibration:
    """eta = gamma t_measured / (tau R) at ``CALIBRATION_NECK``, and the temperature at which
    the Arrhenius law (eta_ref at T_ref_C, activation E_J_mol) gives it."""
    t_m = measured_time(points, CALIBRATION_NECK)
    tau = first_crossing(shifted_tau(run), run.a_over_R, CALIBRATION_NECK)
    R = points[0].radius_um
    eta = run.gamma_N_m * t_m / (tau * R * 1e-6)
    inv_T = 1.0 / (T_ref_C + KELVIN) + GAS_CONSTANT / E_J_mol * math.log(eta / eta_ref)
    return Calibration(points[0].series, R, t_m, tau, eta, 1.0 / inv_T - KELVIN)


def predict(run: PairRun, cal: Calibration, series: dict[str, list[NeckPoint]]) -> list[dict]:
    """Each series' time to each of ``PREDICTED_NECKS`` from its radius alone (t = tau eta R /
    gamma at the calibrated eta) beside the measured one."""
    tau_run = shifted_tau(run)
    rows = []
    for name, points in series.items():
        R = points[0].radius_um
        for neck in PREDICTED_NECKS:
            tau = first_crossing(tau_run, run.a_over_R, neck)
            t_p = tau * cal.eta_Pas * R * 1e-6 / run.gamma_N_m
            t_m = measured_time(points, neck)
            rows.append(
                {
                    "series": name,
                    "radius_um": R,
                    "neck": neck,
                    "t_predicted_s": t_p,
                    "t_measured_s": t_m,
                    "error_s": t_p - t_m,
                    "relative_error": (t_p - t_m) / t_m if t_m > 0 else math.nan,
                    "calibrated_on": name == cal.series,
                }
            )
    return rows


def scaling_gap(a: PairRun, b: PairRun) -> dict[str, float]:
    """How far two runs' a / R against tau (each shifted to a point contact) differ: the
    largest |difference| in a / R over the tau both reach, and the relative difference of the
    tau at which each reaches each of ``PREDICTED_NECKS``."""
    ta, tb = shifted_tau(a), shifted_tau(b)
    lo, hi = max(ta[0], tb[0]), min(ta[-1], tb[-1])
    grid = np.linspace(lo, hi, 400)
    gap = {
        "max_abs_a_over_R": float(
            np.max(np.abs(np.interp(grid, ta, a.a_over_R) - np.interp(grid, tb, b.a_over_R)))
        )
    }
    for neck in PREDICTED_NECKS:
        xa = first_crossing(ta, a.a_over_R, neck)
        xb = first_crossing(tb, b.a_over_R, neck)
        gap[f"tau_rel_at_{neck:g}"] = (xb - xa) / xa
    return gap


def plot_hot_stage(
    runs: tuple[PairRun, PairRun],
    cal: Calibration,
    series: dict[str, list[NeckPoint]],
    path: Path,
) -> None:
    """Left: every measured series (points) and its prediction from its radius (line, the
    calibration series bold). Right: the two runs' a / R against tau beside Hopper's."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from ...io.frame_panels import save_png
    from ..references.hopper import hopper_neck_at

    fig = Figure(figsize=(12, 5))
    ax, axs = fig.subplots(1, 2, gridspec_kw={"width_ratios": [3, 2]})
    run = runs[0]
    tau_run = shifted_tau(run)
    colours = matplotlib.colormaps["viridis"]
    radii = sorted({p[0].radius_um for p in series.values()})
    for name, points in series.items():
        R = points[0].radius_um
        c = colours((R - radii[0]) / (radii[-1] - radii[0]))
        t = tau_run * cal.eta_Pas * R * 1e-6 / run.gamma_N_m
        bold = name == cal.series
        ax.plot(t, run.a_over_R, color=c, lw=2.5 if bold else 0.9)
        marker = "s" if name == "Zhao" else "o"
        label = f"{name} R = {R:g} um" + (" (calibrated on)" if bold else "")
        ax.plot(
            [p.t_s for p in points],
            [p.neck_over_radius for p in points],
            marker,
            color=c,
            ms=4,
            label=label,
        )
    for end, what in ((2 ** (1 / 3), "3D end 2^(1/3)"), (math.sqrt(2), "2D end sqrt 2")):
        ax.axhline(end, color="#999999", ls=":", lw=0.8)
        ax.text(0.1, end + 0.01, what, fontsize=7, color="#666666")
    ax.set_xlim(0, 16)
    ax.set_ylim(0, 1.5)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("a / R")
    ax.set_title(
        f"lines: 2D pair at eta_0 = {cal.eta_Pas:.0f} Pa s (pa12_process at {cal.T_C:.0f} C), "
        f"calibrated on {cal.series} at a / R = {CALIBRATION_NECK:g}",
        fontsize=9,
    )
    ax.legend(fontsize=7, ncol=2, loc="lower right")
    ax.grid(alpha=0.3)
    for r, style in zip(runs, ("-", "--"), strict=True):
        axs.plot(
            shifted_tau(r), r.a_over_R, style, label=f"run R = {r.radius_um:g} um, {r.T_C:g} C"
        )
    tau = np.linspace(0.0, float(shifted_tau(run)[-1]), 200)
    axs.plot(tau, hopper_neck_at(tau), ":", color="k", label="Hopper (exact 2D)")
    axs.set_xlabel("tau = gamma t / (eta_0 R)  (shifted to a point contact)")
    axs.set_ylabel("a / R")
    axs.set_title("the scaling: both runs against tau", fontsize=9)
    axs.legend(fontsize=8)
    axs.grid(alpha=0.3)
    fig.tight_layout()
    save_png(fig, path, 90)


PREDICTION_COLUMNS = [
    "series",
    "radius_um",
    "neck",
    "t_predicted_s",
    "t_measured_s",
    "error_s",
    "relative_error",
    "calibrated_on",
]


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("hotstage", help="the hot-stage pairs: one calibrated T, ten predicted")
    ap.add_argument("--out", default="renders", help="folder for validation_hot_stage.csv, .png")
    ap.add_argument("--runs", default="out/bench_hotstage", help="folder of the two runs")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    series = load_hot_stage()
    runs = (run_pair(*CALIBRATION_RUN, args.runs), run_pair(*SCALING_RUN, args.runs))
    from ...config import load_case

    mat = load_case(bundled_root() / CASE_PATH).materials["PA12"]
    cal = calibrate(
        runs[0],
        series[CALIBRATION_SERIES],
        mat.viscosity_ref_Pas,
        mat.viscosity_ref_C,
        mat.viscosity_activation_J_mol,
    )
    rows = predict(runs[0], cal, series)
    write_rows(out / "validation_hot_stage.csv", rows, PREDICTION_COLUMNS)
    plot_hot_stage(runs, cal, series, out / "validation_hot_stage.png")
    print(f"calibration: {cal}")
    print(f"scaling: {scaling_gap(*runs)}")
    for r in runs:
        print(
            f"R = {r.radius_um:g} um, {r.T_C:g} C: eta_0 {r.eta_Pas:.0f} Pa s, "
            f"a / R from {r.a_over_R[0]:.3f} to {r.a_over_R[-1]:.3f}"
        )
    for r in rows:
        print(
            f"{r['series']:>7} R {r['radius_um']:6.2f} a/R {r['neck']:.1f}: predicted "
            f"{r['t_predicted_s']:.2f} s measured {r['t_measured_s']:.2f} s error "
            f"{r['error_s']:+.2f} s ({r['relative_error']:+.0%})"
        )
    return 0
