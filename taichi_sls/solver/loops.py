"""How a stage visits the points, and where what they add to the run's totals goes: one loop
over all points (the serial and parallel layouts), or the blocks layout's loops over blocks of
sorted points (solver/blocks.py), scatters in four colour passes, with per-block accumulators.

A stage hands a point body ``body(st, p, blk, heat, geom)`` to :func:`point_loop`; ``blk`` is
the point's block (0 outside the blocks layout)."""

from taichi_sls.backend import ti

from ..physics.grid import active, bed_plane
from ..physics.shape import stencil, stencil_base
from ..physics.thermal import top_loss_column, wall_heat
from .blocks import MARGIN, SIDE
from .step_config import Layout


def blocks(st) -> bool:
    return st.cfg.layout == Layout.BLOCKS


@ti.func
def point_loop(
    st: ti.template(),
    body: ti.template(),
    heat: ti.template(),
    geom: ti.template(),
    scatter: ti.template(),
):
    """``body`` for every point. ``scatter``: the body writes to the nodes around its point, so
    in the blocks layout it runs colour by colour."""
    if ti.static(blocks(st)):
        spread = ti.static(st.blocks.spread)  # blocks.LOOP_ITERATIONS: every thread gets work
        if ti.static(scatter):
            for c in ti.static(range(4)):
                for j in range(ti.static(st.blocks.n_colour[c] * spread)):
                    if j % spread == 0:
                        block_points(st, st.blocks.by_colour[c, j // spread], body, heat, geom)
        else:
            for j in range(st.blocks.n_blocks * spread):
                if j % spread == 0:
                    block_points(st, j // spread, body, heat, geom)
    else:
        for p in range(st.cfg.n_points):
            body(st, p, 0, heat, geom)


@ti.func
def point_stencil(cfg: ti.template(), pt: ti.template(), p):
    base, w, dw = stencil(pt.x[p], cfg.inv_h, cfg.h, cfg.lp, cfg.off)
    return _clamped(cfg, base), w, dw


@ti.func
def point_base(cfg: ti.template(), pt: ti.template(), p):  # point_stencil's base alone
    return _clamped(cfg, stencil_base(pt.x[p], cfg.inv_h, cfg.off))


@ti.func
def _clamped(cfg: ti.template(), base):
    # A point that has left the grid (or become NaN) must not write outside the arrays: the
    # guard reports it at the next frame; the 2-cell padding keeps a healthy run far from this.
    return ti.max(ti.min(base, ti.Vector([n - 4 for n in cfg.shape])), 1)


@ti.func
def block_points(
    st: ti.template(), b, body: ti.template(), heat: ti.template(), geom: ti.template()
):
    """``body`` for the points of block b, in their sorted order (one thread)."""
    for p in range(st.blocks.start[b], st.blocks.start[b] + st.blocks.count[b]):
        body(st, p, b, heat, geom)


@ti.func
def add_laser_energy(st: ti.template(), blk, e):
    if ti.static(blocks(st)):
        st.blocks.laser_energy[blk] = st.blocks.laser_energy[blk] + e
    else:
        st.scalars.laser_energy[None] += e


@ti.func
def add_heat_out(st: ti.template(), blk, q):
    if ti.static(blocks(st)):
        st.blocks.heat_out[blk] = st.blocks.heat_out[blk] + q
    else:
        st.scalars.heat_out[None] += q


@ti.func
def wall_heat_in_order(st: ti.template(), dt_heat):
    """The blocks layout: the fixed nodes' heat to the walls' total, summed in node order by one
    thread (the serial layout's order), so that the total repeats bit for bit."""
    ti.loop_config(serialize=True)
    for I in ti.grouped(ti.ndrange(*active(st.box))):
        st.scalars.heat_out[None] += wall_heat(st.cfg, st.nodes, I, dt_heat)


@ti.func
def heat_step(st: ti.template()):
    """The heat step: heat_every mechanical steps; implicit: the step over its heat substeps
    (solver/implicit.py)."""
    dt_heat = 0.0
    if ti.static(st.cfg.implicit):
        dt_heat = st.scalars.dt_heat[None]
    else:
        dt_heat = st.scalars.dt[None] * st.cfg.heat_every
    return dt_heat


@ti.func
def top_loss_in_order(st: ti.template()):
    """The top surface's loss to the chamber (physics/thermal.py), column by column; its total
    summed in column order by one thread, so that it repeats bit for bit."""
    dt_heat = heat_step(st)
    rows = active(st.box)[1]
    if ti.static(st.cfg.parallel):
        ti.loop_config(serialize=True)
    for column in ti.grouped(ti.ndrange(*bed_plane(st.box))):
        lost = top_loss_column(st.cfg, st.nodes, column, rows[0], rows[1], dt_heat)
        st.scalars.heat_out[None] += lost


@ti.func
def peak_temperature(st: ti.template(), blk, T):
    if ti.static(blocks(st)):
        st.blocks.T_peak[blk] = ti.max(st.blocks.T_peak[blk], T)
    else:
        ti.atomic_max(st.scalars.T_peak[None], T)


@ti.func
def grow_box(st: ti.template(), blk, p):
    """Grow the active region to hold point p's level-set footprint (5x5 nodes) plus
    ``box_margin`` nodes; grid loops run over it only. It never shrinks, so no node outside it
    has ever been written: there every field keeps its empty initial value. Called where a
    point has moved (the end of G2P), so that the next step's grid loops cover it."""
    if ti.static(st.cfg.active_region):
        m = ti.static(st.cfg.box_margin)
        dim = ti.static(st.cfg.dim)
        base = ti.cast(ti.floor(st.points.x[p] * st.cfg.inv_h + 0.5), ti.i32) - 1 + st.cfg.off
        lo = ti.max(base - 1 - m, 0)
        hi = ti.min(base + 4 + m, ti.Vector(st.cfg.shape))
        if ti.static(blocks(st)):
            st.blocks.box[blk] = widen(st.blocks.box[blk], lo, hi)
        else:
            for d in ti.static(range(dim)):
                ti.atomic_min(st.box[None][d], lo[d])
                ti.atomic_max(st.box[None][dim + d], hi[d])


@ti.func
def check_block(st: ti.template(), blk, p):
    """Blocks layout: flag a point that has drifted MARGIN cells out of its block (the points
    are then sorted again before the next step)."""
    if ti.static(blocks(st)):
        cell = ti.cast(ti.floor(st.points.x[p] * st.cfg.inv_h), ti.i32) + st.cfg.off
        b0 = ti.Vector([blk % st.blocks.n_bx, blk // st.blocks.n_bx]) * SIDE
        if (cell < b0 - MARGIN).any() or (cell >= b0 + SIDE + MARGIN).any():
            st.blocks.needs_sort[None] = 1


@ti.func
def reduce_blocks(st: ti.template()):
    """Blocks layout: the per-block accumulators into the run's totals, in block order (the
    result does not depend on the thread count), and reset."""
    if ti.static(blocks(st)):
        sc = ti.static(st.scalars)
        ti.loop_config(serialize=True)
        for b in range(st.blocks.n_blocks):
            sc.laser_energy[None] += st.blocks.laser_energy[b]
            sc.heat_out[None] += st.blocks.heat_out[b]
            sc.T_peak[None] = ti.max(sc.T_peak[None], st.blocks.T_peak[b])
            bx = st.blocks.box[b]
            st.box[None] = widen(st.box[None], ti.Vector([bx[0], bx[1]]), ti.Vector([bx[2], bx[3]]))
            st.blocks.laser_energy[b] = 0.0
            st.blocks.heat_out[b] = 0.0
            st.blocks.box[b] = box_empty(st)


@ti.func
def box_empty(st: ti.template()):
    """The box that holds nothing: its lower corner at the arrays' far end, its upper at 0."""
    return ti.Vector(ti.static(list(st.cfg.shape) + [0] * st.cfg.dim))


@ti.func
def widen(box, lo, hi):
    """The box [i0, j0, i1, j1) grown to hold [lo, hi) (the blocks layout, 2D)."""
    return ti.Vector(
        [ti.min(box[0], lo[0]), ti.min(box[1], lo[1]), ti.max(box[2], hi[0]), ti.max(box[3], hi[1])]
    )


@ti.kernel
def in_order(st: ti.template(), body: ti.template()):
    """``body(st)`` as one kernel: its loops parallel, or in the serial layout serialized, so
    that a run repeats bit for bit."""
    if ti.static(st.cfg.parallel):
        body(st)
    else:
        ti.loop_config(serialize=True)
        for _ in range(1):
            body(st)
