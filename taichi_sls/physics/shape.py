"""uGIMP shape functions (Bardenhagen & Kober 2004) on a 3x3 node stencil.

A point of half-width l_p (uGIMP: l_p = h/4 for 2x2 points per cell) interacts with the nodes
closer than h + l_p. With node spacing h that is at most three nodes per axis, starting at
``base = round(x/h) - 1`` (eqs. 8-9 with N_i the uGIMP function).
"""

from taichi_sls.backend import ti

from .small_matrix import ZERO_MATRIX, ZERO_VECTOR

# The node offsets of a point's stencil, 3 per axis, by dimension (``domain.dim``, 2 or 3). Loops
# over them run at run time, `for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[cfg.dim]))`: a
# `ti.static` loop would make the front end build its body 3^dim times at every call site
# (docs/record/compile.md).
STENCIL_SHAPE = {dim: (3,) * dim for dim in (2, 3)}


@ti.func
def gimp_1d(xi, h, lp):
    """Weight S and its derivative dS/dx_p for a point at signed distance xi = x_p - x_i."""
    a = ti.abs(xi)
    s = 0.0 * xi
    ds = 0.0 * xi
    sgn = 1.0 if xi >= 0 else -1.0
    if a < lp:
        s = 1.0 - (xi * xi + lp * lp) / (2.0 * h * lp)
        ds = -xi / (h * lp)
    elif a < h - lp:
        s = 1.0 - a / h
        ds = -sgn / h
    elif a < h + lp:
        r = h + lp - a
        s = r * r / (4.0 * h * lp)
        ds = -sgn * r / (2.0 * h * lp)
    return s, ds


@ti.func
def stencil_base(xp, inv_h, origin_idx):
    """The base node index of :func:`stencil` alone."""
    return ti.cast(ti.floor(xp * inv_h + 0.5), ti.i32) - 1 + origin_idx


@ti.func
def stencil(xp, inv_h, h, lp, origin_idx):
    """Base node index and the 3x3 tensor-product weights / gradients for point position xp.

    Returns (base, w, dw) where w[a][d] is the weight of node base+a along axis d and dw its
    derivative; node (a, b) has N = w[a][0] * w[b][1] and grad N = (dw[a][0] w[b][1],
    w[a][0] dw[b][1]). Positions are physical; origin_idx is the index of the node at x = 0.
    """
    dim = ti.static(xp.n)
    base = ti.Vector.zero(ti.i32, dim)
    w = ti.Matrix(ZERO_MATRIX[3, dim])
    dw = ti.Matrix(ZERO_MATRIX[3, dim])
    # both loops at run time: one copy of gimp_1d, not 3 dim (the front end's cost)
    for d in range(dim):
        f = xp[d] * inv_h
        base[d] = ti.cast(ti.floor(f + 0.5), ti.i32) - 1
        for a in range(3):
            xi = (f - ti.cast(base[d] + a, float)) * h
            s, ds = gimp_1d(xi, h, lp)
            w[a, d] = s
            dw[a, d] = ds
        base[d] += origin_idx
    return base, w, dw


@ti.func
def node_weight(w, dw, offs):
    """N and grad N of the stencil node at static offset ``offs`` (tensor product, any dim)."""
    dim = ti.static(w.m)
    n = 1.0 + 0.0 * w[0, 0]
    g = ti.Vector(ZERO_VECTOR[dim])
    # run-time loops (the products in the same order): one copy of each body per call site
    for d in range(dim):
        n *= w[offs[d], d]
    for d in range(dim):
        gd = dw[offs[d], d]
        for e in range(dim):
            if e != d:
                gd *= w[offs[e], e]
        g[d] = gd
    return n, g
