"""Surface tension as the gradient of the surface energy (``surface_tension.method =
"surface_energy"``; Hyde, Gagniere, Marquez-Razon & Teran 2020, in 2D).

The surface energy of the bodies is gamma times the length of their outline. On the grid:

1. **Colour** c_i = m_i / (rho V_c) from the node mass of the P2G (``surface_energy_colour =
   "mass"``). Every point adds to it, whatever
   its body: touching bodies share one colour field and so one outline, and they merge. With
   ``surface_energy_colour_filter`` the contoured colour is c after one [1 2 1]/4 pass along x
   and y: a pair whose mid-plane lies on a node line (the paper's) otherwise keeps a one-cell
   notch at the neck, since the points of the two bodies never cross it.
2. **Outline**: the c = 1/2 contour, cell by cell by marching squares (physics/contour.py).
3. **Force**: the perimeter's rate of change under the grid velocity v = sum_i v_i N_i is
   dL/dt = sum_i v_i . sum_q L_q (I - n_q n_q) grad N_i(x_q) (the tangential divergence of v
   along the outline), so the force that lowers gamma L is

       f_i = -gamma sum_q w_q L_q (I - n_q n_q^T) grad N_i(x_q)

   over the Gauss points x_q of the segments (``surface_energy_gauss_points``, weights w_q). No
   curvature appears: nothing to smooth or cap, and a concave cusp gets its full pull. grad N is
   the bilinear hat's (``surface_energy_weight = "hat"``: the segment's cell corners; linear
   along a straight segment, so one Gauss point is exact) or the solver's uGIMP (``"gimp"``).
   Both reproduce constants and linear fields, so every segment's forces have no resultant and
   no torque.
4. **Mass floor**: nodes at the edge of the points' support hold almost no mass but receive
   force from nearby Gauss points; their acceleration f_i / m_i is unbounded. A node below
   m_floor = ``surface_energy_mass_floor`` rho V_c keeps m_i / m_floor of its surface force and
   hands the rest to its 3x3 neighbours in proportion to their mass (``floor_mode = "spread"``,
   momentum kept) or drops it (``"clip"``). The other forces are untouched.

In 3D (``domain.dim = 3``) the energy is gamma times the area: the filter runs along z too, the
surface is cut by marching tetrahedra (physics/tetra.py), the force is taken at three points
of each triangle with (I - n n^T) (:func:`triangle_force`) and the floor spreads to the 3x3x3
neighbours.

Arguments: ``cfg`` (its ``se`` holds this method's switches), ``box`` the active region, ``nd``
the nodes (``mass``, ``volume``, ``colour``, ``surface_force``, and ``force`` that it adds to).
"""

import math

from taichi_sls.backend import ti

from .contour import cell_segments
from .grid import active, ramped_gamma, scatter_add
from .shape import STENCIL_SHAPE, node_weight, stencil
from .small_matrix import ZERO_MATRIX, ZERO_VECTOR
from .tetra import cell_tet_corner, tet_triangles

C_INTERFACE = 0.5  # the outline is the c = 1/2 contour
# a node's neighbourhood, offsets -1..1 per axis, by dimension
NEIGHBOURS = {dim: ((-1, 2),) * dim for dim in (2, 3)}

# Gauss-Legendre points on [0, 1] and weights (summing to 1), by number of points
GAUSS = {
    1: ((0.5,), (1.0,)),
    2: ((0.5 - 0.5 / math.sqrt(3.0), 0.5 + 0.5 / math.sqrt(3.0)), (0.5, 0.5)),
    3: (
        (0.5 - 0.5 * math.sqrt(0.6), 0.5, 0.5 + 0.5 * math.sqrt(0.6)),
        (5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0),
    ),
}


@ti.func
def raw_colour(cfg: ti.template(), nd: ti.template(), I):
    """c_i: the fraction of node i's cell that material fills."""
    return nd.mass[I] / (cfg.rho_ref * cfg.cell_volume)


@ti.func
def colour_field(cfg: ti.template(), box: ti.template(), nd: ti.template()):
    """nd.colour: the colour that is contoured, c_i or its [1 2 1]/4 filter along x and y (3D:
    and z)."""
    if ti.static(cfg.dim == 3):
        _colour_field_3d(cfg, box, nd)
    else:
        _colour_field_2d(cfg, box, nd)


@ti.func
def _colour_field_2d(cfg: ti.template(), box: ti.template(), nd: ti.template()):
    for i, j in ti.ndrange(*active(box)):
        c = 0.0
        if ti.static(cfg.se.filter):
            if i > 0 and j > 0 and i < cfg.nx - 1 and j < cfg.ny - 1:
                for a, b in ti.ndrange(3, 3):  # at run time: one copy of the body
                    wa = (0.5 - 0.25 * ti.abs(a - 1)) * (0.5 - 0.25 * ti.abs(b - 1))
                    c += wa * raw_colour(cfg, nd, ti.Vector([i + a - 1, j + b - 1]))
        else:
            c = raw_colour(cfg, nd, ti.Vector([i, j]))
        nd.colour[i, j] = c


@ti.func
def _colour_field_3d(cfg: ti.template(), box: ti.template(), nd: ti.template()):
    n = ti.Vector([cfg.nx, cfg.ny, cfg.nz])
    for I in ti.grouped(ti.ndrange(*active(box))):
        c = 0.0
        if ti.static(cfg.se.filter):
            if (I > 0).all() and (I < n - 1).all():
                for o in ti.grouped(ti.ndrange(3, 3, 3)):  # at run time: one copy of the body
                    wo = 1.0
                    for d in range(3):
                        wo *= 0.5 - 0.25 * ti.abs(o[d] - 1)
                    c += wo * raw_colour(cfg, nd, I + o - 1)
        else:
            c = raw_colour(cfg, nd, I)
        nd.colour[I] = c


@ti.func
def segment_force(cfg: ti.template(), nd: ti.template(), a, b, gamma):
    """f_i += -gamma w_q L t (t . grad N_i(x_q)) over the Gauss points of segment a-b
    (I - n n^T = t t^T in 2D); below the floor, the node's share as the floor mode says."""
    d = b - a
    L = d.norm()
    if L > 0.0:
        t = d / L
        s, wq = ti.static(GAUSS[cfg.se.gauss_points])
        for q in ti.static(range(len(s))):
            xq = a + s[q] * d
            base, w, dw = stencil(xq, cfg.inv_h, cfg.h, cfg.se.weight_lp, cfg.off)
            for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[cfg.dim])):
                N, gN = node_weight(w, dw, o)
                I = base + o
                tg = t.dot(gN)
                if tg != 0.0:
                    if ti.static(cfg.se.spread):
                        scatter_add(cfg, nd.surface_force, I, (-gamma * wq[q] * L * tg) * t)
                    elif ti.static(cfg.se.floor_mass > 0.0):
                        m = nd.mass[I]
                        scale = m / ti.max(m, cfg.se.floor_mass)
                        scatter_add(cfg, nd.force, I, (-gamma * wq[q] * L * tg * scale) * t)
                    else:
                        scatter_add(cfg, nd.force, I, (-gamma * wq[q] * L * tg) * t)


@ti.func
def spread_light_nodes(cfg: ti.template(), box: ti.template(), nd: ti.template()):
    """floor_mode = "spread": node i keeps m_i / max(m_i, floor) of its surface force and hands
    the rest to its 3x3 neighbours in proportion to their mass. The total force is kept
    (momentum); the torque changes by the rest times at most sqrt(2) h. A node writes its 3x3
    neighbours: in the parallel layouts nodes three apart at a time (:func:`in_passes`)."""
    in_passes(cfg, box, 0, 3, _spread_node, nd, nd, 0.0)


@ti.func
def _spread_node(cfg: ti.template(), nd: ti.template(), target: ti.template(), scale, i, j):
    _spread_node_at(cfg, nd, ti.Vector([i, j]))  # in_passes' visitor in 2D


@ti.func
def _spread_node_at(cfg: ti.template(), nd: ti.template(), I):
    """Node I's share of :func:`spread_light_nodes`."""
    spread_light_node(cfg, nd, I, nd.surface_force[I], cfg.se.floor_mass)


@ti.func
def spread_light_node(cfg: ti.template(), nd: ti.template(), I, f, floor):
    """Force f of node I into nd.force: whole if the node holds at least ``floor`` (kg), else
    its share m_i / floor, the rest to its 3^dim - 1 neighbours by mass."""
    m = nd.mass[I]
    if m >= floor:
        scatter_add(cfg, nd.force, I, f)
    elif f.norm_sqr() > 0.0:
        M = 0.0
        for o in ti.grouped(ti.ndrange(*NEIGHBOURS[cfg.dim])):  # at run time: one copy
            if (o != 0).any():
                M += nd.mass[I + o]
        keep = m / floor
        if M <= 0.0:
            keep = 1.0
        scatter_add(cfg, nd.force, I, keep * f)
        if M > 0.0:
            rest = (1.0 - keep) / M * f
            for o in ti.grouped(ti.ndrange(*NEIGHBOURS[cfg.dim])):
                if (o != 0).any():
                    scatter_add(cfg, nd.force, I + o, nd.mass[I + o] * rest)


@ti.func
def in_passes(
    cfg: ti.template(),
    box: ti.template(),
    shrink: ti.template(),
    stride: ti.template(),
    body: ti.template(),
    nd: ti.template(),
    target: ti.template(),
    scale,
):
    """``body(cfg, nd, target, scale, i, j)`` for every (i, j) in ``active(box, shrink)``,
    where each (i, j) writes nodes less than ``stride`` away along each axis. The blocks layout
    (plain adds): tiles of stride x stride, coloured in four by the parity of their tile
    coordinates as its blocks are (solver/blocks.py); four passes, one per colour, each tile's
    (i, j) in order by one thread. Two tiles of one colour lie a tile apart, so no two threads
    write one node at once, and every node takes its terms in one order whatever the threads (a
    run repeats bit for bit). The other layouts: one loop (serial, or parallel with atomic adds,
    whose order the GPU's atomic P2G leaves open anyway)."""
    b = box[None]
    i0, j0, i1, j1 = b[0], b[1], b[2] - shrink, b[3] - shrink
    if ti.static(cfg.race_free):
        n_ti = (i1 - i0 + stride - 1) // stride
        n_tj = (j1 - j0 + stride - 1) // stride
        for c in ti.static(range(4)):
            ci, cj = ti.static(c % 2, c // 2)
            for u, v in ti.ndrange(
                ti.max(0, (n_ti - ci + 1) // 2), ti.max(0, (n_tj - cj + 1) // 2)
            ):
                lo_i = i0 + stride * (ci + 2 * u)
                lo_j = j0 + stride * (cj + 2 * v)
                for k in range(stride * stride):
                    i = lo_i + k // stride
                    j = lo_j + k % stride
                    if i < i1 and j < j1:
                        body(cfg, nd, target, scale, i, j)
    else:
        for i, j in ti.ndrange((i0, i1), (j0, j1)):
            body(cfg, nd, target, scale, i, j)


@ti.func
def outline_segments(
    cfg: ti.template(),
    box: ti.template(),
    nd: ti.template(),
    visit: ti.template(),
    target: ti.template(),
    scale,
):
    """visit(cfg, target, a, b, scale) for every segment a-b of the c = 1/2 contour of
    nd.colour, cell by cell (marching squares). A Gauss point in cell i has its stencil on
    nodes i-1..i+2: cells four apart never write one node (:func:`in_passes`)."""
    in_passes(cfg, box, 1, 4, ti.static(_cell_outline(visit)), nd, target, scale)


def _cell_outline(visit):
    """The body of :func:`outline_segments` for cell (i, j), with its arguments bound."""

    @ti.func
    def body(cfg: ti.template(), nd: ti.template(), target: ti.template(), scale, i, j):
        if i > 0 and j > 0 and i < cfg.nx - 2 and j < cfg.ny - 2:
            f = C_INTERFACE - ti.Vector(
                [nd.colour[i, j], nd.colour[i + 1, j], nd.colour[i + 1, j + 1], nd.colour[i, j + 1]]
            )
            if f.max() >= 0.0 and f.min() < 0.0:
                x0 = ti.cast(ti.Vector([i, j]) - cfg.off, float) * cfg.h
                count, ends = cell_segments(f, x0, cfg.h)
                for k in range(count):
                    a = ti.Vector([ends[4 * k], ends[4 * k + 1]])
                    b = ti.Vector([ends[4 * k + 2], ends[4 * k + 3]])
                    visit(cfg, target, a, b, scale)

    return body


@ti.func
def surface_force_add(cfg: ti.template(), nd: ti.template(), I, f):
    """Node I's share f of the surface force: kept apart for the spread floor, scaled by
    m_i / max(m_i, floor) for the clip floor, added to nd.force without a floor."""
    if ti.static(cfg.se.spread):
        scatter_add(cfg, nd.surface_force, I, f)
    elif ti.static(cfg.se.floor_mass > 0.0):
        m = nd.mass[I]
        scatter_add(cfg, nd.force, I, (m / ti.max(m, cfg.se.floor_mass)) * f)
    else:
        scatter_add(cfg, nd.force, I, f)


@ti.func
def triangle_force(cfg: ti.template(), nd: ti.template(), a, b, c, gamma):
    """f_i += -gamma A / 3 (I - n n^T) grad N_i(x_q) over the three points x_q = (2/3, 1/6, 1/6)
    in barycentric coordinates of triangle abc (weights 1/3: exact to degree 2). The triangle
    lies in one cell, where the trilinear hat's grad N is bilinear, so degree 2 on the plane of
    the triangle: the rule is exact for the hat (``surface_energy_gauss_points`` is the 2D
    segments' count)."""
    nrm = (b - a).cross(c - a)
    A2 = nrm.norm()
    if A2 > 0.0:
        n = nrm / A2
        fq = -gamma * A2 / 6.0  # -gamma w_q A with A = |nrm| / 2, w_q = 1/3
        mid = (a + b + c) / 6.0
        for q in range(3):  # at run time: one copy of the stencil loop
            xq = mid + 0.5 * ti.select(q == 0, a, ti.select(q == 1, b, c))
            base, w, dw = stencil(xq, cfg.inv_h, cfg.h, cfg.se.weight_lp, cfg.off)
            for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[cfg.dim])):
                N, gN = node_weight(w, dw, o)
                g = gN - n.dot(gN) * n
                if g.norm_sqr() != 0.0:
                    surface_force_add(cfg, nd, base + o, fq * g)


@ti.func
def outline_triangles(
    cfg: ti.template(),
    box: ti.template(),
    nd: ti.template(),
    visit: ti.template(),
    target: ti.template(),
    scale,
):
    """visit(cfg, target, a, b, c, scale) for every triangle abc of the c = 1/2 surface of
    nd.colour, cube by cube (marching tetrahedra, physics/tetra.py). One loop over the cubes
    with atomic adds: the 3D layouts are not race free (config/dim.py refuses blocks)."""
    ti.static_assert(not cfg.race_free, "3D surface force: atomic adds only")
    n = ti.Vector([cfg.nx, cfg.ny, cfg.nz])
    for I in ti.grouped(ti.ndrange(*active(box, 1))):
        if (I > 0).all() and (I < n - 2).all():
            lo, hi = 1.0, -1.0
            for o in ti.grouped(ti.ndrange(2, 2, 2)):
                fo = C_INTERFACE - nd.colour[I + o]
                lo = ti.min(lo, fo)
                hi = ti.max(hi, fo)
            if hi >= 0.0 and lo < 0.0:
                x0 = ti.cast(I - cfg.off, float) * cfg.h
                for t in range(6):
                    f = ti.Vector([0.0, 0.0, 0.0, 0.0])
                    p = ti.Matrix(ZERO_MATRIX[4, 3])
                    for k in range(4):
                        o = cell_tet_corner(I, t, k)
                        f[k] = C_INTERFACE - nd.colour[I + o]
                        for d in range(3):
                            p[k, d] = x0[d] + cfg.h * o[d]
                    count, tri = tet_triangles(f, p)
                    for q in range(count):
                        a = ti.Vector([tri[3 * q, 0], tri[3 * q, 1], tri[3 * q, 2]])
                        b = ti.Vector([tri[3 * q + 1, 0], tri[3 * q + 1, 1], tri[3 * q + 1, 2]])
                        c = ti.Vector([tri[3 * q + 2, 0], tri[3 * q + 2, 1], tri[3 * q + 2, 2]])
                        visit(cfg, target, a, b, c, scale)


@ti.func
def surface_energy_force(cfg: ti.template(), box: ti.template(), nd: ti.template(), t):
    """The outline of the colour field and its surface-energy force, added to nd.force."""
    if ti.static(cfg.se.spread):
        for I in ti.grouped(ti.ndrange(*active(box))):
            nd.surface_force[I] = ti.Vector(ZERO_VECTOR[cfg.dim])
    colour_field(cfg, box, nd)
    if ti.static(cfg.dim == 3):
        outline_triangles(cfg, box, nd, triangle_force, nd, ramped_gamma(cfg, t))
    else:
        outline_segments(cfg, box, nd, segment_force, nd, ramped_gamma(cfg, t))
    if ti.static(cfg.se.spread):
        if ti.static(cfg.dim == 3):
            for I in ti.grouped(ti.ndrange(*active(box))):
                _spread_node_at(cfg, nd, I)
        else:
            spread_light_nodes(cfg, box, nd)
