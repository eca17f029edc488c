"""The surface-energy colour of the current points over a periodic depth, without a step (the
verification's neck sections in 3D): the step's stages through the fold of solver/periodic.py,
so that a node near z = 0 or z = D holds the volume of the points on either side."""

from taichi_sls.backend import ti

from ..physics.surface_energy import colour_field
from .periodic import periodic_fold
from .step import STAGES, grow_box_all


@ti.kernel
def periodic_colour(st: ti.template()):
    """nodes.colour over one period of node layers (off .. off + ncz); the active region's z
    range restored afterwards, as the step's closing stage leaves it."""
    grow_box_all(st)
    for stage in ti.static(STAGES[: STAGES.index(periodic_fold) + 1]):
        stage(st, False, False)
    colour_field(st.cfg, st.box, st.nodes)
    st.box[None][2] = 0
    st.box[None][5] = st.cfg.nz
