"""Node positions and the active region of the grid."""

import taichi as ti


@ti.func
def node_x(cfg: ti.template(), idx):
    """Position (m) of the node with array index ``idx``."""
    return ti.cast(idx - cfg.off, float) * cfg.h


@ti.func
def active(box: ti.template(), shrink: ti.template() = 0):
    """Index ranges of the active region ``box`` = [i0, j0, i1, j1) for ti.ndrange; ``shrink``
    drops that many nodes at the upper end (1: the cells between active nodes)."""
    b = box[None]
    return (b[0], b[2] - shrink), (b[1], b[3] - shrink)
