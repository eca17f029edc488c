"""One explicit MPM step (update-stress-last) as an ordered list of stages, and its layouts.

    clear_grid     over the active region (grown at the end of G2P to hold every point)
    p2g            mass, momentum, forces (eqs. 10-12); heat capacity (eq. 28)*; eq. 21**
    (fold_after_p2g, fold_before_update: mirror walls; pressure_floor: dilatation = "cell")
    grid_temperature  node temperature (fixed-temperature walls)*
    surface_force  level set and curvature (eqs. 21-24)**; grad m, CSF force (eqs. 19-20)
    heat_flux      grad T_p, conduction and laser heat rates (eqs. 29-31)*
    grid_update    v^{n+1} with walls (eq. 13); dT_i*
    g2p            velocity, position, L, F, J (eqs. 14-18); enthalpy, T, xi_s (eqs. 32-33)*;
                   strain split and Perzyna return map (eqs. 34-45); the active region grows
    advance_clock  t += dt

``STAGES`` writes this order once; every layout, the implicit step (solver/implicit.py) and the grid
views (solver/grid_views.py) run it (or a prefix of it). Two clocks skip what a step does not need.
* Heat runs every ``heat_every`` steps with a heat step of heat_every * dt: conduction's stability
limit is ~100x the elastic one, and its thermal strain increment is spread over the mechanical steps
that follow. ** The level set and curvature are rebuilt every ``curvature_every`` steps (a fraction
of the capillary limit); the CSF force is rebuilt from the current mass every step. Each stage takes
``heat`` and ``geom``: Python bools in the parallel layout (the stages compile in or out), runtime
flags in the serial one.

Layouts. Serial (CPU, small scenes): many steps inside one kernel call with the step loop
serialized, since a kernel launch costs tens of microseconds and the paper's scene has a few
thousand points. Parallel (GPU, large scenes): one kernel call per step, every stage a parallel
loop. Staged (the speed benchmark's comparison only): one kernel call per stage.
"""

from taichi_sls.backend import ti

from ..physics.beam_surface import column_of, find_column_tops
from ..physics.codes import SurfaceMethod, Update
from ..physics.constitutive import stress_update, thermal_strain_increment, thermal_strain_step
from ..physics.csf import csf_force, mass_gradient, surface_geometry
from ..physics.dilatation import pressure_floor
from ..physics.grid import active
from ..physics.held_temperature import hold_at_table
from ..physics.level_set import scatter_level_set
from ..physics.mechanics import (
    g2p_kinematics,
    g2p_velocity,
    grid_remap_velocity,
    grid_velocity,
    p2g_mechanics,
    p2g_momentum,
)
from ..physics.mirror import fold_after_p2g, fold_before_update
from ..physics.small_matrix import ZERO_VECTOR
from ..physics.surface_energy import surface_energy_force
from ..physics.thermal import (
    counts_molten,
    g2p_heat,
    grid_heat,
    grid_temperature,
    p2g_heat_capacity,
    p2g_heat_flux,
)
from .fields import State
from .loops import (
    add_heat_out,
    add_laser_energy,
    check_block,
    grow_box,
    heat_step,
    peak_temperature,
    point_loop,
    point_stencil,
    reduce_blocks,
    top_loss_in_order,
    wall_heat_in_order,
)
from .periodic import with_periodic


@ti.func
def _grow_box_body(st: ti.template(), p, blk, heat: ti.template(), geom: ti.template()):
    grow_box(st, blk, p)


@ti.func
def grow_box_all(st: ti.template()):
    point_loop(st, _grow_box_body, False, False, False)
    reduce_blocks(st)


@ti.kernel
def init_box(st: ti.template()):
    """The active region of the points as they are (before the first step, after a resume)."""
    grow_box_all(st)


@ti.func
def clear_grid(st: ti.template(), heat: ti.template(), geom: ti.template()):
    nd = ti.static(st.nodes)
    for I in ti.grouped(ti.ndrange(*active(st.box))):
        nd.mass[I] = 0.0
        nd.momentum[I] = ti.Vector(ZERO_VECTOR[st.cfg.dim])
        nd.force[I] = ti.Vector(ZERO_VECTOR[st.cfg.dim])
        if ti.static(st.cfg.thermal):
            if heat:
                nd.heat_capacity[I] = 0.0
                nd.capacity_T[I] = 0.0
                nd.heat_rate[I] = 0.0
                if ti.static(st.cfg.subgrid_filter > 0.0):
                    nd.deviation[I] = 0.0
                    nd.deviation_capacity[I] = 0.0
        if ti.static(_csf(st)):
            if geom:
                nd.phi_raw[I] = st.cfg.phi_cap


def _csf(st) -> bool:
    return st.cfg.surface and st.cfg.surface_method == SurfaceMethod.CSF


def _energy(st) -> bool:
    return st.cfg.surface and st.cfg.surface_method == SurfaceMethod.SURFACE_ENERGY


@ti.func
def _p2g_body(st: ti.template(), p, blk, heat: ti.template(), geom: ti.template()):
    pt, nd = ti.static(st.points, st.nodes)
    base, w, dw = point_stencil(st.cfg, pt, p)
    if ti.static(st.cfg.mech):
        p2g_mechanics(st.cfg, pt, nd, p, base, w, dw)
    if ti.static(st.cfg.thermal):
        if heat:
            p2g_heat_capacity(st.cfg, pt, nd, st.materials, p, base, w, dw)
    if ti.static(_csf(st)):
        if geom:
            scatter_level_set(st.cfg, pt, nd, p, base)


@ti.func
def p2g(st: ti.template(), heat: ti.template(), geom: ti.template()):
    point_loop(st, _p2g_body, heat, geom, True)


@ti.func
def on_clock(st: ti.template(), flag: ti.template(), body: ti.template()):
    """``body(st)`` when the clock's ``flag`` is set: a Python bool in the one-call-per-step
    layouts (the stage compiles in or out), a runtime flag in the serial one."""
    if ti.static(isinstance(flag, bool)):
        if ti.static(flag):
            body(st)
    else:
        if flag:
            body(st)


@ti.func
def grid_temperature_stage(st: ti.template(), heat: ti.template(), geom: ti.template()):
    """The node temperatures of a heat step (before the heat flux needs them)."""
    if ti.static(st.cfg.thermal):
        on_clock(st, heat, _grid_temperature_loop)


@ti.func
def _grid_temperature_loop(st: ti.template()):
    for I in ti.grouped(ti.ndrange(*active(st.box))):
        grid_temperature(st.cfg, st.nodes, I)


@ti.func
def surface_force(st: ti.template(), heat: ti.template(), geom: ti.template()):
    if ti.static(_energy(st)):
        surface_energy_force(st.cfg, st.box, st.nodes, st.scalars.t[None])
    if ti.static(_csf(st)):
        # the level set and curvature on their clock; the mass gradient every step
        on_clock(st, geom, _csf_geometry)
        on_clock(st, not geom if ti.static(isinstance(geom, bool)) else geom == 0, _csf_mass)
        csf_force(st.cfg, st.box, st.nodes, st.surf, st.scalars.t[None])


@ti.func
def _csf_geometry(st: ti.template()):
    surface_geometry(st.cfg, st.box, st.nodes, st.surf)


@ti.func
def _csf_mass(st: ti.template()):
    mass_gradient(st.cfg, st.box, st.nodes)


@ti.func
def _heat_flux_body(st: ti.template(), p, blk, heat: ti.template(), geom: ti.template()):
    dt_heat = heat_step(st)
    t = st.scalars.t[None]
    pt = ti.static(st.points)
    base, w, dw = point_stencil(st.cfg, pt, p)
    top = 0.0
    if ti.static(st.cfg.local_surface):
        top = st.column_top[column_of(st.cfg, pt.x[p])]
    nd, mat = ti.static(st.nodes, st.materials)
    e = p2g_heat_flux(st.cfg, pt, nd, mat, st.lasers, p, base, w, dw, t, dt_heat, top)
    if ti.static(st.cfg.laser):
        add_laser_energy(st, blk, e)


@ti.func
def _heat_flux_loop(st: ti.template()):
    point_loop(st, _heat_flux_body, True, False, True)


@ti.func
def _column_tops(st: ti.template()):
    find_column_tops(st.cfg, st.points, st.column_top)


@ti.func
def heat_flux(st: ti.template(), heat: ti.template(), geom: ti.template()):
    if ti.static(st.cfg.thermal):
        if ti.static(st.cfg.local_surface):
            on_clock(st, heat, _column_tops)
        on_clock(st, heat, _heat_flux_loop)
        if ti.static(st.cfg.top_loss):
            on_clock(st, heat, top_loss_in_order)


@ti.func
def grid_update(st: ti.template(), heat: ti.template(), geom: ti.template()):
    dt = st.scalars.dt[None]
    dt_heat = heat_step(st)
    for I in ti.grouped(ti.ndrange(*active(st.box))):
        if ti.static(st.cfg.mech and not st.cfg.implicit):
            grid_velocity(st.cfg, st.nodes, I, dt)
        if ti.static(st.cfg.thermal):
            if heat:
                grid_heat(st.cfg, st.nodes, st.scalars, I, dt_heat)
    if ti.static(st.cfg.thermal and st.cfg.race_free):
        if ti.static(heat):
            wall_heat_in_order(st, dt_heat)


@ti.func
def g2p_point(
    st: ti.template(), p, blk, base, w, dw, dt, kinematics: ti.template(), heat: ti.template()
):
    """Heat, thermal strains and velocity of point p; with ``kinematics`` (USL) also its motion
    and stress."""
    g2p_point_heat(st, p, blk, base, w, dw, dt, heat)
    g2p_point_mechanics(st, p, base, w, dw, dt, kinematics)


@ti.func
def g2p_point_heat(st: ti.template(), p, blk, base, w, dw, dt, heat: ti.template()):
    """Heat (eqs. 32-33) and the thermal strain increment of point p."""
    pt, nd, mat = ti.static(st.points, st.nodes, st.materials)
    if ti.static(st.cfg.thermal):
        if heat:
            chi = st.cfg.subgrid_filter
            if ti.static(st.cfg.implicit):  # its heat step varies (time.adaptive)
                chi = 1.0 - ti.exp(-st.cfg.subgrid_rate * st.scalars.dt_heat[None])
            dt_heat = heat_step(st)  # = dt heat_every explicit; dt_heat[None] implicit
            dT, dxi, q = 0.0, 0.0, 0.0
            if ti.static(st.cfg.imposed):  # held at the table's T at the heat step's end
                t_end = st.scalars.t[None] + dt_heat
                dT, dxi, q = hold_at_table(st.cfg, pt, mat, st.imposed, p, t_end, dt_heat)
            else:
                dT, dxi, q = g2p_heat(st.cfg, pt, nd, mat, p, base, w, dw, chi, dt_heat)
            if ti.static(st.cfg.any_fixed or st.cfg.imposed):
                add_heat_out(st, blk, q)
            peak_temperature(st, blk, pt.T[p])
            if counts_molten(st.cfg, mat[pt.material[p]], pt.solid_fraction[p]):
                pt.time_molten[p] += dt_heat
            if ti.static(st.cfg.th_strain and st.cfg.mech):
                if ti.static(st.cfg.implicit):  # the step's strain: the sum over its substeps
                    inc = thermal_strain_increment(pt, mat, p, dT, dxi)
                    pt.iso_strain_step[p] += inc
                    pt.iso_strain[p] += inc
                else:
                    thermal_strain_step(st.cfg, pt, mat, p, dT, dxi)
        if ti.static(st.cfg.th_strain and st.cfg.mech and not st.cfg.implicit):
            pt.iso_strain[p] += pt.iso_strain_step[p]


@ti.func
def g2p_point_mechanics(st: ti.template(), p, base, w, dw, dt, kinematics: ti.template()):
    """Velocity of point p; with ``kinematics`` (USL) also its motion and stress."""
    pt, nd, mat = ti.static(st.points, st.nodes, st.materials)
    if ti.static(st.cfg.mech):
        g2p_velocity(st.cfg, pt, nd, p, base, w, dw)
        if ti.static(kinematics):
            L = g2p_kinematics(st.cfg, pt, nd, p, base, w, dw, dt)
            stress_update(st.cfg, pt, mat, p, L, dt)


@ti.func
def watch(st: ti.template(), p):
    """Keep the first step at which point p ran hot, inverted or went NaN (fields.WATCHED)."""
    pt, sc = ti.static(st.points, st.scalars)
    k = sc.step[None]
    T = pt.T[p]
    if T > st.cfg.T_runaway or not (T == T):
        ti.atomic_min(sc.first_hot[None], k)
    if pt.J[p] <= 0.0:
        ti.atomic_min(sc.first_inverted[None], k)
    x = pt.x[p]
    if not ((x == x).all() and pt.J[p] == pt.J[p]):
        ti.atomic_min(sc.first_nan[None], k)


def _musl(st) -> bool:
    return st.cfg.update == Update.MUSL


@ti.func
def _g2p_body(st: ti.template(), p, blk, heat: ti.template(), geom: ti.template()):
    base, w, dw = point_stencil(st.cfg, st.points, p)
    g2p_point(st, p, blk, base, w, dw, st.scalars.dt[None], ti.static(not _musl(st)), heat)
    watch(st, p)
    if ti.static(not _musl(st)):
        grow_box(st, blk, p)
        check_block(st, blk, p)


@ti.func
def _momentum_body(st: ti.template(), p, blk, heat: ti.template(), geom: ti.template()):
    base, w, dw = point_stencil(st.cfg, st.points, p)
    p2g_momentum(st.cfg, st.points, st.nodes, p, base, w, dw)


@ti.func
def _kinematics_body(st: ti.template(), p, blk, heat: ti.template(), geom: ti.template()):
    dt = st.scalars.dt[None]
    base, w, dw = point_stencil(st.cfg, st.points, p)
    L = g2p_kinematics(st.cfg, st.points, st.nodes, p, base, w, dw, dt)
    stress_update(st.cfg, st.points, st.materials, p, L, dt)
    grow_box(st, blk, p)
    check_block(st, blk, p)


@ti.func
def g2p(st: ti.template(), heat: ti.template(), geom: ti.template()):
    nd = ti.static(st.nodes)
    point_loop(st, _g2p_body, heat, geom, False)
    if ti.static(_musl(st) and st.cfg.mech):
        for I in ti.grouped(ti.ndrange(*active(st.box))):
            nd.momentum[I] = ti.Vector(ZERO_VECTOR[st.cfg.dim])
        point_loop(st, _momentum_body, heat, geom, True)
        for I in ti.grouped(ti.ndrange(*active(st.box))):
            grid_remap_velocity(st.cfg, nd, I)
        point_loop(st, _kinematics_body, heat, geom, False)


@ti.func
def advance_clock(st: ti.template(), heat: ti.template(), geom: ti.template()):
    reduce_blocks(st)
    st.scalars.t[None] = st.scalars.t[None] + st.scalars.dt[None]
    st.scalars.step[None] += 1


# The order of one step, written once.
STAGES = (
    clear_grid,
    p2g,
    fold_after_p2g,
    pressure_floor,
    grid_temperature_stage,
    surface_force,
    heat_flux,
    fold_before_update,
    grid_update,
    g2p,
    advance_clock,
)
STAGES = with_periodic(STAGES, grid_temperature_stage, grid_update)  # solver/periodic.py
SURFACE = STAGES.index(surface_force)


@ti.func
def substep(st: ti.template(), heat: ti.template(), geom: ti.template()):
    for stage in ti.static(STAGES):
        stage(st, heat, geom)


@ti.kernel
def advance_serial(st: ti.template(), n: ti.i32):
    """CPU layout: n steps in one call."""
    ti.loop_config(serialize=True)
    for _ in range(n):
        k = st.scalars.step[None]
        substep(st, k % st.cfg.heat_every == 0, k % st.cfg.geom_every == 0)


@ti.kernel
def advance_one(st: ti.template(), heat: ti.template(), geom: ti.template()):
    """GPU layout: one step per call, each stage a parallel loop."""
    substep(st, heat, geom)


@ti.kernel
def run_stage(st: ti.template(), stage: ti.template(), heat: ti.template(), geom: ti.template()):
    """One stage as its own kernel call (the staged layout)."""
    stage(st, heat, geom)


def _clocks(st: State, k: int) -> tuple[bool, bool]:
    return k % st.cfg.heat_every == 0, k % st.cfg.geom_every == 0


def advance(st: State, n: int) -> None:
    """n steps in the state's layout: serial (one call) or parallel (one call per step). The
    layout is fixed when the state is made: it decides which loops are unrolled."""
    if st.cfg.parallel:
        k = int(st.scalars.step[None])
        for i in range(k, k + n):
            advance_one(st, *_clocks(st, i))
    else:
        advance_serial(st, n)


def advance_staged(st: State, n: int) -> None:
    """n steps, every stage its own kernel call (the speed benchmark's comparison)."""
    if not st.cfg.parallel:
        raise ValueError("advance_staged needs a state made with the parallel layout")
    k = int(st.scalars.step[None])
    for i in range(k, k + n):
        for stage in STAGES:
            run_stage(st, stage, *_clocks(st, i))
