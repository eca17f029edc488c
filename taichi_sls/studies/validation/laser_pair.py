"""The laser-pulsed pair (issue 54, item 2b): ``taichi-sls bench laserpair [--out renders]``.

``cases/validation/pulse_pair_laser.toml`` under its 192 uJ pulse. **A calibration, said so**:
the absorbed fraction A is found by bisection (:func:`calibrate_absorptivity`, short runs
through the pulse) so that the computed peak of the hottest point is the measured 211 C; then
one run to the case's end compares the cooling (the hottest point's and the mean temperature)
with the measured temperature at ``COOLING_S``, and the neck with the measured one (the case's
``output.validation``). Writes validation_laser_pair.csv and validation_laser_pair.png.
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np

from ...config.loading import bundled_root
from ...io.atomic import write_rows
from .measured import load_pulse_temperature

CASE_PATH = Path("validation") / "pulse_pair_laser.toml"
COOLING_S = (0.1, 0.2, 0.4)
PULSE_END_S = 2e-3  # a bisection run: the 1 ms pulse and the first ms after it
PEAK_TOLERANCE_K = 1.0  # the bisection stops within 1 K of the measured peak


def run_laser(absorptivity: float, end_s: float, out: Path, extra: tuple[str, ...] = ()) -> dict:
    """The case at ``absorptivity`` to ``end_s``: its time series as columns (numpy arrays)."""
    from ...config import load_case
    from ...jobs.case_run import run_case
    from .neck import validation_observers

    sets = [f"lasers.0.absorptivity={absorptivity!r}", f"time.end_s={end_s!r}", *extra]
    case = load_case(bundled_root() / CASE_PATH, sets)
    summary = run_case(case, out, progress=False, observers=validation_observers(case, out))
    if summary["status"] != "complete":
        raise RuntimeError(f"A = {absorptivity}: the run ended {summary['status']}")
    print(
        f"A = {absorptivity:.4f}: {summary['steps']} steps, {summary['wall_s']:.0f} s",
        file=sys.stderr,
    )
    with (out / "timeseries.csv").open() as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def peak_C(series: dict) -> float:
    """The hottest point's highest temperature over the run (C)."""
    return float(np.max(series["T_max_C"]))


def calibrate_absorptivity(
    target_C: float, lo: float, hi: float, runs: Path, iterations: int = 7
) -> tuple[float, list[tuple[float, float]]]:
    """Bisection on A in [lo, hi] for a peak of ``target_C`` (the peak rises with A); stops
    within ``PEAK_TOLERANCE_K``. Returns A and every (A, peak) tried."""
    tried = []
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        peak = peak_C(run_laser(mid, PULSE_END_S, runs / f"A{mid:.4f}"))
        tried.append((mid, peak))
        if abs(peak - target_C) <= PEAK_TOLERANCE_K:
            break
        lo, hi = (mid, hi) if peak < target_C else (lo, mid)
    return tried[-1][0], tried


def cooling_rows(series: dict) -> list[dict]:
    """The computed hottest-point and mean temperature at ``COOLING_S`` beside the measured one
    (linear between the measured points)."""
    measured = load_pulse_temperature()
    mt = np.array([p.t_s for p in measured])
    mT = np.array([p.T_C for p in measured])
    t = series["t_s"]
    rows = []
    for ts in COOLING_S:
        m = float(np.interp(ts, mt, mT))
        tmax = float(np.interp(ts, t, series["T_max_C"]))
        tmean = float(np.interp(ts, t, series["T_mean_C"]))
        rows.append(
            {
                "t_s": ts,
                "T_max_C": tmax,
                "T_mean_C": tmean,
                "measured_C": m,
                "error_max_K": tmax - m,
                "error_mean_K": tmean - m,
            }
        )
    return rows


def plot_cooling(series: dict, path: Path) -> None:
    """The hottest point's and the mean temperature against time beside the measured one."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from ...io.frame_panels import save_png

    measured = load_pulse_temperature()
    fig = Figure(figsize=(7, 4))
    ax = fig.subplots()
    t = series["t_s"]
    ax.semilogx(t, series["T_max_C"], label="computed: hottest point")
    ax.semilogx(t, series["T_mean_C"], label="computed: mean of the pair")
    ax.semilogx(
        [p.t_s for p in measured if p.t_s > 0],
        [p.T_C for p in measured if p.t_s > 0],
        "o",
        color="#d62728",
        ms=3,
        label="measured (thermal imaging, digitised)",
    )
    ax.set_xlabel("time after the pulse's start (s)")
    ax.set_ylabel("T (C)")
    ax.set_title(
        "pulse_pair_laser: A calibrated on the 211 C peak; the cooling predicted", fontsize=9
    )
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    save_png(fig, path, 90)


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("laserpair", help="the laser-pulsed pair: A on the peak, the cooling")
    ap.add_argument("--out", default="renders", help="folder for validation_laser_pair.*")
    ap.add_argument("--runs", default="out/bench_laserpair", help="folder of the runs")
    ap.add_argument("--lo", type=float, default=0.0, help="bisection: lowest A")
    ap.add_argument("--hi", type=float, default=2.0, help="bisection: highest A")
    ap.add_argument("--end-s", type=float, default=1.0, help="the full run's end (s)")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out, runs = Path(args.out), Path(args.runs)
    out.mkdir(parents=True, exist_ok=True)
    target = max(p.T_C for p in load_pulse_temperature())
    A, tried = calibrate_absorptivity(target, args.lo, args.hi, runs)
    for a, peak in tried:
        print(f"bisection: A = {a:.4f} peak {peak:.2f} C (target {target:.2f} C)")
    series = run_laser(A, args.end_s, runs / "full")
    rows = cooling_rows(series)
    write_rows(out / "validation_laser_pair.csv", rows)
    plot_cooling(series, out / "validation_laser_pair.png")
    print(f"calibrated A = {A:.4f}; peak {peak_C(series):.2f} C")
    for r in rows:
        print(
            f"t = {r['t_s']:g} s: hottest {r['T_max_C']:.1f} C, mean {r['T_mean_C']:.1f} C, "
            f"measured {r['measured_C']:.1f} C"
        )
    return 0
