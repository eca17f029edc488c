"""One explicit MPM step (update-stress-last), its stage order, and the kernel layouts.

    active region (grows to hold every point plus margins; the grid loops run over it only)
    clear grid
    P2G        mass, momentum, forces (eqs. 10-12); heat capacity (eq. 28)*; level set (eq. 21)**
    grid       v^n; node temperature (fixed-temperature walls)*
    surface    contour, redistance, curvature (eqs. 21-24)**; grad m, CSF force (eqs. 19-20)
    P2G heat   grad T_p, conduction and laser heat rates (eqs. 29-31)*
    grid       v^{n+1} with walls (eq. 13); dT_i*
    G2P        velocity, position, L, F, J (eqs. 14-18); enthalpy, T, xi_s (eqs. 32-33)*;
               strain split and Perzyna return map (eqs. 34-45)

Two clocks skip what a step does not need. * Heat runs every ``heat_every`` steps with a heat
step of heat_every * dt: conduction's stability limit is ~100x the elastic one, and its thermal
strain increment is spread over the mechanical steps that follow. ** The level set and curvature
are rebuilt every ``curvature_every`` steps (a fraction of the capillary limit); the CSF force is
rebuilt from the current mass every step.

Layouts. Serial (CPU, small scenes): many steps inside one kernel call with the step loop
serialized, since a kernel launch costs tens of microseconds and the paper's scene has a few
thousand points. Parallel (GPU, large scenes): one kernel call per step, every stage a parallel
loop. Staged (the speed benchmark's comparison only): one kernel call per stage.
"""

import taichi as ti

from .constitutive import embed3, perzyna_update
from .materials import P, lerp_phase
from .mechanics import (
    g2p_kinematics,
    g2p_velocity,
    grid_remap_velocity,
    grid_velocity,
    p2g_mechanics,
    p2g_momentum,
)
from .shape import stencil
from .state import State, active
from .surface import (
    blur_level_set,
    csf_force,
    curvature,
    extend_and_smooth,
    level_set,
    mass_gradient,
    scatter_level_set,
    surface_geometry,
)
from .thermal import g2p_heat, grid_heat, grid_temperature, p2g_heat_capacity, p2g_heat_flux


@ti.func
def _stencil(st: ti.template(), p):
    base, w, dw = stencil(st.x[p], st.inv_h, st.h, st.lp, st.off)
    # A point that has left the grid (or become NaN) must not write outside the arrays: clamp
    # its stencil; the guard reports it at the next frame. The 2-cell padding keeps every point
    # of a healthy run far from this bound.
    base = ti.max(ti.min(base, ti.Vector([st.nx - 4, st.ny - 4])), 1)
    return base, w, dw


@ti.func
def update_box(st: ti.template()):
    """Grow the active region to hold every point's level-set footprint (5x5 nodes) plus
    ``box_margin`` nodes; grid loops run over it only. It never shrinks, so no node outside it
    has ever been written: there every field keeps its empty initial value."""
    if ti.static(st.active_region):
        m = ti.static(st.box_margin)
        for p in range(st.n_points):
            base = ti.cast(ti.floor(st.x[p] * st.inv_h + 0.5), ti.i32) - 1 + st.off
            ti.atomic_min(st.box[None][0], ti.max(base[0] - 1 - m, 0))
            ti.atomic_min(st.box[None][1], ti.max(base[1] - 1 - m, 0))
            ti.atomic_max(st.box[None][2], ti.min(base[0] + 4 + m, st.nx))
            ti.atomic_max(st.box[None][3], ti.min(base[1] + 4 + m, st.ny))


@ti.func
def clear_grid(st: ti.template(), heat: ti.template(), geom: ti.template()):
    for I in ti.grouped(ti.ndrange(*active(st))):
        st.gm[I] = 0.0
        st.gmv[I] = ti.Vector.zero(float, st.dim)
        st.gf[I] = ti.Vector.zero(float, st.dim)
        if ti.static(st.thermal):
            if heat:
                st.gcap[I] = 0.0
                st.gcT[I] = 0.0
                st.gQ[I] = 0.0
        if ti.static(st.surface):
            if geom:
                st.phi_raw[I] = st.phi_cap


@ti.func
def p2g(st: ti.template(), heat: ti.template(), geom: ti.template()):
    for p in range(st.n_points):
        base, w, dw = _stencil(st, p)
        if ti.static(st.mech):
            p2g_mechanics(st, p, base, w, dw)
        if ti.static(st.thermal):
            if heat:
                p2g_heat_capacity(st, p, base, w, dw)
        if ti.static(st.surface):
            if geom:
                scatter_level_set(st, p, base)


@ti.func
def grid_prepare(st: ti.template(), heat: ti.template()):
    for I in ti.grouped(ti.ndrange(*active(st))):
        if ti.static(st.mech):
            grid_velocity(st, I, 0.0)  # v^n only; forces are not complete yet
        if ti.static(st.thermal):
            if heat:
                grid_temperature(st, I)


@ti.func
def p2g_heat(st: ti.template(), t, dt_heat):
    for p in range(st.n_points):
        base, w, dw = _stencil(st, p)
        p2g_heat_flux(st, p, base, w, dw, t, dt_heat)


@ti.func
def grid_update(st: ti.template(), dt, heat: ti.template(), dt_heat):
    for I in ti.grouped(ti.ndrange(*active(st))):
        if ti.static(st.mech):
            grid_velocity(st, I, dt)
        if ti.static(st.thermal):
            if heat:
                grid_heat(st, I, dt_heat)


@ti.func
def constitutive(st: ti.template(), p, L, dt):
    """Strain increment (eqs. 16-17, 34) and the Perzyna update (eqs. 38-45)."""
    eps = st.eps[p] + 0.5 * (L + L.transpose()) * dt
    st.eps[p] = eps
    sig, epl, a = perzyna_update(
        st.matp,
        st.mat[p],
        embed3(eps),
        st.eps_pl[p],
        st.alpha[p],
        st.e_iso[p],
        st.xi[p],
        st.T[p],
        dt,
        st.plastic,
        st.paper_stress,
    )
    st.sigma[p] = sig
    st.eps_pl[p] = epl
    st.alpha[p] = a


@ti.func
def g2p_point(
    st: ti.template(), p, base, w, dw, dt, kinematics: ti.template(), heat: ti.template()
):
    """Heat, thermal strains and velocity of point p; with ``kinematics`` (USL) also its motion
    and stress."""
    if ti.static(st.thermal):
        if heat:
            dT, dxi = g2p_heat(st, p, base, w, dw)
            if ti.static(st.th_strain and st.mech):
                # eqs. 36-37: alpha at the step's mean solid fraction. The increment of one heat
                # step is spread over the heat_every mechanical steps that follow: added at once
                # it is an impulse that rings the elastic melt (the scan case's kinetic energy
                # tripled with heat every 19 steps)
                m = st.mat[p]
                alpha = lerp_phase(st.matp, m, st.xi[p] - 0.5 * dxi, "alpha_c", "alpha_m")
                st.de_iso[p] = (alpha * dT + st.matp[m, P["beta"]] * dxi) / st.heat_every
        if ti.static(st.th_strain and st.mech):
            st.e_iso[p] += st.de_iso[p]
    if ti.static(st.mech):
        g2p_velocity(st, p, base, w, dw)
        if ti.static(kinematics):
            constitutive(st, p, g2p_kinematics(st, p, base, w, dw, dt), dt)


@ti.func
def g2p(st: ti.template(), dt, heat: ti.template()):
    for p in range(st.n_points):
        base, w, dw = _stencil(st, p)
        g2p_point(st, p, base, w, dw, dt, not st.musl, heat)
    if ti.static(st.musl and st.mech):
        for I in ti.grouped(ti.ndrange(*active(st))):
            st.gmv[I] = ti.Vector.zero(float, st.dim)
        for p in range(st.n_points):
            base, w, dw = _stencil(st, p)
            p2g_momentum(st, p, base, w, dw)
        for I in ti.grouped(ti.ndrange(*active(st))):
            grid_remap_velocity(st, I)
        for p in range(st.n_points):
            base, w, dw = _stencil(st, p)
            constitutive(st, p, g2p_kinematics(st, p, base, w, dw, dt), dt)


@ti.func
def substep(st: ti.template(), heat: ti.template(), geom: ti.template()):
    """One mechanical step. ``heat``: conduction and laser this step, over heat_every * dt (the
    thermal clock); ``geom``: level set and curvature this step (reused for curvature_every
    steps; the CSF force itself is rebuilt from the current mass every step). Both are Python
    bools in the GPU layout (the stages compile in or out) and runtime flags in the CPU one."""
    dt = st.dt[None]
    t = st.t[None]
    dt_heat = dt * st.heat_every
    update_box(st)
    clear_grid(st, heat, geom)
    p2g(st, heat, geom)
    grid_prepare(st, heat)
    if ti.static(st.surface):
        if ti.static(isinstance(geom, bool)):
            if ti.static(geom):
                surface_geometry(st)
            else:
                mass_gradient(st)
        else:
            if geom:
                surface_geometry(st)
            else:
                mass_gradient(st)
        csf_force(st)
    if ti.static(st.thermal):
        if ti.static(isinstance(heat, bool)):
            if ti.static(heat):
                p2g_heat(st, t, dt_heat)
        else:
            if heat:
                p2g_heat(st, t, dt_heat)
    grid_update(st, dt, heat, dt_heat)
    g2p(st, dt, heat)
    st.t[None] = t + dt
    st.step[None] += 1


@ti.kernel
def advance_serial(st: ti.template(), n: ti.i32):
    """CPU layout: n steps in one call."""
    ti.loop_config(serialize=True)
    for _ in range(n):
        k = st.step[None]
        substep(st, k % st.heat_every == 0, k % st.geom_every == 0)


@ti.kernel
def advance_one(st: ti.template(), heat: ti.template(), geom: ti.template()):
    """GPU layout: one step per call, each stage a parallel loop."""
    substep(st, heat, geom)


@ti.kernel
def level_set_only(st: ti.template()):
    """The level set of the current points, for monitors."""
    update_box(st)
    for I in ti.grouped(ti.ndrange(st.nx, st.ny)):
        st.phi_raw[I] = st.phi_cap
    for p in range(st.n_points):
        base, w, dw = _stencil(st, p)
        scatter_level_set(st, p, base)
    level_set(st)


def advance(st: State, n: int) -> None:
    """n steps in the state's layout: serial (one call) or parallel (one call per step). The
    layout is fixed when the state is made: it decides which loops are unrolled."""
    if st.parallel:
        k = int(st.step[None])
        for i in range(k, k + n):
            advance_one(st, i % st.heat_every == 0, i % st.geom_every == 0)
    else:
        advance_serial(st, n)


@ti.kernel
def surface_only(st: ti.template()):
    """Grid mass, level set, curvature and CSF force of the current points, without a step
    (diagnostics and verification)."""
    update_box(st)
    clear_grid(st, True, True)
    p2g(st, True, True)
    surface_geometry(st)
    csf_force(st)


# ---- the same step laid out as one kernel call per stage: the speed benchmark's comparison
@ti.kernel
def _k_clear(st: ti.template(), heat: ti.template(), geom: ti.template()):
    clear_grid(st, heat, geom)


@ti.kernel
def _k_p2g(st: ti.template(), heat: ti.template(), geom: ti.template()):
    p2g(st, heat, geom)


@ti.kernel
def _k_grid_prepare(st: ti.template(), heat: ti.template()):
    grid_prepare(st, heat)


@ti.kernel
def _k_level_set(st: ti.template()):
    level_set(st)


@ti.kernel
def _k_blur(st: ti.template()):
    blur_level_set(st)


@ti.kernel
def _k_curvature(st: ti.template()):
    curvature(st)


@ti.kernel
def _k_mass_gradient(st: ti.template()):
    mass_gradient(st)


@ti.kernel
def _k_extend(st: ti.template()):
    extend_and_smooth(st)


@ti.kernel
def _k_csf(st: ti.template()):
    csf_force(st)


@ti.kernel
def _k_p2g_heat(st: ti.template()):
    dt = st.dt[None]
    p2g_heat(st, st.t[None], dt * st.heat_every)


@ti.kernel
def _k_grid_update(st: ti.template(), heat: ti.template()):
    dt = st.dt[None]
    grid_update(st, dt, heat, dt * st.heat_every)


@ti.kernel
def _k_g2p(st: ti.template(), heat: ti.template()):
    g2p(st, st.dt[None], heat)
    st.t[None] += st.dt[None]
    st.step[None] += 1


def advance_staged(st: State, n: int) -> None:
    """n steps, every stage its own kernel call (13 per step with surface tension and heat)."""
    if not st.parallel:
        raise ValueError("advance_staged needs a state made with the parallel layout")
    k = int(st.step[None])
    for i in range(k, k + n):
        heat, geom = i % st.heat_every == 0, i % st.geom_every == 0
        _k_clear(st, heat, geom)
        _k_p2g(st, heat, geom)
        _k_grid_prepare(st, heat)
        if st.surface:
            if geom:
                _k_level_set(st)
                _k_blur(st)
                _k_curvature(st)
            _k_mass_gradient(st)
            if geom:
                _k_extend(st)
            _k_csf(st)
        if st.thermal and heat:
            _k_p2g_heat(st)
        _k_grid_update(st, heat)
        _k_g2p(st, heat)
