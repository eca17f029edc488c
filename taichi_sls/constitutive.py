"""Strain split and the Perzyna elasto-viscoplastic return map (paper eqs. 34-45, MODEL.md).

Plane strain: the in-plane total strain is accumulated from the velocity gradient
(eqs. 16-17, eps_zz = 0); plastic, thermal and transformation strains are full 3x3 tensors.
Readings of MODEL.md: s_trial = 2 mu dev(eps_e) (eq. 39 lost its 2 mu on the trace term) and
p = K tr(eps_e), K = lambda + 2 mu / 3, with eps_e = eps - eps_pl - (eps_th + eps_m).
"""

import math

import taichi as ti

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
def perzyna_update(
    mat: ti.template(),
    m,
    eps3,
    eps_pl,
    alpha,
    e_iso,
    xi,
    T,
    dt,
    plastic: ti.template(),
    paper: ti.template(),
):
    """One backward-Euler Perzyna step. Returns (sigma, eps_pl, alpha). ``paper`` selects the
    printed eq. 39 and pressure instead of MODEL.md's reading.

    Trial: s_tr = 2 mu dev(eps_e), f = |s_tr| - sqrt(2/3)(sigma_Y + H alpha) (eq. 40); when f > 0,
    dgamma = (f / 2mu) / (tau/dt + 1 + H/(3 mu)), tau = eta / (2 mu) (eq. 41), and the plastic
    strain, hardening variable and deviator follow eqs. 42-45.
    """
    E = lerp_phase(mat, m, xi, "E_c", "E_m")
    nu = lerp_phase(mat, m, xi, "nu", "nu_m")
    mu = E / (2.0 * (1.0 + nu))
    K = E / (3.0 * (1.0 - 2.0 * nu))
    I3 = ti.Matrix.identity(float, 3)
    ee = eps3 - eps_pl - e_iso * I3
    tr = ee.trace()
    s = 2.0 * mu * (ee - tr / 3.0 * I3)
    p = K * tr
    if ti.static(paper):
        # eq. 39 as printed (the trace term without its 2 mu) and p = lambda tr(eps_{n+1})
        s = 2.0 * mu * ee - tr / 3.0 * I3
        p = (K - 2.0 * mu / 3.0) * eps3.trace()
    if ti.static(plastic):
        sy = lerp_phase(mat, m, xi, "sy_c", "sy_m")
        Hh = lerp_phase(mat, m, xi, "H_c", "H_m")
        snorm = s.norm()
        f = snorm - SQRT23 * (sy + Hh * alpha)
        if f > 0.0:
            tau = viscosity(mat, m, T) / (2.0 * mu)
            dgam = (f / (2.0 * mu)) / (tau / dt + 1.0 + Hh / (3.0 * mu))
            n = s / snorm
            eps_pl += dgam * n
            alpha += SQRT23 * dgam
            s -= 2.0 * mu * dgam * n
    return p * I3 + s, eps_pl, alpha
