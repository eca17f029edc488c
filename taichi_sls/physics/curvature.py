"""Curvature of the CSF method: the 9-point least-squares fit (eqs. 22-24) and its smoothing.

The quadratic of eq. 23 is fitted by least squares to the nine phi values around a node (the 6x9
fit matrix is the same for every node of a uniform grid) and eq. 24 gives the node's curvature.
With a signed distance, a node at distance phi from the interface sees the curvature of the
parallel curve; kappa_node / (1 - phi kappa_node) projects it back to the interface (exact for a
circle), so all band nodes carry the interface's curvature. Nodes where the fit is not a
distance (a neighbour outside the band, |grad phi| < 1/2) get the mean of the valid curvatures
around them (extension), or none. ``smoothing_passes`` mass-weighted 3x3 averages of kappa over
the interface nodes follow (unbiased for constant curvature), then |kappa| is capped at
``curvature_cap_h / h`` (the grid resolves no radius below a couple of cells).

Arguments: ``cfg``, ``box`` (active region), ``nd`` nodes, ``surf`` the surface scratch (the fit
matrix, the list of interface nodes).
"""

import numpy as np

from taichi_sls.backend import ti

from .codes import NodeFlag
from .grid import active
from .small_matrix import ZERO_VECTOR

CURVATURE = int(NodeFlag.CURVATURE)
INTERFACE = int(NodeFlag.INTERFACE)


def fit_matrix() -> np.ndarray:
    """(A^T A)^-1 A^T for the quadratic of eq. 23 on the 3x3 node stencil, offsets in cells.

    Rows give a0..a5 of a0 + a1 x + a2 y + a3 x^2 + a4 y^2 + a5 x y; columns are the nine nodes
    in the order (dx, dy) = ndrange(3, 3) - 1. The same for every node of a uniform grid.
    """
    A = []
    for a in range(3):
        for b in range(3):
            x, y = a - 1.0, b - 1.0
            A.append([1.0, x, y, x * x, y * y, x * y])
    A = np.array(A)
    return np.linalg.solve(A.T @ A, A.T)


@ti.func
def curvature(cfg: ti.template(), box: ti.template(), nd: ti.template(), surf: ti.template()):
    """Eqs. 22-24 at every node whose 3x3 neighbourhood lies in the band (flag CURVATURE)."""
    h = cfg.h
    for i, j in ti.ndrange(*active(box)):
        k = 0.0
        ok = 0
        if i > 0 and j > 0 and i < cfg.nx - 1 and j < cfg.ny - 1:
            f9 = ti.Vector(ZERO_VECTOR[9])
            inband = 1
            for a, b in ti.static(ti.ndrange(3, 3)):
                v = nd.phi_smooth[i + a - 1, j + b - 1]
                f9[3 * a + b] = v
                if ti.abs(v) >= cfg.phi_cap:
                    inband = 0
            if inband == 1:
                c = surf.fit[None] @ f9
                px, py = c[1] / h, c[2] / h
                pxx, pyy, pxy = 2.0 * c[3] / (h * h), 2.0 * c[4] / (h * h), c[5] / (h * h)
                g2 = px * px + py * py
                g = ti.sqrt(g2)
                if g > 0.5:  # phi is a signed distance: |grad phi| = 1 away from its kinks
                    kn = (pxx * py * py - 2.0 * px * py * pxy + pyy * px * px) / (g2 * g)
                    den = 1.0 - nd.phi_smooth[i, j] * kn
                    if den > 0.25:
                        k = kn / den
                        ok = CURVATURE
        nd.kappa[i, j] = k
        nd.flags[i, j] = ok


@ti.func
def extend_and_smooth(
    cfg: ti.template(), box: ti.template(), nd: ti.template(), surf: ti.template()
):
    """Give interface nodes without a valid curvature the mean of valid neighbours, then
    ``smoothing_passes`` mass-weighted 3x3 averages over interface nodes, then the cap.

    The passes only change interface nodes and only read interface neighbours: they run over a
    list of those nodes (a few hundred of the paper grid's 1457), alternating between scratch and
    kappa (Jacobi sweeps, so the list's order does not matter)."""
    surf.n_iface[None] = 0
    for i, j in ti.ndrange(*active(box)):
        k = nd.kappa[i, j]
        if nd.flags[i, j] & INTERFACE and i > 0 and j > 0 and i < cfg.nx - 1 and j < cfg.ny - 1:
            if nd.flags[i, j] == INTERFACE:
                s = 0.0
                n = 0
                for a, b in ti.static(ti.ndrange(3, 3)):
                    if nd.flags[i + a - 1, j + b - 1] & CURVATURE:
                        s += nd.kappa[i + a - 1, j + b - 1]
                        n += 1
                k = s / n if n > 0 else 0.0
            surf.iface[ti.atomic_add(surf.n_iface[None], 1)] = ti.Vector([i, j])
        nd.scratch[i, j] = k
    if ti.static(cfg.parallel):
        for q in ti.static(range(cfg.smooth_passes)):
            _smooth_pass(nd, surf, q % 2 == 1)
    else:
        for q in range(cfg.smooth_passes):
            _smooth_pass(nd, surf, q % 2 == 1)
    if ti.static(cfg.smooth_passes % 2 == 1):  # the last pass wrote kappa
        for q in range(surf.n_iface[None]):
            I = surf.iface[q]
            nd.scratch[I] = nd.kappa[I]
    for i, j in ti.ndrange(*active(box)):
        k = nd.scratch[i, j]
        if ti.static(cfg.kappa_cap > 0.0):
            k = ti.min(cfg.kappa_cap, ti.max(-cfg.kappa_cap, k))
        nd.kappa[i, j] = k


@ti.func
def _smooth_pass(nd: ti.template(), surf: ti.template(), back):
    """One mass-weighted 3x3 average over the interface nodes: scratch -> kappa, or back."""
    for q in range(surf.n_iface[None]):
        I = surf.iface[q]
        s = 0.0
        w = 0.0
        for a, b in ti.static(ti.ndrange(3, 3)):
            J = I + ti.Vector([a - 1, b - 1])
            if nd.flags[J] & INTERFACE:
                m = nd.mass[J]
                s += m * (nd.kappa[J] if back else nd.scratch[J])
                w += m
        if back:
            nd.scratch[I] = s / w
        else:
            nd.kappa[I] = s / w
