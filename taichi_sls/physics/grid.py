"""Node positions, the active region of the grid, and the capillary coefficient in time."""

from taichi_sls.backend import ti


@ti.func
def node_x(cfg: ti.template(), idx):
    """Position (m) of the node with array index ``idx``."""
    return ti.cast(idx - cfg.off, float) * cfg.h


@ti.func
def active(box: ti.template(), shrink: ti.template() = 0):
    """Index ranges of the active region ``box`` = [i0, j0, i1, j1) (3D: [i0, j0, k0, i1, j1,
    k1)) for ti.ndrange; ``shrink`` drops that many nodes at the upper end (1: the cells between
    active nodes)."""
    b = box[None]
    if ti.static(box.n == 6):
        return (b[0], b[3] - shrink), (b[1], b[4] - shrink), (b[2], b[5] - shrink)
    else:
        return (b[0], b[2] - shrink), (b[1], b[3] - shrink)


@ti.func
def bed_plane(box: ti.template()):
    """The index ranges of the active region's node columns, across the bed plane: i in 2D,
    (i, k) in 3D (y up), for ti.ndrange."""
    ranges = active(box)
    if ti.static(box.n == 6):
        return ranges[0], ranges[2]
    else:
        return (ranges[0],)


@ti.func
def ramped_gamma(cfg: ti.template(), t):
    """gamma at time t: ``gamma_ramp_s`` > 0 lets it rise linearly from 0 (either method)."""
    gamma = cfg.gamma
    if ti.static(cfg.gamma_ramp_s > 0.0):
        gamma *= ti.min(1.0, t / cfg.gamma_ramp_s)
    return gamma


@ti.func
def scatter_add(cfg: ti.template(), field: ti.template(), I, v):
    """field[I] += v. An atomic add where writers of several threads may meet at a node (the
    parallel layout); a plain one where the layout keeps them apart (``race_free``: the blocks
    layout, whose threads scatter from blocks of cells far enough apart)."""
    if ti.static(cfg.race_free):
        field[I] = field[I] + v
    else:
        field[I] += v


@ti.func
def scatter_min(cfg: ti.template(), field: ti.template(), I, v):
    """field[I] = min(field[I], v), atomic or plain as :func:`scatter_add`."""
    if ti.static(cfg.race_free):
        field[I] = ti.min(field[I], v)
    else:
        ti.atomic_min(field[I], v)
