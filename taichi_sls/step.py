"""One explicit MPM step (update-stress-last), its stage order, and the two kernel layouts.

    clear grid
    P2G        mass, momentum, forces (eqs. 10-12); heat capacity (eq. 28); level set (eq. 21)
    grid       v^n; node temperature (fixed-temperature walls)
    surface    contour, redistance, curvature, grad m, CSF force (eqs. 19-24)
    P2G heat   grad T_p, conduction and laser heat rates (eqs. 29-31)
    grid       v^{n+1} with walls (eq. 13); dT_i
    G2P        velocity, position, L, F, J (eqs. 14-18); enthalpy, T, xi_s (eqs. 32-33);
               strain split and Perzyna return map (eqs. 34-45)

CPU layout: many steps inside one kernel call with the step loop serialized (a kernel launch
costs tens of microseconds; the paper's scene has a few thousand points). GPU layout: one kernel
call per step, every stage a parallel loop.
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
from .state import State
from .surface import level_set, scatter_level_set, surface_forces
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
def clear_grid(st: ti.template()):
    for I in ti.grouped(ti.ndrange(st.nx, st.ny)):
        st.gm[I] = 0.0
        st.gmv[I] = ti.Vector.zero(float, st.dim)
        st.gf[I] = ti.Vector.zero(float, st.dim)
        if ti.static(st.thermal):
            st.gcap[I] = 0.0
            st.gcT[I] = 0.0
            st.gQ[I] = 0.0
        if ti.static(st.surface):
            st.phi_raw[I] = st.phi_cap


@ti.func
def p2g(st: ti.template()):
    for p in range(st.n_points):
        base, w, dw = _stencil(st, p)
        if ti.static(st.mech):
            p2g_mechanics(st, p, base, w, dw)
        if ti.static(st.thermal):
            p2g_heat_capacity(st, p, base, w, dw)
        if ti.static(st.surface):
            scatter_level_set(st, p, base)


@ti.func
def grid_prepare(st: ti.template(), dt):
    for I in ti.grouped(ti.ndrange(st.nx, st.ny)):
        if ti.static(st.mech):
            grid_velocity(st, I, 0.0)  # v^n only; forces are not complete yet
        if ti.static(st.thermal):
            grid_temperature(st, I)


@ti.func
def p2g_heat(st: ti.template(), t, dt):
    for p in range(st.n_points):
        base, w, dw = _stencil(st, p)
        p2g_heat_flux(st, p, base, w, dw, t, dt)


@ti.func
def grid_update(st: ti.template(), dt):
    for I in ti.grouped(ti.ndrange(st.nx, st.ny)):
        if ti.static(st.mech):
            grid_velocity(st, I, dt)
        if ti.static(st.thermal):
            grid_heat(st, I, dt)


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
def g2p_point(st: ti.template(), p, base, w, dw, dt, kinematics: ti.template()):
    """Heat, thermal strains and velocity of point p; with ``kinematics`` (USL) also its motion
    and stress."""
    if ti.static(st.thermal):
        dT, dxi = g2p_heat(st, p, base, w, dw)
        if ti.static(st.th_strain and st.mech):
            # eqs. 36-37: alpha at the step's mean solid fraction
            m = st.mat[p]
            alpha = lerp_phase(st.matp, m, st.xi[p] - 0.5 * dxi, "alpha_c", "alpha_m")
            st.e_iso[p] += alpha * dT + st.matp[m, P["beta"]] * dxi
    if ti.static(st.mech):
        g2p_velocity(st, p, base, w, dw)
        if ti.static(kinematics):
            constitutive(st, p, g2p_kinematics(st, p, base, w, dw, dt), dt)


@ti.func
def g2p(st: ti.template(), dt):
    for p in range(st.n_points):
        base, w, dw = _stencil(st, p)
        g2p_point(st, p, base, w, dw, dt, not st.musl)
    if ti.static(st.musl and st.mech):
        for I in ti.grouped(ti.ndrange(st.nx, st.ny)):
            st.gmv[I] = ti.Vector.zero(float, st.dim)
        for p in range(st.n_points):
            base, w, dw = _stencil(st, p)
            p2g_momentum(st, p, base, w, dw)
        for I in ti.grouped(ti.ndrange(st.nx, st.ny)):
            grid_remap_velocity(st, I)
        for p in range(st.n_points):
            base, w, dw = _stencil(st, p)
            constitutive(st, p, g2p_kinematics(st, p, base, w, dw, dt), dt)


@ti.func
def substep(st: ti.template()):
    dt = st.dt[None]
    t = st.t[None]
    clear_grid(st)
    p2g(st)
    grid_prepare(st, dt)
    if ti.static(st.surface):
        surface_forces(st)
    if ti.static(st.thermal):
        p2g_heat(st, t, dt)
    grid_update(st, dt)
    g2p(st, dt)
    st.t[None] = t + dt


@ti.kernel
def advance_serial(st: ti.template(), n: ti.i32):
    """CPU layout: n steps in one call."""
    ti.loop_config(serialize=True)
    for _ in range(n):
        substep(st)


@ti.kernel
def advance_one(st: ti.template()):
    """GPU layout: one step per call, each stage a parallel loop."""
    substep(st)


@ti.kernel
def level_set_only(st: ti.template()):
    """The level set for monitors when surface tension is off."""
    for I in ti.grouped(ti.ndrange(st.nx, st.ny)):
        st.phi_raw[I] = st.phi_cap
    for p in range(st.n_points):
        base, w, dw = _stencil(st, p)
        scatter_level_set(st, p, base)
    level_set(st)


def advance(st: State, n: int, gpu: bool) -> None:
    if gpu:
        for _ in range(n):
            advance_one(st)
    else:
        advance_serial(st, n)


@ti.kernel
def surface_only(st: ti.template()):
    """Grid mass, level set, curvature and CSF force of the current points, without a step
    (diagnostics and verification)."""
    clear_grid(st)
    p2g(st)
    surface_forces(st)
