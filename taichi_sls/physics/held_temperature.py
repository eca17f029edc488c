"""A held temperature history (``thermal.imposed_temperature_csv``, ``cfg.imposed``): every point
is set to the table's T(t) at the end of each heat step instead of taking the grid's increment
(physics/thermal.py). The pair is taken as isothermal (Biot number << 1), as a measured
temperature history of a whole particle reads it (docs/validation.md). Its solid fraction
follows as at any temperature: melting by the melting branch, and with kinetics the melt
crystallises by Nakamura's law at the held temperature (a thermostat takes the latent heat, so T
does not rise). The enthalpy this sets is booked in ``heat_out`` (negative: heat put in), so the
energy balance still holds.

Arguments: ``cfg`` the step's configuration, ``pt`` points, ``mat`` materials, ``table`` the
rows (``t`` in s, ``T`` in K; solver/fields.py ``State.imposed``), ``rows`` their number.
"""

from taichi_sls.backend import ti

from .materials import (
    enthalpy,
    enthalpy_history,
    nakamura_step,
    solid_fraction,
    solid_fraction_history,
)


@ti.func
def imposed_temperature(table: ti.template(), rows: ti.template(), t):
    """The held temperature (K) at time t (s) of the table's ``rows`` rows (``t`` in s, ``T``
    in K; times from 0, increasing): linear between rows, the last row's after them."""
    T = table.T[rows - 1]
    if t <= table.t[0]:
        T = table.T[0]
    for k in range(1, rows):
        if table.t[k - 1] < t and t <= table.t[k]:
            s = (t - table.t[k - 1]) / (table.t[k] - table.t[k - 1])
            T = table.T[k - 1] + s * (table.T[k] - table.T[k - 1])
    return T


@ti.func
def hold_temperature(cfg: ti.template(), pt: ti.template(), mat: ti.template(), p, T1, dt_heat):
    """Point p held at T1 (K) over a heat step of dt_heat (module docstring); returns (dT,
    d xi_s) for the thermal strains and the heat the hold took out of the point (J/m; negative
    when it put heat in), counted in heat_out. The solid fraction follows as at any
    temperature: the melting branch (with hysteresis its history), then with kinetics the melt
    crystallises by Nakamura's law at T1, never past the melting branch's fraction at T1."""
    mp = mat[pt.material[p]]
    T0 = pt.T[p]
    xi0 = pt.solid_fraction[p]
    H0 = pt.enthalpy[p]
    xi1 = 0.0
    H1 = 0.0
    if ti.static(cfg.hysteresis):
        xi1 = solid_fraction_history(mp, T1, xi0)
        if ti.static(cfg.kinetics):
            if mp.kinetics:
                grown = ti.min(nakamura_step(mp, T1, xi1, dt_heat), solid_fraction(mp, T1))
                xi1 = ti.max(xi1, grown)
        H1 = enthalpy_history(mp, T1, xi1)
    else:
        xi1 = solid_fraction(mp, T1)
        H1 = enthalpy(mp, T1)
    pt.enthalpy[p] = H1
    pt.T[p] = T1
    pt.solid_fraction[p] = xi1
    return T1 - T0, xi1 - xi0, -pt.mass[p] * (H1 - H0)


@ti.func
def hold_at_table(
    cfg: ti.template(), pt: ti.template(), mat: ti.template(), table: ti.template(), p, t, dt_heat
):
    """Point p held at the table's temperature at time t (s), the heat step's end: what
    :func:`hold_temperature` returns."""
    return hold_temperature(cfg, pt, mat, p, imposed_temperature(table, cfg.imposed, t), dt_heat)
