"""Heat conduction on the grid, enthalpy and solid fraction (eqs. 25-33).

Per heat step: heat capacity c_i = sum M_p c_p N_ip (eq. 28, with c_p the apparent capacity
dH/dT, so the grid update already sees the latent heat) and the capacity-weighted node
temperature; the point temperature gradient grad T_p = sum T_i grad N_ip; the heat rate
Q_i = - sum V_p k_p grad T_p . grad N_ip + sum V_p s_laser N_ip (eq. 29 with the weak-form minus
sign of docs/model.md, eq. 30's laser term with eq. 31 read as W/m^3); dT_i = dt Q_i / c_i; each
point gains enthalpy dH_p = c_p sum N_ip dT_i. Since sum_p M_p c_p N_ip / c_i = 1 this moves exactly
the grid's heat to the points: the energy balance holds to round-off.

Sub-grid filter (``thermal.subgrid_filter``, chi per heat step): the grid sees a point's
temperature only through the capacity-weighted node average, so increments alone (FLIP) never
damp a point's
deviation d_p = T_p - sum N T_i from the grid field; stirred by the flow (spurious capillary
currents), such sub-grid noise grows over long runs until points lie below the coldest wall.
Physically it would vanish within a heat step (its diffusion time at the point spacing is far
shorter). Each heat step the noise part of d -- d_p minus the grid interpolation of the
capacity-weighted node means of d -- is removed at the fraction chi = 1 - exp(-rate dt_heat /
t_thermal) (a relaxation in time, independent of the heat clock), as enthalpy: exactly
conservative, and of order h^4 on a smooth field (d is then smooth), so the scheme stays second
order.

Thermal hysteresis (``cfg.hysteresis``, some material sets ``crystallization_range_C``): the
solid fraction is history (physics/materials.py). The enthalpy stays the carried state and
eq. 30's latent term stays inside it: T comes from (H, previous xi_s), xi_s is then updated at
T, and c_p is the apparent capacity of the branch the point is on (melting, crystallising, or
none while the fraction holds). The energy balance is untouched: it never depended on c_p.
Without it (``ti.static``) the code is the one above.

Crystallisation kinetics (``cfg.kinetics``, some material sets ``crystallization_kinetics``;
hysteresis is then on): after T and xi_s of the heat step, a kinetics point's melt crystallises
by Nakamura's law over the heat step at that T, at the same enthalpy, so the latent heat it
releases raises T (physics/materials.py ``crystallize_at_enthalpy``). The carried enthalpy is
untouched: the energy balance holds as before.

Held temperature (``cfg.imposed``): every point is set to a table's T(t) instead of taking the
grid's increment (physics/held_temperature.py).

Fixed-temperature walls: their nodes enter the gradient at the wall temperature and take no
increment; the heat that reaches them leaves the body and is counted in ``heat_out``. Points next
to them are updated as ``g2p_heat`` says, so that none is pushed past the wall temperature
(docs/model.md: resetting the nodes by increments drove points beside the plate to 110 C).

Top-surface loss (``cfg.top_loss``, ``thermal.top_surface = "chamber"``): the layer's top surface
loses q(T) = h_c (T - T_ch) + eps sigma (T^4 - T_ch^4) per area to the chamber. Each node column
is exposed over its share of the domain's width (its projected top, the area a rough surface
presents to the chamber; in 3D each (i, k) column over its share of the bed plane); T is the
capacity-weighted temperature of the column's top three nodes (the topmost holding material and
the two below it, fixed ones excluded), and the column's loss is taken from them in proportion
to their capacities, so the skin cools as one. Over a step the skin is one lumped capacity C
losing H (T - T_ch), with H = A q(T) / (T - T_ch) frozen at the step's start, integrated
exactly: C (T - T_ch) (1 - exp(-H dt / C)). For H dt / C << 1 that is the flux times the area
and the step, to O(H dt / C); for a long implicit step on a skin that holds little material (a
sphere's edge grazing a column by a side wall) it never takes the skin below the chamber's
temperature, which the flux times the step did. It enters the nodes' heat rate as the laser's
heat does, and is counted in ``heat_out``: the energy balance still holds to round-off.

Arguments: ``cfg`` the step's configuration, ``pt`` points, ``nd`` nodes, ``mat`` materials,
``sc`` the run's scalars (heat out through the walls' nodes), ``lasers`` the beams. The point
functions return what a point adds to the run's totals (laser energy, heat out); the solver
accumulates them as its layout needs.
"""

import math

from taichi_sls.backend import ti

from .grid import scatter_add
from .laser import laser_source
from .materials import (
    KINETICS_MOLTEN,
    apparent_heat_capacity,
    crystallize_at_enthalpy,
    enthalpy,
    enthalpy_history,
    heat_capacity_history,
    lerp_phase,
    solid_fraction,
    solid_fraction_history,
    temperature_from_enthalpy,
    temperature_from_enthalpy_history,
)
from .shape import STENCIL_SHAPE, node_weight
from .small_matrix import ZERO_VECTOR

STEFAN_BOLTZMANN = 5.670374419e-8  # W/(m^2 K^4)
SKIN_NODES = 3  # the top nodes of a column that lose the top surface's heat


@ti.func
def point_heat_capacity(cfg: ti.template(), mp: ti.template(), T, xi):
    """c_p of eq. 28: the apparent capacity dH/dT, with hysteresis that of the branch the point
    is on (physics/materials.py). Any c_p > 0 moves the grid's heat exactly; it only sets how
    the heat step spreads it."""
    c = 0.0
    if ti.static(cfg.hysteresis):
        c = heat_capacity_history(mp, T, xi)
    else:
        c = apparent_heat_capacity(mp, T)
    return c


@ti.func
def counts_molten(cfg: ti.template(), mp: ti.template(), xi):
    """Whether a point counts as molten this heat step (``time_molten``): xi_s = 0 (above T_m,
    or a supercooled melt); with kinetics also a kinetics material's melt under
    KINETICS_MOLTEN crystallised, whose xi_s leaves 0 as soon as it cools below T_m0."""
    molten = xi == 0.0
    if ti.static(cfg.kinetics):
        molten = molten or (mp.kinetics != 0 and xi < KINETICS_MOLTEN)
    return molten


@ti.func
def point_conductivity(mp: ti.template(), xi):
    """k of eq. 29 at solid fraction xi."""
    return lerp_phase(xi, mp.conductivity_solid_W_mK, mp.conductivity_liquid_W_mK)


@ti.func
def p2g_heat_capacity(
    cfg: ti.template(), pt: ti.template(), nd: ti.template(), mat: ti.template(), p, base, w, dw
):
    mp = pt.mass[p]
    c = point_heat_capacity(cfg, mat[pt.material[p]], pt.T[p], pt.solid_fraction[p])
    for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[cfg.dim])):
        N, gN = node_weight(w, dw, o)
        I = base + o
        scatter_add(cfg, nd.heat_capacity, I, N * mp * c)
        scatter_add(cfg, nd.capacity_T, I, N * mp * c * pt.T[p])


@ti.func
def fixed_temperature(cfg: ti.template(), I):
    """(is fixed, wall temperature) of node I from the walls' thermal conditions."""
    fixed = 0
    Tw = 0.0
    hi = ti.Vector(cfg.wall_index)
    for d in ti.static(range(cfg.dim)):
        if ti.static(cfg.wall_fixed[2 * d]):
            if I[d] <= cfg.off:
                fixed = 1
                Tw = cfg.wall_T[2 * d]
        if ti.static(cfg.wall_fixed[2 * d + 1]):
            if I[d] >= hi[d]:
                fixed = 1
                Tw = cfg.wall_T[2 * d + 1]
    return fixed, Tw


@ti.func
def grid_temperature(cfg: ti.template(), nd: ti.template(), I):
    T = 0.0
    if nd.heat_capacity[I] > 0.0:
        T = nd.capacity_T[I] / nd.heat_capacity[I]
        fixed, Tw = fixed_temperature(cfg, I)
        if fixed:
            T = Tw
    nd.T[I] = T


@ti.func
def p2g_heat_flux(
    cfg: ti.template(),
    pt: ti.template(),
    nd: ti.template(),
    mat: ti.template(),
    lasers: ti.template(),
    p,
    base,
    w,
    dw,
    t,
    dt,
    column_top,
):
    """Conduction (eq. 29, weak-form sign) and laser (eqs. 30-31) into the nodes' heat rate;
    with the sub-grid filter on, the point's deviation from the grid temperature too. Returns
    the laser energy the point took (J/m). ``column_top``: the local surface above the point
    (physics/beam_surface.py), read by beams that measure their depth from it."""
    gT = ti.Vector(ZERO_VECTOR[cfg.dim])
    T_grid = 0.0
    w_fixed = 0.0
    for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[cfg.dim])):
        N, gN = node_weight(w, dw, o)
        gT += nd.T[base + o] * gN
        if ti.static(cfg.subgrid_filter > 0.0):
            T_grid += N * nd.T[base + o]
            if ti.static(cfg.any_fixed):
                fixed, Tw = fixed_temperature(cfg, base + o)
                if fixed:
                    w_fixed += N
    mp = mat[pt.material[p]]
    if ti.static(cfg.subgrid_filter > 0.0):
        if w_fixed == 0.0:  # points beside a fixed wall take the grid temperature anyway
            mc = pt.mass[p] * point_heat_capacity(cfg, mp, pt.T[p], pt.solid_fraction[p])
            d = pt.T[p] - T_grid
            for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[cfg.dim])):
                N, gN = node_weight(w, dw, o)
                scatter_add(cfg, nd.deviation, base + o, N * mc * d)
                scatter_add(cfg, nd.deviation_capacity, base + o, N * mc)
    k = point_conductivity(mp, pt.solid_fraction[p])
    Vp = pt.volume0[p] * pt.J[p]
    s = 0.0
    energy = 0.0  # the laser energy the point takes this heat step
    if ti.static(cfg.laser):
        s = laser_source(cfg, lasers, pt.x[p], t, dt, column_top)
        energy = Vp * s * dt
    for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[cfg.dim])):
        N, gN = node_weight(w, dw, o)
        scatter_add(cfg, nd.heat_rate, base + o, -Vp * k * gT.dot(gN) + Vp * s * N)
    return energy


@ti.func
def surface_flux(cfg: ti.template(), T):
    """q (W/m^2) that the top surface at T (K) loses to the chamber."""
    Tc = cfg.chamber_T
    return cfg.convection * (T - Tc) + cfg.emissivity * STEFAN_BOLTZMANN * (T**4 - Tc**4)


@ti.func
def _open_extent(cfg: ti.template(), index, cells):
    """The length of node ``index``'s cell share that lies inside [0, cells h] along one axis."""
    x = (index - cfg.off) * cfg.h
    return ti.max(ti.min(x + 0.5 * cfg.h, cells * cfg.h) - ti.max(x - 0.5 * cfg.h, 0.0), 0.0)


@ti.func
def column_node(cfg: ti.template(), column, j):
    """The node of ``column`` (i in 2D, (i, k) in 3D) at row j (y up)."""
    if ti.static(cfg.dim == 3):
        return ti.Vector([column[0], j, column[1]])
    else:
        return ti.Vector([column[0], j])


@ti.func
def column_area(cfg: ti.template(), column):
    """The projected top a node column presents to the chamber: its share of the domain's
    width (per depth) in 2D, of the bed plane's area in 3D."""
    area = _open_extent(cfg, column[0], cfg.ncx)
    if ti.static(cfg.dim == 3):
        area *= _open_extent(cfg, column[1], cfg.ncz)
    return area


# (1 - exp(-x)) / x = sum_n (-x)^n / (n + 1)!, to n = 8: below x = 0.05 its truncation is
# under 1e-18 and 1 - exp(-x) would lose eps / x to cancellation
_FRACTION_SERIES = tuple((-1.0) ** n / math.factorial(n + 1) for n in range(9))
_FRACTION_SERIES_BELOW = 0.05


@ti.func
def _relaxed_fraction(x):
    """(1 - exp(-x)) / x for x >= 0: the share of the explicit loss x (in units of the skin's
    heat above the chamber) that a lumped skin loses exactly."""
    result = 0.0
    if x < _FRACTION_SERIES_BELOW:
        for n in ti.static(range(len(_FRACTION_SERIES) - 1, -1, -1)):
            result = _FRACTION_SERIES[n] + x * result
    else:
        result = (1.0 - ti.exp(-x)) / x
    return result


@ti.func
def top_loss_column(cfg: ti.template(), nd: ti.template(), column, j_lo, j_hi, dt):
    """Take a node column's top-surface loss over dt from its skin nodes' heat rates (module
    docstring); returns the heat lost (J per depth in 2D, J in 3D). ``column`` is i in 2D,
    (i, k) in 3D; rows j_lo <= j < j_hi hold the material."""
    area = column_area(cfg, column)
    top = j_lo - 1
    for jj in range(j_hi - j_lo):  # from the top down to the first node holding material
        j = j_hi - 1 - jj
        if top < j_lo and nd.heat_capacity[column_node(cfg, column, j)] > 0.0:
            top = j
    lost = 0.0
    if top >= j_lo and area > 0.0:
        C = 0.0
        CT = 0.0
        for k in range(SKIN_NODES):
            j = top - k
            if j >= j_lo:
                node = column_node(cfg, column, j)
                fixed, Tw = fixed_temperature(cfg, node)
                if not fixed:
                    C += nd.heat_capacity[node]
                    CT += nd.heat_capacity[node] * nd.T[node]
        if C > 0.0:
            T = CT / C
            rate = area * surface_flux(cfg, T)  # W (per depth in 2D), at the step's start
            if rate != 0.0:  # the lumped skin's exact loss over dt (module docstring)
                rate *= _relaxed_fraction(rate * dt / (C * (T - cfg.chamber_T)))
            for k in range(SKIN_NODES):
                j = top - k
                if j >= j_lo:
                    node = column_node(cfg, column, j)
                    fixed, Tw = fixed_temperature(cfg, node)
                    if not fixed:
                        nd.heat_rate[node] -= rate * nd.heat_capacity[node] / C
            lost = rate * dt
    return lost


@ti.func
def wall_heat(cfg: ti.template(), nd: ti.template(), I, dt):
    """The heat (J per depth) that fixed node I passes to the walls over dt (0 if not fixed)."""
    q = 0.0
    if nd.heat_capacity[I] > 0.0:
        fixed, Tw = fixed_temperature(cfg, I)
        if fixed:
            q = dt * nd.heat_rate[I]
    return q


@ti.func
def grid_heat(cfg: ti.template(), nd: ti.template(), sc: ti.template(), I, dt):
    """Node I's temperature change over dt; a fixed node's heat goes to the walls' total here,
    but in the blocks layout by :func:`wall_heat` in node order (a float sum that threads take
    in any order would not repeat bit for bit)."""
    dT = 0.0
    if nd.heat_capacity[I] > 0.0:
        fixed, Tw = fixed_temperature(cfg, I)
        if fixed:
            if ti.static(not cfg.race_free):
                sc.heat_out[None] += dt * nd.heat_rate[I]
        else:
            dT = dt * nd.heat_rate[I] / nd.heat_capacity[I]
    nd.dT[I] = dT


@ti.func
def g2p_heat(
    cfg: ti.template(),
    pt: ti.template(),
    nd: ti.template(),
    mat: ti.template(),
    p,
    base,
    w,
    dw,
    chi,
    dt_heat,
):
    """Enthalpy increment from the grid; returns (dT, d xi_s) for the thermal strains and the
    heat the point exchanged with fixed walls (J/m, counted in heat_out). ``chi``: the sub-grid
    filter's fraction this heat step; ``dt_heat`` the heat step (read with kinetics only).

    Points away from fixed-temperature walls take the FLIP increment c_p sum N dT_i (exact energy
    transfer). A point within the support of a fixed node takes the interpolated grid temperature
    sum N T_i^{n+1} instead (T_i = the wall temperature there): a convex combination of node
    temperatures, so it can never pass the wall temperature (docs/model.md), and second-order
    accurate next to the wall where increments alone would lag. What that changes in its enthalpy
    beyond the FLIP increment is heat exchanged with the wall and is booked in heat_out.
    """
    dTg = 0.0
    T_pic = 0.0
    w_fixed = 0.0
    T_grid = 0.0  # the grid temperature at the point, before the increment
    d_smooth = 0.0  # the smooth part of the points' deviation from it
    for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[cfg.dim])):
        N, gN = node_weight(w, dw, o)
        I = base + o
        dTg += N * nd.dT[I]
        if ti.static(cfg.any_fixed):
            T_pic += N * (nd.T[I] + nd.dT[I])
            fixed, Tw = fixed_temperature(cfg, I)
            if fixed:
                w_fixed += N
        if ti.static(cfg.subgrid_filter > 0.0):
            T_grid += N * nd.T[I]
            if nd.deviation_capacity[I] > 0.0:
                d_smooth += N * nd.deviation[I] / nd.deviation_capacity[I]
    mp = mat[pt.material[p]]
    T0 = pt.T[p]
    xi0 = pt.solid_fraction[p]
    c0 = point_heat_capacity(cfg, mp, T0, xi0)
    dH = c0 * dTg
    heat_out = 0.0
    if ti.static(cfg.subgrid_filter > 0.0):
        if w_fixed == 0.0:
            # the sub-grid part of the deviation relaxes (module docstring): exactly
            # conservative, since sum_p N m c (d_p - d_i) = 0 at every node
            dH -= chi * c0 * ((T0 - T_grid) - d_smooth)
    if ti.static(cfg.any_fixed):
        if w_fixed > 0.0:
            H_pic = 0.0
            if ti.static(cfg.hysteresis):
                H_pic = enthalpy_history(mp, T_pic, solid_fraction_history(mp, T_pic, xi0))
            else:
                H_pic = enthalpy(mp, T_pic)
            heat_out = -(pt.mass[p] * (H_pic - pt.enthalpy[p] - dH))
            dH = H_pic - pt.enthalpy[p]
    pt.enthalpy[p] += dH
    T1 = 0.0
    xi1 = 0.0
    if ti.static(cfg.hysteresis):  # xi_s is history: T from (H, xi0), then xi0 updated at T
        T1 = temperature_from_enthalpy_history(mp, pt.enthalpy[p], xi0)
        xi1 = solid_fraction_history(mp, T1, xi0)
        if ti.static(cfg.kinetics):  # then the melt crystallises over the heat step
            if mp.kinetics:
                T1, xi1 = crystallize_at_enthalpy(mp, pt.enthalpy[p], T1, xi1, dt_heat)
    else:
        T1 = temperature_from_enthalpy(mp, pt.enthalpy[p])
        xi1 = solid_fraction(mp, T1)
    pt.T[p] = T1
    pt.solid_fraction[p] = xi1
    return T1 - T0, xi1 - xi0, heat_out
