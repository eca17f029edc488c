"""Mirror (symmetry) walls: ``boundary.<side>.mechanical = "mirror"``.

A mirror wall is a plane of symmetry on the wall's node line: the run is the half (two
mirrors: the quarter) of a scene that is symmetric about it. Its ghost nodes beyond the plane
hold the mirror image of the nodes inside, as if the mirrored points were there:

1. After the P2G (:func:`fold_after_p2g`): the active region is widened to every ghost node on
   the mirrored side; a ghost node I's sums (mass, momentum, force, heat capacity, c T, the
   volume colour, the sub-grid sums) are added to its image J = 2 P - I (vectors with their
   normal component reversed), and then I takes J's sums, reflected. A node on the plane P
   takes its own sums twice (the mirrored points give it as much as the points do), its normal
   momentum and force cancelling. The colour of the surface-energy method is then symmetric:
   no c = 1/2 surface appears at the plane, and the triangles in the ghost cells give the
   nodes inside the force of the mirrored half's surface.
2. Before the grid update (:func:`fold_before_update`): the heat rates are folded as in 1, and
   the ghost nodes take the reflected force of their images (the surface force on a ghost node
   is not complete: the ghost layer ends).
3. The grid update (physics/mechanics.py ``apply_walls``): the plane's nodes lose their normal
   velocity; the ghost nodes' velocities are then the reflected ones of their images.

So a mechanical mirror slips (zero normal velocity, tangential free) and is insulated (no heat
crosses it: the heat flux is symmetric). Several mirrors fold one after the other (a corner's
ghost nodes take the sums of all four quarters). The 2D and 3D paths are one; without a mirror
nothing compiles in.

Arguments: ``cfg`` the step's configuration (its ``wall_mechanical`` codes), ``box`` the active
region, ``nd`` the nodes, ``heat`` the heat clock (the heat sums are folded on heat steps only).
"""

from taichi_sls.backend import ti

from .codes import WallMechanical
from .grid import active


def mirror_planes(cfg) -> tuple[tuple[int, int], ...]:
    """(axis, side) of every mirror wall: side 0 the lower wall (x, y or z = 0), 1 the upper."""
    return tuple(
        (d, s)
        for d in range(cfg.dim)
        for s in (0, 1)
        if cfg.wall_mechanical[2 * d + s] == WallMechanical.MIRROR
    )


def plane_index(cfg, d: int, s: int) -> int:
    """The array index of the mirror's node line along axis d."""
    return cfg.wall_index[d] if s == 1 else cfg.off


@ti.func
def _widen(cfg: ti.template(), box: ti.template()):
    """The active region holds every ghost node beyond each mirror (they have never been
    written before: zero, as an empty node should be)."""
    for d, s in ti.static(mirror_planes(cfg)):
        if ti.static(s == 0):
            box[None][d] = 0
        else:
            box[None][cfg.dim + d] = cfg.shape[d]


@ti.func
def _fold_scalar(field: ti.template(), I, J, twice):
    """field[J] += field[I], then field[I] = field[J]; on the plane (twice) field[I] *= 2."""
    if twice:
        field[I] = 2.0 * field[I]
    else:
        field[J] += field[I]
        field[I] = field[J]


@ti.func
def _reflected(v, d: ti.template()):
    r = v
    r[d] = -v[d]
    return r


@ti.func
def _fold_vector(field: ti.template(), I, J, d: ti.template(), twice):
    """As :func:`_fold_scalar` for a vector, the normal component reversed across the plane."""
    if twice:
        field[I] = field[I] + _reflected(field[I], d)
    else:
        field[J] += _reflected(field[I], d)
        field[I] = _reflected(field[J], d)


@ti.func
def _for_ghosts(
    st: ti.template(), d: ti.template(), s: ti.template(), stage: ti.template(), heat: ti.template()
):
    """:func:`_fold_node` for each ghost node I beyond plane (d, s) with its image J inside the
    active region, and (twice, J = I) for each node on the plane."""
    box = ti.static(st.box)
    P = ti.static(plane_index(st.cfg, d, s))
    b = box[None]
    for I in ti.grouped(ti.ndrange(*active(box))):
        beyond = I[d] < P if ti.static(s == 0) else I[d] > P
        J = I
        J[d] = 2 * P - I[d]
        if I[d] == P:
            _fold_node(st, I, I, d, True, stage, heat)
        elif beyond and J[d] >= b[d] and J[d] < b[st.cfg.dim + d]:
            _fold_node(st, I, J, d, False, stage, heat)


@ti.func
def _fold_node(
    st: ti.template(), I, J, d: ti.template(), twice, stage: ti.template(), heat: ti.template()
):
    """Stage 0: the P2G's sums (1. above); stage 1: the heat rate and the ghosts' force (2.)."""
    nd = ti.static(st.nodes)
    if ti.static(stage == 0):
        _fold_scalar(nd.mass, I, J, twice)
        _fold_vector(nd.momentum, I, J, d, twice)
        _fold_vector(nd.force, I, J, d, twice)
        if ti.static(st.cfg.thermal):
            if heat:
                _fold_scalar(nd.heat_capacity, I, J, twice)
                _fold_scalar(nd.capacity_T, I, J, twice)
                if ti.static(st.cfg.subgrid_filter > 0.0):
                    _fold_scalar(nd.deviation, I, J, twice)
                    _fold_scalar(nd.deviation_capacity, I, J, twice)
    else:
        if not twice:
            nd.force[I] = _reflected(nd.force[J], d)
        if ti.static(st.cfg.thermal):
            if heat:
                _fold_scalar(nd.heat_rate, I, J, twice)


@ti.func
def fold_after_p2g(st: ti.template(), heat: ti.template(), geom: ti.template()):
    """Stage after the P2G: widen the active region and fold the P2G's sums (1. above)."""
    if ti.static(len(mirror_planes(st.cfg)) > 0):
        _widen(st.cfg, st.box)
        for d, s in ti.static(mirror_planes(st.cfg)):
            _for_ghosts(st, d, s, 0, heat)


@ti.func
def fold_before_update(st: ti.template(), heat: ti.template(), geom: ti.template()):
    """Stage before the grid update: fold the heat rates, reflect the force into the ghosts."""
    for d, s in ti.static(mirror_planes(st.cfg)):
        _for_ghosts(st, d, s, 1, heat)
