"""The level set of the CSF method (eq. 21) and its redistancing.

1. **Level set from the points** (eq. 21): phi_raw(x_i) = min_p |x_i - x_p| - r_p, scattered by
   each point onto the 5x5 nodes around it (O(points) work). It is a distance outside the body
   but a plateau near -r_p inside, where eq. 24 would divide by a vanishing gradient.
2. **Redistancing** (``surface_tension.level_set = "redistanced"``, the only reading): the zero
   contour of phi_raw is traced by marching squares (linear interpolation on cell edges, saddles
   resolved by the cell-centre value) and every node within ``band_cells`` of it gets the signed
   distance to the nearest contour segment (eq. 21 as printed is not offered).
3. **Blur** before the curvature fit: ``level_set_smoothing_passes`` binomial passes (a Gaussian
   blur; a circle stays a circle, shrunk by sigma^2 / 2R).

Arguments: ``cfg`` the step's configuration, ``box`` the active region, ``nd`` the nodes, ``seg``
the contour segments (``seg.ends`` up to two per cell, ``seg.count``).
"""

from taichi_sls.backend import ti

from .contour import cell_segments
from .grid import active, scatter_min


@ti.func
def scatter_level_set(cfg: ti.template(), pt: ti.template(), nd: ti.template(), p, base):
    """Eq. 21 onto the 5x5 nodes around point p (base: its 3x3 stencil origin)."""
    xp = pt.x[p]
    for o in ti.grouped(ti.ndrange(5, 5)):  # at run time: one copy of the body (compile time)
        I = base + o - 1
        xi = ti.cast(I - cfg.off, float) * cfg.h
        scatter_min(cfg, nd.phi_raw, I, (xi - xp).norm() - cfg.r_p)


@ti.func
def contour_segments(
    cfg: ti.template(), box: ti.template(), values: ti.template(), seg: ti.template()
):
    """Marching squares on the node field ``values`` (inside where < 0): up to two segments per
    cell, in metres."""
    for i, j in ti.ndrange(*active(box, 1)):
        f = ti.Vector([values[i, j], values[i + 1, j], values[i + 1, j + 1], values[i, j + 1]])
        x0 = ti.cast(ti.Vector([i, j]) - cfg.off, float) * cfg.h
        count, ends = cell_segments(f, x0, cfg.h)
        seg.ends[i, j] = ends
        seg.count[i, j] = count


@ti.func
def _seg_dist2(x, a, b):
    ab = b - a
    L2 = ab.dot(ab)
    t = 0.0
    if L2 > 0.0:
        t = ti.min(1.0, ti.max(0.0, (x - a).dot(ab) / L2))
    d = x - (a + t * ab)
    return d.dot(d)


@ti.func
def redistance(cfg: ti.template(), box: ti.template(), nd: ti.template(), seg: ti.template()):
    """Signed distance to the contour segments for every node within the band."""
    nb = ti.static(cfg.band)
    for i, j in ti.ndrange(*active(box)):
        f = nd.phi_raw[i, j]
        sgn = 1.0 if f >= 0.0 else -1.0
        out = sgn * cfg.phi_cap
        if f < cfg.phi_cap:
            x = ti.cast(ti.Vector([i, j]) - cfg.off, float) * cfg.h
            d2 = cfg.phi_cap * cfg.phi_cap
            for ci in range(ti.max(i - nb, 0), ti.min(i + nb, cfg.nx - 1)):
                for cj in range(ti.max(j - nb, 0), ti.min(j + nb, cfg.ny - 1)):
                    for s in range(seg.count[ci, cj]):
                        sg = seg.ends[ci, cj]
                        a = ti.Vector([sg[4 * s], sg[4 * s + 1]])
                        b = ti.Vector([sg[4 * s + 2], sg[4 * s + 3]])
                        d2 = ti.min(d2, _seg_dist2(x, a, b))
            out = sgn * ti.sqrt(d2)
        nd.phi[i, j] = out


@ti.func
def level_set(cfg: ti.template(), box: ti.template(), nd: ti.template(), seg: ti.template()):
    """phi on the nodes from the points' scatter already in phi_raw (steps 1-2 above)."""
    contour_segments(cfg, box, nd.phi_raw, seg)
    redistance(cfg, box, nd, seg)


@ti.func
def blur_level_set(cfg: ti.template(), box: ti.template(), nd: ti.template()):
    """phi_smooth = phi after ``level_set_smoothing_passes`` binomial [1 2 1]/4 passes along x
    then y (a Gaussian of variance passes * h^2 / 2 per axis): removes the points' staircase
    before eq. 24 amplifies it. For a disc it moves the interface inward by about that variance
    / (2R). phi itself stays unsmoothed for the contact line."""
    for I in ti.grouped(ti.ndrange(*active(box))):
        nd.phi_smooth[I] = nd.phi[I]
    # passes unrolled only where each loop must stay a top-level parallel loop: unrolled, the
    # serial step kernel grows by two loops a pass and Taichi's optimiser slows down with it
    if ti.static(cfg.parallel):
        for _ in ti.static(range(cfg.blur_passes)):
            _blur_pass(cfg, box, nd)
    else:
        for _ in range(cfg.blur_passes):
            _blur_pass(cfg, box, nd)


@ti.func
def _blur_pass(cfg: ti.template(), box: ti.template(), nd: ti.template()):
    for i, j in ti.ndrange(*active(box)):
        v = nd.phi_smooth[i, j]
        if i > 0 and i < cfg.nx - 1:
            v = 0.25 * (nd.phi_smooth[i - 1, j] + nd.phi_smooth[i + 1, j]) + 0.5 * v
        nd.scratch[i, j] = v
    for i, j in ti.ndrange(*active(box)):
        v = nd.scratch[i, j]
        if j > 0 and j < cfg.ny - 1:
            v = 0.25 * (nd.scratch[i, j - 1] + nd.scratch[i, j + 1]) + 0.5 * v
        nd.phi_smooth[i, j] = v
