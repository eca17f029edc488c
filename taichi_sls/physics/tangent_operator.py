"""The points' tangent of the implicit step applied through the points, on any grid spacing.

physics/stiffness.py assembles K_ij = sum_p V_p B_i^T C_p B_j into node rows. The same tangent
acts on a grid velocity field x without a row: at each point the velocity gradient
H = sum_j x_j (x) grad N_j, the stress of the point's linear isotropic law
C_p H = a_lambda tr(H) 1 + a_mu (H + H^T), and (K x)_i = sum_p V_p (C_p H) grad N_i
(stiffness.py's module docstring, its K_ij contracted with x_j). One point pass scatters it,
in memory per point three numbers (V, a_lambda, a_mu), where the rows take 375 entries per node
in 3D.

The kernels take the grid as flat arrays of ``dim`` values a node (row-major node index) at
any spacing h with the node at x = 0 at index ``off``, and the points as rows of quadrature
(position, V, a_lambda, a_mu, mass): the multigrid's coarse levels (solver/multigrid.py) apply
the tangent rediscretised on grids of 2h, 4h, ... with the points merged cell by cell into
fewer quadrature points, and take its diagonal blocks and lumped mass there.
"""

from taichi_sls.backend import ti

from .shape import STENCIL_SHAPE, node_weight, stencil
from .small_matrix import IDENTITY
from .stiffness import stencil_gradients, stencil_offset


@ti.func
def _quadrature_stencil(
    dim: ti.template(), q: ti.template(), p, inv_h, h, lp, off, shape: ti.template()
):
    """Quadrature point p's stencil on a grid of spacing h; its base kept inside the grid's
    arrays (a point that has left the grid writes to the border, as solver/loops.py's clamp)."""
    xp = ti.Vector([q[p, d] for d in ti.static(range(dim))])
    base, w, dw = stencil(xp, inv_h, h, lp, off)
    for d in ti.static(range(dim)):
        base[d] = ti.max(0, ti.min(base[d], shape[d] - 3))
    return base, w, dw


@ti.func
def _node(I, shape: ti.template()):
    """The flat index of node I."""
    k = 0
    for d in ti.static(range(I.n)):
        k = k * shape[d] + I[d]
    return k


@ti.kernel
def apply_point_tangent(
    dim: ti.template(),
    q: ti.types.ndarray(ndim=2),
    x: ti.types.ndarray(ndim=1),
    y: ti.types.ndarray(ndim=1),
    shape: ti.types.ndarray(ndim=1),
    inv_h: float,
    h: float,
    lp: float,
    off: ti.i32,
):
    """y += K x (module docstring) on the grid of ``shape`` nodes, over the quadrature points
    q: one row each, (x_1 .. x_dim, V, a_lambda, a_mu, mass)."""
    for p in range(q.shape[0]):
        V, a_lam, a_mu = q[p, dim], q[p, dim + 1], q[p, dim + 2]
        if V > 0.0:
            n = ti.Vector([shape[d] for d in ti.static(range(dim))])
            base, w, dw = _quadrature_stencil(dim, q, p, inv_h, h, lp, off, n)
            G = stencil_gradients(w, dw)  # once for the gather and the scatter
            H = ti.Matrix.zero(float, dim, dim)
            for r in range(3**dim):
                k = _node(base + stencil_offset(r, dim), n) * dim
                for a, b in ti.static(ti.ndrange(dim, dim)):
                    H[a, b] += x[k + a] * G[r, b]
            sig = V * (a_lam * H.trace() * ti.Matrix(IDENTITY[dim]) + a_mu * (H + H.transpose()))
            for r in range(3**dim):
                k = _node(base + stencil_offset(r, dim), n) * dim
                for a in ti.static(range(dim)):
                    f = 0.0
                    for b in ti.static(range(dim)):
                        f += sig[a, b] * G[r, b]
                    y[k + a] += f


@ti.kernel
def point_tangent_diagonal(
    dim: ti.template(),
    q: ti.types.ndarray(ndim=2),
    D: ti.types.ndarray(ndim=1),
    mass: ti.types.ndarray(ndim=1),
    shape: ti.types.ndarray(ndim=1),
    inv_h: float,
    h: float,
    lp: float,
    off: ti.i32,
):
    """D += the dim x dim diagonal blocks K_ii of the tangent (row-major, a node's after
    another's) and mass += the lumped mass, over the quadrature points q
    (:func:`apply_point_tangent`) on the grid of ``shape`` nodes."""
    for p in range(q.shape[0]):
        V, a_lam, a_mu = q[p, dim], q[p, dim + 1], q[p, dim + 2]
        n = ti.Vector([shape[d] for d in ti.static(range(dim))])
        base, w, dw = _quadrature_stencil(dim, q, p, inv_h, h, lp, off, n)
        for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[dim])):
            N, g = node_weight(w, dw, o)
            k = _node(base + o, n)
            mass[k] += N * q[p, dim + 3]
            if V > 0.0:
                gg = g.dot(g)
                for a, b in ti.static(ti.ndrange(dim, dim)):
                    v = a_lam * g[a] * g[b] + a_mu * g[b] * g[a]
                    if ti.static(a == b):
                        v += a_mu * gg
                    D[(k * dim + a) * dim + b] += V * v


@ti.kernel
def point_tangent_matrix(
    dim: ti.template(),
    q: ti.types.ndarray(ndim=2),
    unknown: ti.types.ndarray(ndim=1),
    M: ti.types.ndarray(ndim=2),
    shape: ti.types.ndarray(ndim=1),
    inv_h: float,
    h: float,
    lp: float,
    off: ti.i32,
):
    """M += K over the unknowns (a small grid's dense matrix, the multigrid's coarsest):
    K_ij[a, c] = sum_p V_p (a_lambda g_i[a] g_j[c] + a_mu g_i[c] g_j[a] + a_mu (g_i . g_j)
    delta_ac), g = grad N at point p, :func:`apply_point_tangent`'s operator as entries;
    ``unknown``: each node component's row and column in M (flat node * dim + a), -1 where
    it is not one."""
    for p in range(q.shape[0]):
        V, a_lam, a_mu = q[p, dim], q[p, dim + 1], q[p, dim + 2]
        if V > 0.0:
            n = ti.Vector([shape[d] for d in ti.static(range(dim))])
            base, w, dw = _quadrature_stencil(dim, q, p, inv_h, h, lp, off, n)
            G = stencil_gradients(w, dw)
            for r, s in ti.ndrange(3**dim, 3**dim):
                i = _node(base + stencil_offset(r, dim), n) * dim
                j = _node(base + stencil_offset(s, dim), n) * dim
                gg = 0.0
                for b in ti.static(range(dim)):
                    gg += G[r, b] * G[s, b]
                for a, c in ti.static(ti.ndrange(dim, dim)):
                    row, col = unknown[i + a], unknown[j + c]
                    if row >= 0 and col >= 0:
                        v = a_lam * G[r, a] * G[s, c] + a_mu * G[r, c] * G[s, a]
                        if ti.static(a == c):
                            v += a_mu * gg
                        M[row, col] += V * v


@ti.kernel
def points_quadrature(st: ti.template(), q: ti.types.ndarray(ndim=2)):
    """The points as quadrature rows (:func:`apply_point_tangent`), their moduli those the
    implicit step's force pass kept."""
    dim = ti.static(st.cfg.dim)
    for p in range(st.cfg.n_points):
        for d in ti.static(range(dim)):
            q[p, d] = st.points.x[p][d]
        for c in ti.static(range(3)):
            q[p, dim + c] = st.implicit.moduli[p][c]
        q[p, dim + 3] = st.points.mass[p]
