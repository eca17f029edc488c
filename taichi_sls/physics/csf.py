"""The paper's surface tension (eqs. 19-24): the CSF force from the level set's curvature
(``surface_tension.method = "csf"``).

The force (eq. 19): f_i = V_c gamma kappa_i grad m_i / [m] * m_i / <m> with [m] = rho V_c and
<m> = [m] / 2 (docs/model.md), grad m_i from eq. 20 with the uGIMP gradient at node positions. The
ghost nodes beyond the walls enter grad m only. Level set: physics/level_set.py; curvature:
physics/curvature.py.
"""

from taichi_sls.backend import ti

from .codes import NodeFlag
from .curvature import curvature, extend_and_smooth
from .grid import active, ramped_gamma
from .level_set import blur_level_set, level_set
from .small_matrix import ZERO_VECTOR

CURVATURE = int(NodeFlag.CURVATURE)
INTERFACE = int(NodeFlag.INTERFACE)


def _node_stencil_1d(h: float, lp: float) -> tuple[list[float], list[float]]:
    """uGIMP weight and derivative of node i' seen from node i = i' + (1 - a) (a = 0, 1, 2)."""
    # xi = x_i - x_i' = (1 - a) h: the left neighbour (a = 0) sits at xi = +h, where
    # dS/dxi = -1/(2h); so grad m is the central difference (m_right - m_left) / 2h, y-smoothed
    s0, s1 = 1.0 - lp / (2.0 * h), lp / (4.0 * h)
    d1 = 1.0 / (2.0 * h)
    return [s1, s0, s1], [-d1, 0.0, d1]


@ti.func
def mass_gradient(cfg: ti.template(), box: ti.template(), nd: ti.template()):
    """Eq. 20 with the uGIMP gradient at node positions; flags interface nodes."""
    S, dS = ti.static(_node_stencil_1d(cfg.h, cfg.lp))
    for i, j in ti.ndrange(*active(box)):
        g = ti.Vector(ZERO_VECTOR[2])
        if i > 0 and j > 0 and i < cfg.nx - 1 and j < cfg.ny - 1:
            for a, b in ti.static(ti.ndrange(3, 3)):
                m = nd.mass[i + a - 1, j + b - 1]
                g += m * ti.Vector([dS[a] * S[b], S[a] * dS[b]])
        nd.mass_gradient[i, j] = g
        iface = 0
        if nd.mass[i, j] > cfg.mass_cut and g.norm() * cfg.h > 1e-6 * cfg.rho_ref * cfg.cell_volume:
            iface = INTERFACE
        nd.flags[i, j] = (nd.flags[i, j] & CURVATURE) | iface


@ti.func
def csf_force(cfg: ti.template(), box: ti.template(), nd: ti.template(), surf: ti.template(), t):
    """Eq. 19 with [m] = rho V_c and <m> = rho V_c / 2 (docs/model.md).

    Surface tension on a closed surface has no resultant, but the discrete CSF force keeps a
    small one from the curvature's noise (0.3 % of |f| on a disc of points, enough to set it
    drifting). With ``zero_net_force`` the resultant is removed in proportion to node mass."""
    # f_i = V_c gamma kappa grad(c) w(c), c = m_i / (rho V_c): eq. 19 is w = 2c. With a colour
    # threshold c0 > 0, w = 2 max(c - c0, 0) / (1 - c0)^2 keeps the force across an interface
    # (the integral of w dc over [0, 1] is 1) but gives none to nodes that only a few stray
    # points touch: the CSF acceleration does not fall with node mass, and a lone point in a
    # concave pocket would be flung out of the box.
    c0 = ti.static(cfg.csf_c0)
    full = cfg.rho_ref * cfg.cell_volume
    coef = ramped_gamma(cfg, t) / (cfg.rho_ref * (1.0 - c0) * (1.0 - c0))
    if ti.static(cfg.zero_net_force):
        surf.resultant[None] = ti.Vector(ZERO_VECTOR[3])
    for i, j in ti.ndrange(*active(box)):
        if nd.flags[i, j] & INTERFACE:
            wc = 2.0 * ti.max(nd.mass[i, j] / full - c0, 0.0)
            f = coef * nd.kappa[i, j] * wc * nd.mass_gradient[i, j]
            nd.force[i, j] += f
            if ti.static(cfg.zero_net_force):
                surf.resultant[None] += ti.Vector([f[0], f[1], nd.mass[i, j]])
    if ti.static(cfg.zero_net_force):
        for i, j in ti.ndrange(*active(box)):
            if nd.flags[i, j] & INTERFACE:
                r = surf.resultant[None]
                nd.force[i, j] -= nd.mass[i, j] / r[2] * ti.Vector([r[0], r[1]])


@ti.func
def surface_geometry(
    cfg: ti.template(), box: ti.template(), nd: ti.template(), surf: ti.template()
):
    """Level set, curvature and interface nodes; the CSF force (``csf_force``) follows."""
    level_set(cfg, box, nd, surf)
    blur_level_set(cfg, box, nd)
    curvature(cfg, box, nd, surf)
    mass_gradient(cfg, box, nd)
    extend_and_smooth(cfg, box, nd, surf)
