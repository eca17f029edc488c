"""A pair in the sintering window against Hopper (cases/pair_window.toml):
``taichi-sls bench window [--out renders] [--set KEY=VALUE]``.

The paper's pulse melts a PA12 pair on a 172 C bed; the melt lives (crystallisation kinetics)
and coalesces. Its neck (the per-contact section across the centres) is set beside Hopper's
solution on the clock tau = tau_align + int gamma dt / (eta_N(T(t)) R0) at the pair's mean
temperature as the run records it (studies/sinter_hold.py: :func:`hopper_clock`), aligned at
``ALIGN_S`` after the pulse, up to tau = ``TAU_END``. Writes pair_window.csv (the series with
the clock and Hopper's neck beside it) and pair_window.png (neck against tau, the difference,
the temperature and the viscosity), and prints the neck against Hopper at tau = 0.5, 1, 1.5, 2.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from ..config import load_case
from ..config.loading import add_set_argument
from ..io.atomic import write_rows
from .sinter_hold import compare, print_against_hopper, run_or_reuse

CASE = "pair_window"
ALIGN_S = 1e-3  # the pulse is over and the pair molten through by then
TAU_END = 2.0  # the comparison's range: the neck within 5 % of Hopper's at every tau up to 2
REPORT_TAU = (0.5, 1.0, 1.5, 2.0)


def window_rows(out_dir: Path, align_s: float = ALIGN_S, tau_end: float = TAU_END) -> list[dict]:
    """The rows of a finished pair_window run from align_s to the first row at or past
    tau_end, with Hopper's clock and neck beside them (:func:`studies.sinter_hold.compare`)."""
    rows = [r for r in compare(out_dir, align_s) if r["tau"] == r["tau"]]
    past = [k for k, r in enumerate(rows) if r["tau"] >= tau_end]
    return rows[: past[0] + 1] if past else rows


def plot(rows: list[dict], R0_um: float, path: Path) -> None:
    """Neck / R0 against tau beside Hopper's, their difference, and the temperature and
    viscosity the clock ran on, against time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    col = {k: np.array([r[k] for r in rows]) for k in rows[0]}
    fig, ((a, b), (c, d)) = plt.subplots(2, 2, figsize=(10, 6.4))
    a.plot(col["tau"], 0.5 * col["neck_um"] / R0_um, "o", ms=3, label="run (filtered colour)")
    a.plot(col["tau"], 0.5 * col["hopper_neck_um"] / R0_um, "k-", label="Hopper")
    a.axhline(1.0, color="0.6", lw=0.8, ls=":")
    a.set_xlabel("tau = int gamma dt / (eta_N(T) R0)")
    a.set_ylabel("r_n / R0")
    a.legend(title="at the recorded temperature")
    b.plot(col["tau"], 100.0 * col["difference"], "o-", ms=3)
    for y in (-5.0, 5.0):
        b.axhline(y, color="r", lw=0.8, ls="--")
    b.set_xlabel("tau")
    b.set_ylabel("run / Hopper - 1 (%)")
    c.semilogx(col["t_s"], col["T_mean_C"], "r-")
    c.set_xlabel("time (s)")
    c.set_ylabel("mean temperature (C)")
    d.semilogx(col["t_s"], col["eta_N_Pa_s"], "b-")
    d.set_xlabel("time (s)")
    d.set_ylabel("eta_N (Pa s)")
    fig.suptitle("a laser-melted PA12 pair on a 172 C bed against Hopper")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("window", help="a laser-melted pair on a 172 C bed, against Hopper")
    ap.add_argument("--out", default="renders", help="folder for pair_window.csv and .png")
    ap.add_argument("--runs", default="out/bench_window", help="folder of the run")
    add_set_argument(ap, "override of the case")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    run_dir, summary = run_or_reuse(CASE, args.set, args.runs)
    rows = window_rows(run_dir)
    write_rows(out / "pair_window.csv", rows)
    R0 = load_case(str(run_dir / "case.toml")).bodies[0].radius_um
    plot(rows, R0, out / "pair_window.png")
    print(
        f"{CASE}: {summary['steps']} steps to {summary['simulated_s']:g} s in "
        f"{summary['step_wall_s']:.1f} s of stepping; worst |difference| to tau = "
        f"{rows[-1]['tau']:.2f}: {max(abs(r['difference']) for r in rows):.2%}",
        file=sys.stderr,
    )
    print_against_hopper(rows, "tau", REPORT_TAU, "tau = {:g}")
    return 0 if math.isfinite(rows[-1]["tau"]) else 1
