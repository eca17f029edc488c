"""Monitored quantities, read once per output frame: temperatures, energies, Jacobian, contact line.

Contact line (the paper's neck length, Fig. 4). One definition, kept for every case: between the
mass centroids of bodies 0 and 1, take every vertical node column and measure the total length of
{y : phi(x, y) < 0} along it (phi linear between nodes); the contact line is the smallest such
length -- the narrowest vertical section of material between the two bodies. It follows the neck
when the pair slides, counts only material (a hole in the neck shortens it) and drops to zero when
the neck tears. ``neck_span_um`` reports, for the same column, the outer extent from the lowest to
the highest material (holes included): the silhouette's neck.

The material is {phi < 0} of eq. 21 (the paper's Fig. 4, with the point radius r_p) or
{c > 1/2} of the surface-energy colour (phi = 1/2 - c; the interface that force moves, no r_p;
``output.neck_measure``).
"""

from enum import IntEnum

import numpy as np

from taichi_sls.backend import ti

from ..physics.materials import KELVIN
from . import struct_copy
from .fields import State


class Trouble(IntEnum):
    """What the point reduction found wrong (the guard reads it)."""

    NONE = 0
    NAN = 1  # NaN in a position, temperature or Jacobian
    LEFT_GRID = 2  # a point beyond the ghost layer


def grid_reach(cfg) -> tuple[float, tuple[float, ...]]:
    """(lowest coordinate, highest per axis) in m that a point may reach with its stencil
    inside the arrays; beyond them it has left the grid (Trouble.LEFT_GRID)."""
    return -float(cfg.off - 1) * cfg.h, tuple(float(n - cfg.off - 2) * cfg.h for n in cfg.shape)


@ti.kernel
def reduce_points(st: ti.template()):
    """The totals of the points (fields.TOTALS)."""
    tot, pt = ti.static(st.totals, st.points)
    tot.T_max[None] = -1e30
    tot.J_min[None] = 1e30
    tot.T_min[None] = 1e30
    tot.J_max[None] = -1e30
    tot.v_max[None] = 0.0
    tot.mass_T[None] = 0.0
    tot.mass[None] = 0.0
    tot.molten_mass[None] = 0.0
    tot.enthalpy[None] = 0.0
    tot.kinetic_energy[None] = 0.0
    tot.trouble[None] = 0.0
    lo, hi = ti.static(grid_reach(st.cfg))
    # serial: float sums in a fixed order, so that monitors repeat bit for bit (resume test);
    # it runs once per output frame
    ti.loop_config(serialize=True)
    for p in range(st.cfg.n_points):
        m = pt.mass[p]
        T = pt.T[p]
        ti.atomic_max(tot.T_max[None], T)
        tot.mass_T[None] += m * T
        tot.mass[None] += m
        tot.molten_mass[None] += m * (1.0 - pt.solid_fraction[p])
        tot.enthalpy[None] += m * pt.enthalpy[p]
        tot.kinetic_energy[None] += 0.5 * m * pt.v[p].norm_sqr()
        ti.atomic_min(tot.J_min[None], pt.J[p])
        ti.atomic_min(tot.T_min[None], T)
        ti.atomic_max(tot.J_max[None], pt.J[p])
        ti.atomic_max(tot.v_max[None], pt.v[p].norm())
        x = pt.x[p]
        bad = float(Trouble.NONE)
        if not ((x == x).all() and T == T and pt.J[p] == pt.J[p]):
            bad = float(Trouble.NAN)
        elif (x < lo).any() or (x > ti.Vector(hi)).any():
            bad = float(Trouble.LEFT_GRID)
        ti.atomic_max(tot.trouble[None], bad)


def point_monitors(st: State) -> tuple[dict[str, float], dict[str, float]]:
    """(monitors for the time series, internal figures for the guard)."""
    reduce_points(st)
    r = {k: float(v) for k, v in struct_copy.to_numpy(st.totals).items()}
    public = {
        "T_max_C": r["T_max"] - KELVIN,
        "T_min_C": r["T_min"] - KELVIN,
        "T_mean_C": r["mass_T"] / r["mass"] - KELVIN,
        "molten_fraction": r["molten_mass"] / r["mass"],
        "enthalpy_J_per_m": r["enthalpy"],
        "kinetic_energy_J_per_m": r["kinetic_energy"],
        "J_min": r["J_min"],
    }
    internal = {
        "trouble": Trouble(int(r["trouble"])),
        "T_min_K": r["T_min"],
        "J_max": r["J_max"],
        "v_max": r["v_max"],
    }
    return public, internal


def column_material_length(phi_col: np.ndarray, h: float) -> float:
    """Total length where a piecewise-linear phi sampled every h is negative."""
    total = 0.0
    for a, b in zip(phi_col[:-1], phi_col[1:], strict=True):
        if a < 0 and b < 0:
            total += h
        elif a < 0 <= b:
            total += h * a / (a - b)
        elif b < 0 <= a:
            total += h * b / (b - a)
    return total


def column_span(phi_col: np.ndarray, h: float) -> float:
    """Distance from the lowest to the highest crossing of a piecewise-linear phi (holes
    included)."""
    neg = np.nonzero(phi_col < 0)[0]
    if len(neg) == 0:
        return 0.0
    lo, hi = neg[0], neg[-1]
    y0 = lo * h
    if lo > 0:
        a, b = phi_col[lo - 1], phi_col[lo]
        y0 -= h * b / (b - a)
    y1 = hi * h
    if hi < len(phi_col) - 1:
        a, b = phi_col[hi], phi_col[hi + 1]
        y1 += h * a / (a - b)
    return float(y1 - y0)


def neck_measures(
    phi: np.ndarray, h: float, off: int, x_left: float, x_right: float
) -> tuple[float, float]:
    """(contact line, neck span) in metres: the narrowest material section over the node columns
    strictly between x_left and x_right, and the outer extent (holes included) of that column."""
    best, best_i = np.inf, -1
    for i in range(phi.shape[0]):
        x = (i - off) * h
        if x_left < x < x_right:
            v = column_material_length(phi[i], h)
            if v < best:
                best, best_i = v, i
    if best_i < 0:
        return float("nan"), float("nan")
    return float(best), column_span(phi[best_i], h)
