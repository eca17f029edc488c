"""The tangent of the implicit step's momentum balance on the grid (solver/implicit.py).

Backward Euler for the grid velocities v_i^{n+1}:

    m_i (v_i - v_i^n) / dt = f_i^ext + f_i^cap(x^n) - dt (K^cap v)_i + f_i^int(v)

f^int is the internal force of the stress each point takes after the step (its Perzyna update
with L = sum_j v_j grad N_j). Newton's tangent of -f^int is assembled from each point's linear
isotropic law, delta sigma = a_lambda tr(delta D) 1 + 2 a_mu delta D with delta D = sym(delta L):

    K_ij^ab = V_p [a_lambda dN_i/dx_a dN_j/dx_b + a_mu (dN_i/dx_b dN_j/dx_a + delta_ab grad N_i .
              grad N_j)],   a_lambda = dt (K - 2 mu_t / 3) - 2 eta / 3,  a_mu = dt mu_t + eta

with mu_t the secant shear modulus of the return map and eta the solvent viscosity
(physics/constitutive.py, trial_stress): symmetric and positive definite while K + mu_t / 3 > 0.
K^cap is the semi-implicit capillary stiffness of Baensch (2001) and Hysing (2006) on the
surface-energy outline, the surface Laplacian gamma sum_q w_q L_q (t . grad N_i)(t . grad N_j) 1
over the Gauss points of its segments (physics/surface_energy.py): the force at x^n + dt v to
first order, which lifts the capillary step limit. In 3D the same on the triangles of the
marching-tetrahedra surface, (P grad N_i) . (P grad N_j) with P = I - n n^T.

A point couples the nodes of its 3^dim stencil, so node i's row holds the 5^dim nodes within two
of it: the matrix lives on the grid as ``K[I, I_j - I_i + 2, a, b]`` and solver/implicit.py
gathers it into a sparse matrix. The fixed part (inertia, capillary stiffness) is a scalar times
the identity in the components and lives as scalar rows ``K[I, I_j - I_i + 2]``.

The points' tangent and the conduction matrix are symmetric, K_ji = K_ij^T, so the points write
the upper triangle alone: the slots from the row's own node on, in the row's order
(:func:`upper_slot`), and of the node's own 3x3 block its upper triangle; half the scatter of
full rows. A reader takes a lower entry from where its transpose is stored
(:func:`mirrored_slot`; solver/implicit_system.py, ``tangent_entry``), so the gathered matrix is
exactly symmetric.
"""

from taichi_sls.backend import ti

from .dilatation import CELL_CORNERS, cell_gradient, light_corners, point_cell
from .shape import node_weight, stencil
from .small_matrix import ZERO_MATRIX
from .surface_energy import GAUSS, outline_segments, outline_triangles

REACH = 2  # nodes of one row lie within REACH of the diagonal node along every axis
WIDTH = 2 * REACH + 1


@ti.func
def stencil_gradients(w, dw):
    """grad N of the 3^dim stencil nodes, one row per node in stencil order (the last axis
    fastest): the pair loops below run over them at run time, so that they compile as one loop
    body instead of 81 unrolled ones."""
    dim = ti.static(w.m)
    G = ti.Matrix(ZERO_MATRIX[3**dim, dim])
    for k in range(3**dim):
        N, g = node_weight(w, dw, stencil_offset(k, dim))
        for d in ti.static(range(dim)):
            G[k, d] = g[d]
    return G


@ti.func
def stencil_offset(k, dim: ti.template(), side: ti.template() = 3):
    """The offset of node k of a block of side^dim nodes, the last axis fastest (the stencil's
    order for side 3; a matrix row's nodes for side WIDTH)."""
    o = ti.Vector.zero(ti.i32, dim)
    r = k
    for d in ti.static(range(dim - 1, -1, -1)):
        o[d] = r % side
        r //= side
    return o


def own_slot(dim: int) -> int:
    """The slot of a row's own node (the middle of its WIDTH^dim, the last axis fastest)."""
    return (WIDTH**dim - 1) // 2


@ti.func
def upper_slot(r, dim: ti.template()):
    """Whether slot r of a row is the row's own node or after it: the half of a symmetric row
    the points write (module docstring). In the stencil's order the same test is j >= i: both
    orders are lexicographic in the offset."""
    return r >= ti.static(own_slot(dim))


@ti.func
def clear_row(K: ti.template(), I, dim: ti.template(), upper: ti.template() = False):
    """Node I's row of K (scalar rows, or dim x dim blocks); ``upper``: the half the points
    write of a symmetric one."""
    for r in range(own_slot(dim) if ti.static(upper) else 0, WIDTH**dim):
        o = stencil_offset(r, dim, WIDTH)
        if ti.static(len(K.shape) == 2 * dim):  # scalar rows (the fixed part)
            K[I, o] = 0.0
        else:
            for a, b in ti.static(ti.ndrange(dim, dim)):
                K[I, o, a, b] = 0.0


@ti.func
def mirrored_slot(I, o, r, dim: ti.template()):
    """Where a symmetric row's slot r (offset o) of node I is stored: (node, offset, whether
    transposed); a lower slot is the neighbour's upper slot towards I."""
    lower = ti.cast(not upper_slot(r, dim), ti.i32)  # 1 below the row's own node
    return I + lower * (o - REACH), o + lower * (2 * REACH - 2 * o), lower


@ti.func
def scatter_point_tangent(cfg: ti.template(), K: ti.template(), base, w, dw, V, a_lam, a_mu):
    """K_ij += the tangent of one point (module docstring) over its stencil's node pairs, j
    from i on (the upper half)."""
    G = stencil_gradients(w, dw)
    for i in range(3**cfg.dim):
        oi = stencil_offset(i, cfg.dim)
        for j in range(i, 3**cfg.dim):
            d = stencil_offset(j, cfg.dim) - oi + REACH
            gg = 0.0
            for c in ti.static(range(cfg.dim)):
                gg += G[i, c] * G[j, c]
            for a, b in ti.static(ti.ndrange(cfg.dim, cfg.dim)):
                k = a_lam * (G[i, a] * G[j, b]) + a_mu * (G[i, b] * G[j, a])
                if ti.static(a == b):
                    k += a_mu * gg
                if ti.static(a <= b):
                    K[base + oi, d, a, b] += V * k
                elif i != j:  # a node's own block: its upper triangle alone
                    K[base + oi, d, a, b] += V * k


@ti.func
def scatter_tangent(
    cfg: ti.template(), K: ti.template(), nd: ti.template(), base, w, dw, xp, V, a_lam, a_mu
):
    """One point's tangent. With ``solver.dilatation = "cell"`` (physics/dilatation.py) the
    point's stress is kappa div_c 1 + 2 a_mu dev(D_p), div_c the divergence at its cell's
    centre, its mean acting through the cell's gradient: the deviatoric part through the point's
    own gradients (the law above with a_lambda = -2 a_mu / dim) and the volumetric one,
    V kappa g_i g_j^T with kappa = a_lambda + 2 a_mu / dim (the in-plane mean in 2D), over the
    cell's 2^dim corners, g the floored gradient the force takes (physics/dilatation.py). Both
    parts are symmetric and positive semi-definite."""
    if ti.static(cfg.cell_dilatation):
        scatter_point_tangent(cfg, K, base, w, dw, V, -2.0 * a_mu / cfg.dim, a_mu)
        scatter_cell_tangent(cfg, K, nd, xp, V * (a_lam + 2.0 * a_mu / cfg.dim))
    else:
        scatter_point_tangent(cfg, K, base, w, dw, V, a_lam, a_mu)


@ti.func
def scatter_cell_tangent(cfg: ti.template(), K: ti.template(), nd: ti.template(), xp, kappa_V):
    """K_ij += kappa V g_i g_j^T over the corners i, j of x_p's cell (j at or after i: the
    upper half), g the corner's gradient that the cell's divergence takes: the corners lie in
    the point's stencil, so within the row's REACH."""
    c = point_cell(cfg, xp)
    rest, mass = light_corners(cfg, nd, c)
    for i in ti.grouped(ti.ndrange(*CELL_CORNERS[cfg.dim])):
        gi = cell_gradient(cfg, nd, c, i, rest, mass)
        for j in ti.grouped(ti.ndrange(*CELL_CORNERS[cfg.dim])):
            d = j - i + REACH
            if upper_slot(flat_slot(d, cfg.dim), cfg.dim):
                gj = cell_gradient(cfg, nd, c, j, rest, mass)
                for a, b in ti.static(ti.ndrange(cfg.dim, cfg.dim)):
                    if ti.static(a <= b):
                        K[c + i, d, a, b] += kappa_V * (gi[a] * gj[b])
                    elif (i != j).any():  # a node's own block: its upper triangle alone
                        K[c + i, d, a, b] += kappa_V * (gi[a] * gj[b])


@ti.func
def flat_slot(o, dim: ti.template()):
    """The slot of offset o in a row (the inverse of stencil_offset with side WIDTH)."""
    r = 0
    for d in ti.static(range(dim)):
        r = r * WIDTH + o[d]
    return r


@ti.func
def scatter_point_conductance(cfg: ti.template(), K: ti.template(), base, w, dw, Vk):
    """K_ij += V_p k_p grad N_i . grad N_j over the stencil's node pairs, j from i on (the upper
    half): the conduction of eq. 29, linear in the node temperatures, as the backward-Euler heat
    step's matrix."""
    G = stencil_gradients(w, dw)
    for i in range(3**cfg.dim):
        oi = stencil_offset(i, cfg.dim)
        for j in range(i, 3**cfg.dim):
            gg = 0.0
            for c in ti.static(range(cfg.dim)):
                gg += G[i, c] * G[j, c]
            K[base + oi, stencil_offset(j, cfg.dim) - oi + REACH] += Vk * gg


@ti.func
def scatter_mass(cfg: ti.template(), K: ti.template(), I, m_over_dt):
    """The inertia m_i / dt on node i's diagonal (K: scalar rows, times the identity)."""
    K[I, ti.Vector([REACH] * cfg.dim)] += m_over_dt


@ti.func
def segment_tangent(cfg: ti.template(), K: ti.template(), a, b, scale):
    """K_ij += scale w_q L (t . grad N_i)(t . grad N_j) over the Gauss points of segment a-b
    (the surface Laplacian of the outline; scale = dt gamma; K: scalar rows, times the
    identity)."""
    d = b - a
    L = d.norm()
    if L > 0.0:
        t = d / L
        s, wq = ti.static(GAUSS[cfg.se.gauss_points])
        for g in ti.static(range(len(s))):
            xq = a + s[g] * d
            base, w, dw = stencil(xq, cfg.inv_h, cfg.h, cfg.se.weight_lp, cfg.off)
            tg = stencil_gradients(w, dw) @ t  # t . grad N of each stencil node
            for i in range(3**cfg.dim):
                oi = stencil_offset(i, cfg.dim)
                for j in range(3**cfg.dim):
                    k = scale * wq[g] * L * tg[i] * tg[j]
                    K[base + oi, stencil_offset(j, cfg.dim) - oi + REACH] += k


@ti.func
def triangle_tangent(cfg: ti.template(), K: ti.template(), a, b, c, scale):
    """K_ij += scale w_q A (P grad N_i) . (P grad N_j), P = I - n n^T, over the three points of
    triangle abc (physics/surface_energy.py, triangle_force): the surface Laplacian in 3D
    (scalar rows, as segment_tangent)."""
    nrm = (b - a).cross(c - a)
    A2 = nrm.norm()
    if A2 > 0.0:
        n = nrm / A2
        kq = scale * A2 / 6.0  # scale w_q A, w_q = 1/3
        mid = (a + b + c) / 6.0
        for q in range(3):
            xq = mid + 0.5 * ti.select(q == 0, a, ti.select(q == 1, b, c))
            base, w, dw = stencil(xq, cfg.inv_h, cfg.h, cfg.se.weight_lp, cfg.off)
            G = stencil_gradients(w, dw)
            Gs = G - (G @ n).outer_product(n)  # the tangential gradients P grad N, by row
            for i in range(3**cfg.dim):
                oi = stencil_offset(i, cfg.dim)
                for j in range(3**cfg.dim):
                    gg = 0.0
                    for e in ti.static(range(cfg.dim)):
                        gg += Gs[i, e] * Gs[j, e]
                    if gg != 0.0:
                        K[base + oi, stencil_offset(j, cfg.dim) - oi + REACH] += kq * gg


@ti.func
def capillary_tangent(
    cfg: ti.template(), box: ti.template(), nd: ti.template(), K: ti.template(), scale
):
    """The capillary stiffness of the outline of nd.colour (the force computed it before)."""
    if ti.static(cfg.dim == 3):
        outline_triangles(cfg, box, nd, triangle_tangent, K, scale)
    else:
        outline_segments(cfg, box, nd, segment_tangent, K, scale)
