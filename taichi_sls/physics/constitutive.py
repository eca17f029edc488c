"""Strain split and the Perzyna elasto-viscoplastic return map (paper eqs. 34-45, docs/model.md).

Plane strain: the in-plane total strain is accumulated from the velocity gradient
(eqs. 16-17, eps_zz = 0); plastic, thermal and transformation strains are full 3x3 tensors.
Readings of docs/model.md: s_trial = 2 mu dev(eps_e) (eq. 39 lost its 2 mu on the trace term) and
p = K tr(eps_e), K = lambda + 2 mu / 3, with eps_e = eps - eps_pl - (eps_th + eps_m).
"""

import math

import taichi as ti

from .codes import StressForm, StressReading
from .materials import lerp_phase, viscosity

SQRT23 = math.sqrt(2.0 / 3.0)


@ti.func
def embed3(e2):
    """In-plane 2x2 strain -> 3x3 with eps_zz = 0 (plane strain)."""
    e = ti.Matrix.zero(float, 3, 3)
    for a, b in ti.static(ti.ndrange(2, 2)):
        e[a, b] = e2[a, b]
    return e


@ti.func
def moduli(mp: ti.template(), xi):
    """(E, nu) of material ``mp`` at solid fraction xi: each interpolated in xi (docs/model.md)."""
    E = lerp_phase(xi, mp.youngs_solid_Pa, mp.youngs_liquid_Pa)
    nu = lerp_phase(xi, mp.poisson, mp.poisson_liquid)
    return E, nu


@ti.func
def perzyna_update(
    mp: ti.template(),
    eps3,
    eps_pl,
    alpha,
    e_iso,
    xi,
    T,
    dt,
    plastic: ti.template(),
    reading: ti.template(),
):
    """One backward-Euler Perzyna step of material ``mp``. Returns (sigma, eps_pl, alpha).
    ``reading``: docs/model.md's stress or the printed eq. 39 and pressure (StressReading).

    Trial: s_tr = 2 mu dev(eps_e), f = |s_tr| - sqrt(2/3)(sigma_Y + H alpha) (eq. 40); when f > 0,
    dgamma = (f / 2mu) / (tau/dt + 1 + H/(3 mu)), tau = eta / (2 mu) (eq. 41), and the plastic
    strain, hardening variable and deviator follow eqs. 42-45.
    """
    E, nu = moduli(mp, xi)
    mu = E / (2.0 * (1.0 + nu))
    K = E / (3.0 * (1.0 - 2.0 * nu))
    I3 = ti.Matrix.identity(float, 3)
    ee = eps3 - eps_pl - e_iso * I3
    tr = ee.trace()
    s = 2.0 * mu * (ee - tr / 3.0 * I3)
    p = K * tr
    if ti.static(reading == StressReading.PAPER):
        # eq. 39 as printed (the trace term without its 2 mu) and p = lambda tr(eps_{n+1})
        s = 2.0 * mu * ee - tr / 3.0 * I3
        p = (K - 2.0 * mu / 3.0) * eps3.trace()
    if ti.static(plastic):
        s, dgam, n = perzyna_return(mp, s, alpha, mu, xi, T, dt)
        if dgam > 0.0:
            eps_pl += dgam * n
            alpha += SQRT23 * dgam
    return p * I3 + s, eps_pl, alpha


@ti.func
def perzyna_return(mp: ti.template(), s, alpha, mu, xi, T, dt):
    """The viscoplastic correction of a trial deviator s (eqs. 40-45). Returns (s, dgamma, n):
    the corrected deviator and the plastic multiplier and direction (dgamma = 0: elastic)."""
    sy = lerp_phase(xi, mp.yield_solid_Pa, mp.yield_liquid_Pa)
    Hh = lerp_phase(xi, mp.hardening_solid_Pa, mp.hardening_liquid_Pa)
    snorm = s.norm()
    f = snorm - SQRT23 * (sy + Hh * alpha)
    dgam = 0.0
    n = ti.Matrix.zero(float, 3, 3)
    if f > 0.0:
        tau = viscosity(mp, T) / (2.0 * mu)
        dgam = (f / (2.0 * mu)) / (tau / dt + 1.0 + Hh / (3.0 * mu))
        n = s / snorm
        s -= 2.0 * mu * dgam * n
    return s, dgam, n


@ti.func
def perzyna_increment(
    mp: ti.template(), sigma, deps3, d_iso, alpha, xi, T, dt, plastic: ti.template()
):
    """The incremental (hypoelastic) form of the same step: the trial stress is the last stress
    plus the moduli at the current solid fraction times the elastic strain increment,
    s_tr = dev(sigma_n) + 2 mu dev(d eps_e), p = p_n + K tr(d eps_e), d eps_e = d eps - d e_iso
    1. A change of moduli (melting, freezing) then leaves the stress continuous: a melt freezes
    in the shape it has, instead of the stiffer solid pulling it back towards the stress-free
    start (which the total form, eq. 38-39, does). Returns (sigma, dgamma, n): the stress and
    the plastic multiplier and direction (dgamma = 0: elastic)."""
    E, nu = moduli(mp, xi)
    mu = E / (2.0 * (1.0 + nu))
    K = E / (3.0 * (1.0 - 2.0 * nu))
    I3 = ti.Matrix.identity(float, 3)
    de = deps3 - d_iso * I3
    tr = de.trace()
    p = sigma.trace() / 3.0 + K * tr
    s = (sigma - sigma.trace() / 3.0 * I3) + 2.0 * mu * (de - tr / 3.0 * I3)
    dgam = 0.0
    n = ti.Matrix.zero(float, 3, 3)
    if ti.static(plastic):
        s, dgam, n = perzyna_return(mp, s, alpha, mu, xi, T, dt)
    return p * I3 + s, dgam, n


@ti.func
def stress_update(cfg: ti.template(), pt: ti.template(), mat: ti.template(), p, L, dt):
    """Strain increment (eqs. 16-17, 34) and the Perzyna update (eqs. 38-45) of point p, in the
    total form (stress from the accumulated elastic strain, the paper's) or the incremental one
    (``solver.stress_form``; it needs neither the accumulated strain nor the plastic strain,
    which it then touches only where the point yields)."""
    deps = 0.5 * (L + L.transpose()) * dt
    if ti.static(cfg.stress_form == StressForm.INCREMENTAL):
        d_iso = 0.0
        if ti.static(cfg.th_strain):
            d_iso = pt.iso_strain_step[p]
        sig, dgam, n = perzyna_increment(
            mat[pt.material[p]],
            pt.stress[p],
            embed3(deps),
            d_iso,
            pt.equivalent_plastic_strain[p],
            pt.solid_fraction[p],
            pt.T[p],
            dt,
            cfg.plastic,
        )
        pt.stress[p] = sig
        if ti.static(cfg.plastic):
            if dgam > 0.0:
                pt.plastic_strain[p] += dgam * n
                pt.equivalent_plastic_strain[p] += SQRT23 * dgam
    else:
        eps = pt.strain[p] + deps
        pt.strain[p] = eps
        sig, epl, a = perzyna_update(
            mat[pt.material[p]],
            embed3(eps),
            pt.plastic_strain[p],
            pt.equivalent_plastic_strain[p],
            pt.iso_strain[p],
            pt.solid_fraction[p],
            pt.T[p],
            dt,
            cfg.plastic,
            cfg.stress_reading,
        )
        pt.stress[p] = sig
        pt.plastic_strain[p] = epl
        pt.equivalent_plastic_strain[p] = a


@ti.func
def thermal_strain_step(cfg: ti.template(), pt: ti.template(), mat: ti.template(), p, dT, dxi):
    """Eqs. 36-37 over one heat step (dT, d xi_s), alpha at the step's mean solid fraction. The
    increment is spread over the heat_every mechanical steps that follow: added at once it is an
    impulse that rings the elastic melt (the scan case's kinetic energy tripled with heat every
    19 steps)."""
    mp = mat[pt.material[p]]
    alpha = lerp_phase(
        pt.solid_fraction[p] - 0.5 * dxi, mp.expansion_solid_1_K, mp.expansion_liquid_1_K
    )
    pt.iso_strain_step[p] = (alpha * dT + mp.solidification_dilatation * dxi) / cfg.heat_every
