"""The sphere pair's neck beside the models of viscous sintering, and its convergence in h:
``taichi-sls bench spherepair --plot renders/sphere_pair_r8_octant.csv ... [--out renders]``.

Two models of two equal Newtonian spheres (radius R, surface tension gamma, viscosity eta)
coalescing, in tau = gamma t / (eta R):

- Frenkel (1945), the early law from an energy balance with a small neck: (x / R)^2 = 3 tau / 2,
  taken here from the run's seeded neck x0, (x / R)^2 = (x0 / R)^2 + 3 tau / 2.
- Pokluda, Bellehumeur & Vlachopoulos (1997, AIChE J 43(12) 3253), Frenkel's balance over the
  whole coalescence with the spheres as two truncated spheres of radius a(theta) that keep the
  volume: d theta / d tau = 2^(-5/3) cos(theta) sin(theta) (2 - cos(theta))^(1/3) /
  ((1 - cos(theta)) (1 + cos(theta))^(1/3)), a / R = (4 / ((1 + cos)^2 (2 - cos)))^(1/3),
  x = a sin(theta); it ends at theta = pi / 2, one sphere of radius 2^(1/3) R. Its small-theta
  limit is (x / R)^2 = tau: slower than Frenkel's 3 tau / 2 by the factor 2/3 that Eshelby's
  correction of Frenkel's flow gives.

Neither is exact (the 3D pair has no closed form); the figures state where the run lies between
them. The convergence in h compares the two finest runs' x / R at the same tau, and with their
clocks aligned where x / R first reaches ``ALIGN`` (the seeded neck, a cell-sized contact, sets
the early clock at each resolution, as it does for Hopper's pair in 2D).
"""

from __future__ import annotations

import csv
import math
import re
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

END_STATE = 2.0 ** (1.0 / 3.0)  # the coalesced sphere's radius over R
ALIGN = 0.6  # x / R at which the clocks of two resolutions are aligned
FROM_TAU = 0.5  # the convergence is read from here on (past the seeded contact's transient)


def frenkel_neck(tau: np.ndarray, x0: float = 0.0) -> np.ndarray:
    """Frenkel's early law from a neck x0 / R at tau = 0: sqrt(x0^2 + 3 tau / 2)."""
    return np.sqrt(x0 * x0 + 1.5 * np.asarray(tau, dtype=float))


def _pokluda_radius(theta: float | np.ndarray) -> float | np.ndarray:
    c = np.cos(theta)
    return np.cbrt(4.0 / ((1.0 + c) ** 2 * (2.0 - c)))


def _pokluda_rate(theta: float) -> float:
    c, s = math.cos(theta), math.sin(theta)
    return (
        2.0 ** (-5.0 / 3.0)
        * c
        * s
        * (2.0 - c) ** (1.0 / 3.0)
        / ((1.0 - c) * (1.0 + c) ** (1.0 / 3.0))
    )


def pokluda_neck(tau: np.ndarray, x0: float = 1e-3) -> np.ndarray:
    """Pokluda et al.'s neck x / R at the given tau (>= 0, any order) from a neck x0 / R at
    tau = 0, tending to the end state 2^(1/3) as theta tends to pi / 2."""
    tau, back = np.unique(np.asarray(tau, dtype=float), return_inverse=True)
    theta = np.linspace(1e-9, 0.5 * math.pi, 200001)
    neck = _pokluda_radius(theta) * np.sin(theta)
    theta0 = float(np.interp(x0, neck, theta))  # x(theta) rises monotonically to pi / 2
    end = 0.5 * math.pi - 1e-9
    sol = solve_ivp(
        lambda t, y: [_pokluda_rate(min(y[0], end))],
        (0.0, float(tau.max())),
        [theta0],
        t_eval=tau,
        rtol=1e-10,
        atol=1e-12,
    )
    th = np.minimum(sol.y[0], 0.5 * math.pi)
    return (_pokluda_radius(th) * np.sin(th))[back]


def load_run(path: str | Path) -> dict[str, np.ndarray]:
    """One table of ``taichi-sls bench spherepair`` as arrays, with its R/h read from the name
    (sphere_pair_r<R/h>[_octant].csv; NaN where the name does not say)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    run = {k: np.array([float(r[k]) for r in rows]) for k in rows[0] if k}
    found = re.search(r"_r([0-9.]+?)(?:_octant)?\.csv$", Path(path).name)
    run["r_over_h"] = np.array(float(found.group(1)) if found else math.nan)
    return run


def first_reach(tau: np.ndarray, x: np.ndarray, level: float) -> float:
    """The tau at which x first reaches ``level`` (linear between frames)."""
    k = int(np.argmax(x >= level))
    if x[k] < level or k == 0:
        return math.nan
    return float(tau[k - 1] + (tau[k] - tau[k - 1]) * (level - x[k - 1]) / (x[k] - x[k - 1]))


def convergence(coarse: dict, fine: dict) -> dict[str, float]:
    """The largest relative difference of x / R between two runs from FROM_TAU on: at the same
    tau, and with the coarse run's clock shifted to reach ALIGN when the fine one does."""
    tau = fine["tau"][fine["tau"] >= FROM_TAU]
    tau = tau[tau <= coarse["tau"].max()]
    same = np.interp(tau, coarse["tau"], coarse["x_over_R"]) / np.interp(
        tau, fine["tau"], fine["x_over_R"]
    )
    shift = first_reach(coarse["tau"], coarse["x_over_R"], ALIGN) - first_reach(
        fine["tau"], fine["x_over_R"], ALIGN
    )
    ok = tau + shift <= coarse["tau"].max()
    aligned = np.interp(tau[ok] + shift, coarse["tau"], coarse["x_over_R"]) / np.interp(
        tau[ok], fine["tau"], fine["x_over_R"]
    )
    return {
        "same_tau": float(np.max(np.abs(same - 1.0))),
        "aligned": float(np.max(np.abs(aligned - 1.0))),
        "clock_shift": shift,
    }


def draw(runs: list[dict], png: Path) -> None:
    """x / R (solid) and the half-length L / R (dashed) of every run against tau, beside
    Frenkel and Pokluda et al. from the finest run's seeded neck."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fine = runs[-1]
    tau = np.linspace(0.0, max(float(r["tau"].max()) for r in runs), 400)
    x0 = float(fine["x_over_R"][0])
    fig, ax = plt.subplots(figsize=(7.0, 4.6), dpi=110)
    for i, run in enumerate(runs):
        label = f"MPM, R/h = {float(run['r_over_h']):g}"
        ax.plot(run["tau"], run["x_over_R"], "-o", ms=3, color=f"C{i}", label=label + ": neck x/R")
        ax.plot(
            run["tau"], run["length_over_R"], "--", color=f"C{i}", label=label + ": half-length"
        )
    ax.plot(
        tau, frenkel_neck(tau, x0), ":", color="k", label="Frenkel (1945), from the seeded neck"
    )
    ax.plot(tau, pokluda_neck(tau, x0), "-", color="0.5", label="Pokluda et al. (1997), same start")
    ax.axhline(END_STATE, color="0.3", lw=0.8)
    ax.text(
        0.02,
        END_STATE + 0.01,
        "one sphere: 2^(1/3) R",
        fontsize=8,
        transform=ax.get_yaxis_transform(),
    )
    ax.set_xlabel("tau = gamma t / (eta R)")
    ax.set_ylabel("x / R, L / R")
    ax.set_ylim(0.0, 2.05)
    ax.set_title("Two liquid spheres coalescing (3D MPM, surface-energy force)")
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png)
    plt.close(fig)


def report_main(paths: list[str], out: Path) -> int:
    """Draw OUT/sphere_pair.png from the tables (ordered by R/h) and print the end state of
    the finest, how the two finest converge, and where the models lie."""
    runs = sorted((load_run(p) for p in paths), key=lambda r: float(r["r_over_h"]))
    draw(runs, out / "sphere_pair.png")
    fine = runs[-1]
    end = {k: float(fine[k][-1]) for k in ("tau", "x_over_R", "length_over_R", "volume_change")}
    print(
        f"R/h = {float(fine['r_over_h']):g} at tau {end['tau']:.2f}: x/R {end['x_over_R']:.4f} "
        f"({end['x_over_R'] / END_STATE - 1:+.2%} of 2^(1/3)), L/R {end['length_over_R']:.4f} "
        f"({end['length_over_R'] / END_STATE - 1:+.2%}), volume {end['volume_change']:+.3%}"
    )
    poke = pokluda_neck(fine["tau"], float(fine["x_over_R"][0]))
    for mark in (0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0):
        k = int(np.argmin(np.abs(fine["tau"] - mark)))
        if abs(fine["tau"][k] - mark) < 0.05:
            x, p = fine["x_over_R"][k], poke[k]
            print(f"  tau {fine['tau'][k]:.2f}: x/R {x:.4f}, Pokluda {p:.4f} ({x / p - 1:+.1%})")
    if len(runs) > 1:
        c = convergence(runs[-2], fine)
        print(
            f"R/h {float(runs[-2]['r_over_h']):g} against {float(fine['r_over_h']):g} from tau "
            f"{FROM_TAU}: {c['same_tau']:.2%} at the same tau, {c['aligned']:.2%} with clocks "
            f"aligned at x/R = {ALIGN} (shift {c['clock_shift']:+.3f})"
        )
    print(f"wrote {out / 'sphere_pair.png'}")
    return 0
