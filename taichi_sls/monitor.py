"""Monitored quantities, read once per output frame: temperatures, energies, Jacobian, contact line.

Contact line (the paper's neck length, Fig. 4). One definition, kept for every case: between the
mass centroids of bodies 0 and 1, take every vertical node column and measure the total length of
{y : phi(x, y) < 0} along it (phi linear between nodes); the contact line is the smallest such
length -- the narrowest vertical section of material between the two bodies. It follows the neck
when the pair slides, counts only material (a hole in the neck shortens it) and drops to zero when
the neck tears. ``neck_span_um`` reports, for the same column, the outer extent from the lowest to
the highest material (holes included): the silhouette's neck.
"""

import numpy as np
import taichi as ti

from .state import State


@ti.kernel
def reduce_points(st: ti.template()):
    """red = [T_max, sum m T, sum m, sum m (1 - xi), sum m H, kinetic energy, J_min, bad,
    T_min, J_max, |v|_max]."""
    st.red[0] = -1e30
    st.red[6] = 1e30
    st.red[8] = 1e30
    st.red[9] = -1e30
    st.red[10] = 0.0
    for k in ti.static(range(1, 6)):
        st.red[k] = 0.0
    st.red[7] = 0.0
    lo = -ti.cast(st.off - 1, float) * st.h
    hi_x = ti.cast(st.nx - st.off - 2, float) * st.h
    hi_y = ti.cast(st.ny - st.off - 2, float) * st.h
    # serial: float sums in a fixed order, so that monitors repeat bit for bit (resume test);
    # it runs once per output frame
    ti.loop_config(serialize=True)
    for p in range(st.n_points):
        m = st.mass[p]
        ti.atomic_max(st.red[0], st.T[p])
        st.red[1] += m * st.T[p]
        st.red[2] += m
        st.red[3] += m * (1.0 - st.xi[p])
        st.red[4] += m * st.H[p]
        st.red[5] += 0.5 * m * st.v[p].norm_sqr()
        ti.atomic_min(st.red[6], st.J[p])
        ti.atomic_min(st.red[8], st.T[p])
        ti.atomic_max(st.red[9], st.J[p])
        ti.atomic_max(st.red[10], st.v[p].norm())
        x = st.x[p]
        bad = 0.0
        if not (x[0] == x[0] and x[1] == x[1] and st.T[p] == st.T[p] and st.J[p] == st.J[p]):
            bad = 1.0  # NaN
        elif x[0] < lo or x[1] < lo or x[0] > hi_x or x[1] > hi_y:
            bad = 2.0  # left the grid
        ti.atomic_max(st.red[7], bad)


def point_monitors(st: State) -> dict[str, float]:
    reduce_points(st)
    r = st.red.to_numpy()
    return {
        "T_max_C": float(r[0] - 273.15),
        "T_mean_C": float(r[1] / r[2] - 273.15),
        "molten_fraction": float(r[3] / r[2]),
        "enthalpy_J_per_m": float(r[4]),
        "kinetic_energy_J_per_m": float(r[5]),
        "J_min": float(r[6]),
        "_bad": float(r[7]),
        "_T_min": float(r[8]),
        "_J_max": float(r[9]),
        "_v_max": float(r[10]),
    }


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


def contact_line(
    phi: np.ndarray, h: float, off: int, x_left: float, x_right: float, span: bool = False
) -> float:
    """The contact line of :func:`neck_measures` (with ``span``: the neck span)."""
    return neck_measures(phi, h, off, x_left, x_right)[1 if span else 0]


def body_centroids_x(x: np.ndarray, body: np.ndarray, mass: np.ndarray) -> list[float]:
    out = []
    for b in range(int(body.max()) + 1):
        sel = body == b
        out.append(float(np.sum(x[sel, 0] * mass[sel]) / np.sum(mass[sel])))
    return out
