"""The grid fields of the current points without a step, for monitors, diagnostics and
verification: the level set of eq. 21, the surface-energy colour, and the step's stages through
the surface force (solver/step.py)."""

from taichi_sls.backend import ti

from ..physics.grid import active
from ..physics.level_set import level_set, scatter_level_set
from ..physics.surface_energy import colour_field
from .loops import point_base, point_loop
from .step import STAGES, SURFACE, grow_box_all, p2g


@ti.kernel
def interface_fields(st: ti.template()):
    """The level set of eq. 21 (2D) and the surface-energy colour (nodes.phi, nodes.colour) of the
    current points, for monitors (also with surface tension off): one kernel for both (a
    kernel's compilation costs tens of ms whatever its size). The colour: the step's stages up
    to P2G without heat or geometry, then the colour (filtered as the case says). Leaves the
    curvature the step keeps between rebuilds untouched."""
    grow_box_all(st)
    for stage in ti.static(STAGES[: STAGES.index(p2g) + 1]):
        stage(st, False, False)
    colour_field(st.cfg, st.box, st.nodes)
    if ti.static(st.cfg.dim == 2):  # eq. 21's level set is 2D (the paper's CSF)
        for I in ti.grouped(ti.ndrange(*active(st.box))):
            st.nodes.phi_raw[I] = st.cfg.phi_cap
        point_loop(st, _level_set_body, False, True, True)
        level_set(st.cfg, st.box, st.nodes, st.surf)


@ti.func
def _level_set_body(st: ti.template(), p, blk, heat: ti.template(), geom: ti.template()):
    scatter_level_set(st.cfg, st.points, st.nodes, p, point_base(st.cfg, st.points, p))


@ti.kernel
def surface_only(st: ti.template()):
    """Grid mass, level set, curvature and capillary force of the current points, without a
    step (diagnostics and verification): the step's stages through the surface force."""
    for stage in ti.static(STAGES[: SURFACE + 1]):
        stage(st, True, True)
