"""Heat conduction on the grid, the Gaussian laser, enthalpy and solid fraction (eqs. 25-33).

Per step: heat capacity c_i = sum M_p c_p N_ip (eq. 28, with c_p the apparent capacity dH/dT, so
the grid update already sees the latent heat) and the capacity-weighted node temperature; the
point temperature gradient grad T_p = sum T_i grad N_ip; the heat rate
Q_i = - sum V_p k_p grad T_p . grad N_ip + sum V_p s_laser N_ip (eq. 29 with the weak-form minus
sign of MODEL.md, eq. 30's laser term with eq. 31 read as W/m^3); dT_i = dt Q_i / c_i; each point
gains enthalpy dH_p = c_p sum N_ip dT_i. Since sum_p M_p c_p N_ip / c_i = 1 this moves exactly the
grid's heat to the points: the energy balance holds to round-off.

Fixed-temperature walls: their nodes enter the gradient at the wall temperature and take no
increment; the heat that reaches them leaves the body and is counted in ``heat_out``. Points next
to them are updated as ``g2p_heat`` says, so that none is pushed past the wall temperature
(MODEL.md: resetting the nodes by increments drove points beside the plate to 110 C).
"""

import taichi as ti

from .materials import (
    apparent_heat_capacity,
    enthalpy,
    lerp_phase,
    solid_fraction,
    temperature_from_enthalpy,
)
from .shape import STENCIL, node_weight
from .state import LP


@ti.func
def p2g_heat_capacity(st: ti.template(), p, base, w, dw):
    mp = st.mass[p]
    c = apparent_heat_capacity(st.matp, st.mat[p], st.T[p])
    for o in ti.static(ti.grouped(STENCIL)):
        N, gN = node_weight(w, dw, o)
        I = base + o
        st.gcap[I] += N * mp * c
        st.gcT[I] += N * mp * c * st.T[p]


@ti.func
def fixed_temperature(st: ti.template(), I):
    """(is fixed, wall temperature) of node I from the walls' thermal conditions."""
    fixed = 0
    Tw = 0.0
    hi = ti.Vector([st.off + st.ncx, st.off + st.ncy])
    for d in ti.static(range(2)):
        if ti.static(st.wall_fixed[2 * d]):
            if I[d] <= st.off:
                fixed = 1
                Tw = st.wall_T[2 * d]
        if ti.static(st.wall_fixed[2 * d + 1]):
            if I[d] >= hi[d]:
                fixed = 1
                Tw = st.wall_T[2 * d + 1]
    return fixed, Tw


@ti.func
def grid_temperature(st: ti.template(), I):
    T = 0.0
    if st.gcap[I] > 0.0:
        T = st.gcT[I] / st.gcap[I]
        fixed, Tw = fixed_temperature(st, I)
        if fixed:
            T = Tw
    st.gT[I] = T


@ti.func
def laser_source(st: ti.template(), xp, t, dt):
    """Eq. 31 (MODEL.md reading): mean power per unit volume at xp over [t, t + dt], summed over
    the lasers. Each beam's on-time within the step is exact (a heat step may span many
    mechanical steps and a switch-on or -off), its position taken at the middle of that time."""
    s = 0.0
    for k in range(st.n_lasers):
        on = st.lasp[k, LP["on"]]
        x0 = st.lasp[k, LP["x0"]]
        speed = st.lasp[k, LP["speed"]]
        x_end = st.lasp[k, LP["x_end"]]
        t0 = ti.max(t, on)
        t1 = ti.min(t + dt, st.lasp[k, LP["off"]])
        # the beam is off while its centre x0 + speed (t - on) lies beyond x_end
        if speed > 0.0:
            t1 = ti.min(t1, on + (x_end - x0) / speed)
        elif speed < 0.0:
            t0 = ti.max(t0, on + (x_end - x0) / speed)
        elif x0 > x_end:
            t1 = t0
        if t1 > t0:
            xl = x0 + speed * (0.5 * (t0 + t1) - on)
            r0 = st.lasp[k, LP["r0"]]
            eta = st.lasp[k, LP["eta"]]
            depth = ti.max(st.lasp[k, LP["top"]] - xp[1], 0.0)
            dx = xl - xp[0]
            s += (
                st.lasp[k, LP["amp"]]
                * ((t1 - t0) / dt)
                * ti.exp(-2.0 * dx * dx / (r0 * r0))
                * ti.exp(-st.lasp[k, LP["sign"]] * depth / eta)
            )
    return s


@ti.func
def p2g_heat_flux(st: ti.template(), p, base, w, dw, t, dt):
    """Conduction (eq. 29, weak-form sign) and laser (eqs. 30-31) into the nodes' heat rate."""
    gT = ti.Vector.zero(float, st.dim)
    for o in ti.static(ti.grouped(STENCIL)):
        N, gN = node_weight(w, dw, o)
        gT += st.gT[base + o] * gN
    m = st.mat[p]
    k = lerp_phase(st.matp, m, st.xi[p], "k_c", "k_m")
    Vp = st.vol0[p] * st.J[p]
    s = 0.0
    if ti.static(st.laser):
        s = laser_source(st, st.x[p], t, dt)
        st.laser_energy[None] += Vp * s * dt
    for o in ti.static(ti.grouped(STENCIL)):
        N, gN = node_weight(w, dw, o)
        st.gQ[base + o] += -Vp * k * gT.dot(gN) + Vp * s * N


@ti.func
def grid_heat(st: ti.template(), I, dt):
    dT = 0.0
    if st.gcap[I] > 0.0:
        fixed, Tw = fixed_temperature(st, I)
        if fixed:
            st.heat_out[None] += dt * st.gQ[I]
        else:
            dT = dt * st.gQ[I] / st.gcap[I]
    st.gdT[I] = dT


@ti.func
def g2p_heat(st: ti.template(), p, base, w, dw):
    """Enthalpy increment from the grid; returns (dT, d xi_s) for the thermal strains.

    Points away from fixed-temperature walls take the FLIP increment c_p sum N dT_i (exact energy
    transfer). A point within the support of a fixed node takes the interpolated grid temperature
    sum N T_i^{n+1} instead (T_i = the wall temperature there): a convex combination of node
    temperatures, so it can never pass the wall temperature (MODEL.md), and second-order accurate
    next to the wall where increments alone would lag. What that changes in its enthalpy beyond
    the FLIP increment is heat exchanged with the wall and is booked in heat_out.
    """
    dTg = 0.0
    T_pic = 0.0
    w_fixed = 0.0
    for o in ti.static(ti.grouped(STENCIL)):
        N, gN = node_weight(w, dw, o)
        I = base + o
        dTg += N * st.gdT[I]
        if ti.static(st.any_fixed):
            T_pic += N * (st.gT[I] + st.gdT[I])
            fixed, Tw = fixed_temperature(st, I)
            if fixed:
                w_fixed += N
    m = st.mat[p]
    T0 = st.T[p]
    xi0 = st.xi[p]
    dH = apparent_heat_capacity(st.matp, m, T0) * dTg
    if ti.static(st.any_fixed):
        if w_fixed > 0.0:
            H_pic = enthalpy(st.matp, m, T_pic)
            st.heat_out[None] -= st.mass[p] * (H_pic - st.H[p] - dH)
            dH = H_pic - st.H[p]
    st.H[p] += dH
    T1 = temperature_from_enthalpy(st.matp, m, st.H[p])
    xi1 = solid_fraction(st.matp, m, T1)
    st.T[p] = T1
    st.xi[p] = xi1
    ti.atomic_max(st.T_peak[None], T1)
    return T1 - T0, xi1 - xi0
