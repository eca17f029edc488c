"""A periodic depth (3D, ``boundary.front`` and ``boundary.back`` with ``mechanical =
"periodic"``): z wraps with the period D = depth, the node arrays' z indices off .. off + ncz - 1
one period (node off + ncz and the ghost layers beyond either end are their images).

The transfers keep their indices; two stages of the step fold the images together instead:

    periodic_fold    after the node temperatures: every scattered node sum (mass, momentum,
                     heat capacity, the colour's volume) summed over a node's images and
                     written back to all of them, the force summed into the canonical image
                     alone, the node temperatures recomputed; the active region's z range cut
                     to one period of cells, so that the surface-energy outline is drawn once
    periodic_close   before the grid update: the surface force that the outline handed to
                     nodes outside that range (never spread) spread at their canonical image,
                     the force and heat rate summed over the images and written back to all,
                     the active region back to the whole z range, the points wrapped into
                     [0, D)

so the grid update, local to a node, gives every image the same velocity and temperature
increment, and G2P reads a point's stencil wherever its indices fall. Without a periodic depth
both stages compile to nothing (2D and walled 3D unchanged)."""

from taichi_sls.backend import ti

from ..physics.codes import SurfaceMethod, WallMechanical
from ..physics.small_matrix import ZERO_VECTOR
from ..physics.surface_energy import _spread_node_at
from ..physics.thermal import grid_temperature
from .loops import point_loop


def is_periodic(cfg) -> bool:
    """Whether the case's depth is periodic (a Python bool for ti.static)."""
    return cfg.dim == 3 and cfg.wall_mechanical[4] == WallMechanical.PERIODIC


def _energy(cfg) -> bool:
    return cfg.surface and cfg.surface_method == SurfaceMethod.SURFACE_ENERGY


def with_periodic(stages: tuple, after_temperature, before_update) -> tuple:
    """The step's stages with :func:`periodic_fold` after ``after_temperature`` (the node
    temperatures) and :func:`periodic_close` before ``before_update`` (the grid update)."""
    out = []
    for s in stages:
        if s is before_update:
            out.append(periodic_close)
        out.append(s)
        if s is after_temperature:
            out.append(periodic_fold)
    return tuple(out)


def _images(cfg) -> int:
    """How many periods the arrays reach beyond the canonical one on either side."""
    return cfg.nz // cfg.ncz + 1


@ti.func
def _fold(cfg: ti.template(), field: ti.template(), i, j, k, to_all: ti.template()):
    """field at canonical (i, j, k) := the sum over its images; then every image (to_all) or
    the others zeroed (not to_all)."""
    M = ti.static(_images(cfg))
    total = field[i, j, k] * 0.0
    for m in ti.static(range(-M, M + 1)):
        kk = k + m * cfg.ncz
        if kk >= 0 and kk < cfg.nz:
            total += field[i, j, kk]
    for m in ti.static(range(-M, M + 1)):
        kk = k + m * cfg.ncz
        if kk >= 0 and kk < cfg.nz:
            if ti.static(to_all):
                field[i, j, kk] = total
            else:
                field[i, j, kk] = total if m == 0 else total * 0.0


@ti.func
def _columns(st: ti.template()):
    b = st.box[None]
    return (b[0], b[3]), (b[1], b[4]), (st.cfg.off, st.cfg.off + st.cfg.ncz)


@ti.func
def periodic_fold(st: ti.template(), heat: ti.template(), geom: ti.template()):
    nd = ti.static(st.nodes)
    if ti.static(is_periodic(st.cfg)):
        for i, j, k in ti.ndrange(*_columns(st)):
            _fold(st.cfg, nd.mass, i, j, k, True)
            _fold(st.cfg, nd.momentum, i, j, k, True)
            _fold(st.cfg, nd.force, i, j, k, False)
            if ti.static(st.cfg.thermal):
                if heat:
                    _fold(st.cfg, nd.heat_capacity, i, j, k, True)
                    _fold(st.cfg, nd.capacity_T, i, j, k, True)
                    if ti.static(st.cfg.subgrid_filter > 0.0):
                        _fold(st.cfg, nd.deviation, i, j, k, True)
                        _fold(st.cfg, nd.deviation_capacity, i, j, k, True)
        if ti.static(st.cfg.thermal):
            if heat:
                b = st.box[None]
                for I in ti.grouped(ti.ndrange((b[0], b[3]), (b[1], b[4]), (0, st.cfg.nz))):
                    grid_temperature(st.cfg, nd, I)
        st.box[None][2] = st.cfg.off
        st.box[None][5] = st.cfg.off + st.cfg.ncz + 1  # nodes off .. off + ncz: ncz cells


@ti.func
def _wrap_point(st: ti.template(), p, blk, heat: ti.template(), geom: ti.template()):
    D = st.cfg.ncz * st.cfg.h
    z = st.points.x[p][2]
    st.points.x[p][2] = z - D * ti.floor(z / D)


@ti.func
def periodic_close(st: ti.template(), heat: ti.template(), geom: ti.template()):
    nd = ti.static(st.nodes)
    if ti.static(is_periodic(st.cfg)):
        b = st.box[None]
        lo, hi = st.cfg.off, st.cfg.off + st.cfg.ncz  # the nodes the surface stage spread
        if ti.static(_energy(st.cfg) and st.cfg.se.spread):
            M = ti.static(_images(st.cfg))
            for i, j, k in ti.ndrange(*_columns(st)):
                rest = ti.Vector(ZERO_VECTOR[3])
                for m in ti.static(range(-M, M + 1)):
                    kk = k + m * st.cfg.ncz
                    if kk >= 0 and kk < st.cfg.nz and (kk < lo or kk > hi):
                        rest += nd.surface_force[i, j, kk]
                        nd.surface_force[i, j, kk] = ti.Vector(ZERO_VECTOR[3])
                nd.surface_force[i, j, k] = rest
            for i, j in ti.ndrange((b[0], b[3]), (b[1], b[4])):
                nd.surface_force[i, j, hi] = ti.Vector(ZERO_VECTOR[3])
            for i, j, k in ti.ndrange(*_columns(st)):
                _spread_node_at(st.cfg, nd, ti.Vector([i, j, k]))
        for i, j, k in ti.ndrange(*_columns(st)):
            _fold(st.cfg, nd.force, i, j, k, True)
            if ti.static(st.cfg.thermal):
                if heat:
                    _fold(st.cfg, nd.heat_rate, i, j, k, True)
        st.box[None][2] = 0
        st.box[None][5] = st.cfg.nz
        point_loop(st, _wrap_point, heat, geom, False)
