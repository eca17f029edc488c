"""One volume per cell (``solver.dilatation = "cell"``): the Q1P0 element's dilatation.

Each point's own tr(L) (eq. 18 per point) gives four volume constraints a cell, with four points
per cell, against about two velocity unknowns a node: a nearly incompressible flow locks, and
more along the grid lines than across the diagonal, so a neck grows faster at 45 deg than along
x (docs/record/verification.md, "Neck growth at any angle"). Here every point of a cell takes
the divergence at the cell's centre of the multilinear interpolant of its corner velocities
(the mean divergence over the cell) for its volume change, its shear its own; the mean stress
acts through the same gradient, so the internal power is sum_p V_p sigma_p : L_p of the L_p the
points take. That gradient reaches corners that a point barely touches: a node below
``solver.dilatation_mass_floor`` of a full cell's mass keeps m_i / floor of this force and hands
the rest to its neighbours by mass (momentum kept), as the surface force's floor does
(physics/surface_energy.py). The implicit step floors the gradient instead, in both the
divergence and the force, so that its tangent stays symmetric: corner k of a cell takes
s_k g_k + (m_k / sum m) sum_j (1 - s_j) g_j, s_k = min(1, m_k / floor), which still sums to
zero over the corners (momentum kept; a translation has no divergence). Unfloored, a light
corner takes a full cell's volumetric stiffness and, at steps where inertia no longer holds it,
the cell's volume change: hopper_pa12 at 10 ms steps tore its neck.

Arguments: ``cfg`` the step's configuration, ``nd`` the nodes (``v``, ``mass``,
``pressure_force``, ``force``), ``box`` the active region.
"""

from taichi_sls.backend import ti

from .grid import active, scatter_add
from .small_matrix import IDENTITY, ZERO_VECTOR
from .surface_energy import in_passes, spread_light_node

CELL_CORNERS = {dim: (2,) * dim for dim in (2, 3)}  # a cell's corner offsets, by dimension


@ti.func
def point_cell(cfg: ti.template(), xp):
    """Array index of the lower corner node of the cell that holds x_p (clamped as the point's
    stencil is, so the corners lie in it)."""
    c = ti.cast(ti.floor(xp * cfg.inv_h), ti.i32) + cfg.off
    return ti.max(ti.min(c, ti.Vector([n - 3 for n in cfg.shape])), 1)


@ti.func
def corner_gradient(cfg: ti.template(), o):
    """grad N at the cell's centre of the multilinear hat of its corner at offset o in
    {0, 1}^dim: +-1/h times 1/2 per other axis."""
    g = ti.Vector(ZERO_VECTOR[cfg.dim])
    for d in ti.static(range(cfg.dim)):
        g[d] = (2.0 * o[d] - 1.0) * cfg.inv_h * 0.5 ** (cfg.dim - 1)
    return g


@ti.func
def light_corners(cfg: ti.template(), nd: ti.template(), c):
    """The implicit step's floor of cell c (module docstring): the gradient its light corners
    give up, sum_k (1 - s_k) g_k with s_k = min(1, m_k / floor), and the corners' mass."""
    rest = ti.Vector(ZERO_VECTOR[cfg.dim])
    mass = 0.0
    if ti.static(_floored(cfg)):
        for o in ti.grouped(ti.ndrange(*CELL_CORNERS[cfg.dim])):
            m = nd.mass[c + o]
            rest += (1.0 - ti.min(1.0, m / cfg.dilatation_floor)) * corner_gradient(cfg, o)
            mass += m
    return rest, mass


@ti.func
def cell_gradient(cfg: ti.template(), nd: ti.template(), c, o, rest, mass):
    """The gradient of corner o of cell c that the cell's divergence and mean stress take: at
    the cell's centre; in the implicit step floored, s_o g_o plus its mass's share of what the
    light corners give up (:func:`light_corners`)."""
    g = corner_gradient(cfg, o)
    if ti.static(_floored(cfg)):
        m = nd.mass[c + o]
        g = ti.min(1.0, m / cfg.dilatation_floor) * g + m / ti.max(mass, 1e-300) * rest
    return g


def _floored(cfg) -> bool:
    """Whether the cell's gradient is floored: the implicit step's, with a floor."""
    return cfg.implicit and cfg.dilatation_floor > 0.0


@ti.func
def cell_divergence(cfg: ti.template(), nd: ti.template(), xp):
    """div v at the centre of the cell that holds x_p, from its corner nodes."""
    c = point_cell(cfg, xp)
    rest, mass = light_corners(cfg, nd, c)
    div = 0.0
    for o in ti.grouped(ti.ndrange(*CELL_CORNERS[cfg.dim])):  # at run time: one copy
        div += nd.v[c + o].dot(cell_gradient(cfg, nd, c, o, rest, mass))
    return div


@ti.func
def cell_velocity_gradient(cfg: ti.template(), nd: ti.template(), xp, L):
    """L with its trace replaced by the divergence at the centre of x_p's cell: the cell's
    dilatation, the point's own shear (the explicit motion and the implicit residual alike)."""
    div = cell_divergence(cfg, nd, xp)
    return L + (div - L.trace()) / cfg.dim * ti.Matrix(IDENTITY[cfg.dim])


@ti.func
def cell_pressure_force(cfg: ti.template(), nd: ti.template(), target: ti.template(), xp, V, sig):
    """-V mean_stress grad N at the centre of x_p's cell onto its corners in ``target`` (the
    explicit step's nd.pressure_force, before the floor; the implicit step's internal force,
    through the floored gradient); returns the deviator, whose force goes through the point's
    own gradients. The mean is the in-plane one in 2D (trace / dim), as the cell's divergence
    is."""
    mean_stress = sig.trace() / cfg.dim
    c = point_cell(cfg, xp)
    rest, mass = light_corners(cfg, nd, c)
    for o in ti.grouped(ti.ndrange(*CELL_CORNERS[cfg.dim])):
        g = cell_gradient(cfg, nd, c, o, rest, mass)
        scatter_add(cfg, target, c + o, -V * mean_stress * g)
    return sig - mean_stress * ti.Matrix(IDENTITY[cfg.dim])


@ti.func
def pressure_floor(st: ti.template(), heat: ti.template(), geom: ti.template()):
    """The step's stage after the P2G (solver/step.py STAGES), with ``dilatation = "cell"``:
    the mean stress's force on the nodes, light ones floored."""
    if ti.static(st.cfg.cell_dilatation):
        pressure_force_floor(st.cfg, st.box, st.nodes)


@ti.func
def pressure_force_floor(cfg: ti.template(), box: ti.template(), nd: ti.template()):
    """nd.pressure_force into nd.force, light nodes' rest spread to their neighbours (module
    docstring): in 2D in the surface force's race-free passes, in 3D with atomic adds."""
    if ti.static(cfg.dim == 3):
        for I in ti.grouped(ti.ndrange(*active(box))):
            _floor_at(cfg, nd, I)
    else:
        in_passes(cfg, box, 0, 3, _floor_node, nd, nd, 0.0)


@ti.func
def _floor_node(cfg: ti.template(), nd: ti.template(), target: ti.template(), scale, i, j):
    _floor_at(cfg, nd, ti.Vector([i, j]))  # in_passes' visitor in 2D


@ti.func
def _floor_at(cfg: ti.template(), nd: ti.template(), I):
    """Node I's pressure force floored into nd.force, then zeroed for the next step's P2G (only
    this visit reads it; it is written nowhere else)."""
    spread_light_node(cfg, nd, I, nd.pressure_force[I], cfg.dilatation_floor)
    nd.pressure_force[I] = ti.Vector(ZERO_VECTOR[cfg.dim])
