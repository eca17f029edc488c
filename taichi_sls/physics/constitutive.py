"""Strain split and the Perzyna elasto-viscoplastic return map (paper eqs. 34-45, docs/model.md).

Plane strain: the in-plane total strain is accumulated from the velocity gradient
(eqs. 16-17, eps_zz = 0); plastic, thermal and transformation strains are full 3x3 tensors.
Readings of docs/model.md: s_trial = 2 mu dev(eps_e) (eq. 39 lost its 2 mu on the trace term) and
p = K tr(eps_e), K = lambda + 2 mu / 3, with eps_e = eps - eps_pl - (eps_th + eps_m).

Finite strain (``solver.strain = "finite"``, :func:`hencky_update`): F = Fe Fp; the elastic
left Cauchy-Green tensor b_e = Fe Fe^T gives the principal stretches and directions, the Hencky
strain e_i = log(lambda_i), the Kirchhoff stress tau_i = 2 mu dev(e)_i + K tr(e) and the same
Perzyna map (eqs. 40-45) on its deviator, backward Euler (zero yield: a Maxwell fluid).
"""

import math

from taichi_sls.backend import ti

from . import small_matrix
from .codes import Strain, StressForm, StressReading
from .materials import lerp_phase, viscosity
from .small_matrix import IDENTITY, ZERO_MATRIX, ZERO_VECTOR, conjugate, matmul, matmul_bt

SQRT23 = math.sqrt(2.0 / 3.0)
# the smallest principal elastic stretch whose logarithm is taken: a point compressed past it
# (or inverted, which its J <= 0 shows to the guard, solver/step.py watch) keeps a finite strain
STRETCH_FLOOR = 1e-6


@ti.func
def to3(A, dim: ti.template()):
    """A dim x dim tensor as 3x3 (plane strain: zero out-of-plane row and column)."""
    out = ti.Matrix(ZERO_MATRIX[3, 3])
    for a, b in ti.static(ti.ndrange(dim, dim)):
        out[a, b] = A[a, b]
    return out


@ti.func
def embed3(e2):
    """A dim x dim strain as 3x3: in 2D the in-plane strain with eps_zz = 0 (plane strain), in
    3D itself."""
    e = ti.Matrix(ZERO_MATRIX[3, 3])
    for a, b in ti.static(ti.ndrange(e2.n, e2.m)):
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
    I3 = ti.Matrix(IDENTITY[3])
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
    n = ti.Matrix(ZERO_MATRIX[3, 3])
    if f > 0.0:
        tau = viscosity(mp, T) / (2.0 * mu)
        dgam = (f / (2.0 * mu)) / (tau / dt + 1.0 + Hh / (3.0 * mu))
        n = s / snorm
        s -= 2.0 * mu * dgam * n
    return s, dgam, n


@ti.func
def perzyna_secant_at_zero(mp: ti.template(), alpha, mu, xi, T, dt):
    """|s| / |s_trial| of :func:`perzyna_return` as the trial deviator goes to zero: 1 (elastic)
    where the yield stress sqrt(2/3)(sigma_Y + H alpha) is positive; where it is zero every trial
    deviator flows, and the ratio is the flow's constant 1 - 1 / (tau/dt + 1 + H/(3 mu)) (a zero-
    yield melt at rest, whose return map reads f = 0 as elastic, is a Newtonian fluid)."""
    sy = lerp_phase(xi, mp.yield_solid_Pa, mp.yield_liquid_Pa)
    Hh = lerp_phase(xi, mp.hardening_solid_Pa, mp.hardening_liquid_Pa)
    ratio = 1.0
    if sy + Hh * alpha <= 0.0:
        tau = viscosity(mp, T) / (2.0 * mu)
        ratio = 1.0 - 1.0 / (tau / dt + 1.0 + Hh / (3.0 * mu))
    return ratio


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
    I3 = ti.Matrix(IDENTITY[3])
    de = deps3 - d_iso * I3
    tr = de.trace()
    p = sigma.trace() / 3.0 + K * tr
    s = (sigma - sigma.trace() / 3.0 * I3) + 2.0 * mu * (de - tr / 3.0 * I3)
    dgam = 0.0
    n = ti.Matrix(ZERO_MATRIX[3, 3])
    if ti.static(plastic):
        s, dgam, n = perzyna_return(mp, s, alpha, mu, xi, T, dt)
    return p * I3 + s, dgam, n


@ti.func
def bulk_shear(mp: ti.template(), xi):
    """(mu, K) of material ``mp`` at solid fraction xi."""
    E, nu = moduli(mp, xi)
    return E / (2.0 * (1.0 + nu)), E / (3.0 * (1.0 - 2.0 * nu))


@ti.func
def principal_frame(b, dim: ti.template()):
    """Eigenvalues and eigenvectors (columns of a rotation Q) of the symmetric 3x3 b. Plane
    strain: the 2x2 block in closed form by atan2 (exact for near-equal eigenvalues; ti.svd's
    zeroed off-diagonals below 1e-5, erasing small shears) and b_zz; 3D: symmetric_eigen."""
    Q = ti.Matrix(IDENTITY[3])
    ev = ti.Vector([b[0, 0], b[1, 1], b[2, 2]])
    if ti.static(dim == 2):
        half = 0.5 * (b[0, 0] - b[1, 1])
        r = ti.sqrt(half * half + b[0, 1] * b[0, 1])
        mean = 0.5 * (b[0, 0] + b[1, 1])
        th = 0.5 * ti.atan2(b[0, 1], half)
        c, s = ti.cos(th), ti.sin(th)
        Q[0, 0], Q[0, 1], Q[1, 0], Q[1, 1] = c, -s, s, c
        ev[0], ev[1] = mean + r, mean - r
    else:
        ev, Q = small_matrix.symmetric_eigen(b)
    return ev, Q


@ti.func
def hencky_update(
    mp: ti.template(),
    Fe,
    xi_last,
    alpha,
    f,
    d_iso,
    xi,
    T,
    J,
    dt,
    plastic: ti.template(),
    dim: ti.template(),
):
    """One finite-strain step of material ``mp``: Fe the 3x3 elastic stretch before the step,
    f = I + dt L its relative deformation gradient (3x3, f_zz = 1 in plane strain), J = det F.
    Returns (sigma, Fe, dgamma, n): the Cauchy stress, the new elastic stretch (the symmetric
    left stretch V_e: the stress of an isotropic material depends on b_e = Fe Fe^T only) and the
    plastic multiplier and direction (global frame; dgamma = 0: elastic).

    Trial b_e = f b_e,n f^T (objective: a rotation increment rotates b_e, its eigenvalues stay);
    Hencky strain e_i = log(lambda_i) less the step's isotropic thermal and solidification strain
    d_iso (eqs. 36-37) from each principal value, the out-of-plane one too. A change of the solid
    fraction since the stored strain was last turned into stress (xi_last != xi, melting or
    freezing: the moduli change tenfold) rescales the deviatoric strain by mu_old/mu and the
    volumetric by K_old/K: the stress stays continuous and the difference becomes permanent
    deformation, as in the incremental small-strain form (a melt freezes in the shape it has
    instead of springing back). It applies to the trial strain, this step's increment included:
    a difference of order d(xi) dt. Then s_tr = 2 mu dev(e), the Perzyna correction of eqs.
    40-45 on the Kirchhoff deviator, tau = s + K tr(e) 1 and sigma = Q tau Q^T / J."""
    mu, K = bulk_shear(mp, xi)
    b = matmul_bt(matmul_bt(matmul(f, Fe), Fe), f)  # f Fe Fe^T f^T, as @
    ev, Q = principal_frame(b, dim)
    e = ti.Vector(ZERO_VECTOR[3])
    for i in ti.static(range(3)):
        e[i] = 0.5 * ti.log(ti.max(ev[i], STRETCH_FLOOR * STRETCH_FLOOR)) - d_iso
    e_vol = e.sum()
    e_dev = e - e_vol / 3.0
    if xi_last != xi:
        mu0, K0 = bulk_shear(mp, xi_last)
        e_dev *= mu0 / mu
        e_vol *= K0 / K
    s = ti.Matrix(ZERO_MATRIX[3, 3])
    for i in ti.static(range(3)):
        s[i, i] = 2.0 * mu * e_dev[i]
    dgam = 0.0
    n = ti.Matrix(ZERO_MATRIX[3, 3])
    if ti.static(plastic):
        s, dgam, n = perzyna_return(mp, s, alpha, mu, xi, T, dt)
    tau = ti.Matrix(ZERO_MATRIX[3, 3])
    lam = ti.Matrix(ZERO_MATRIX[3, 3])
    for i in ti.static(range(3)):
        tau[i, i] = s[i, i] + K * e_vol
        lam[i, i] = ti.exp(s[i, i] / (2.0 * mu) + e_vol / 3.0)
    return conjugate(Q, tau) / J, conjugate(Q, lam), dgam, conjugate(Q, n)


@ti.func
def solvent_stress(mp: ti.template(), L, xi):
    """The Kelvin-Voigt solvent stress of the melt, (1 - xi_s) 2 eta_s dev(D), D = sym(L), in
    plane (``materials.*.solvent_viscosity_Pa_s``): a force term only, outside the elastic
    state, so it damps without entering the stress history."""
    D = 0.5 * (L + L.transpose())
    dev = D - D.trace() / 3.0 * ti.Matrix(IDENTITY[L.n])
    return 2.0 * mp.solvent_viscosity_Pa_s * (1.0 - xi) * dev


@ti.func
def _iso_step(cfg: ti.template(), pt: ti.template(), p):
    """Point p's isotropic thermal and solidification strain of this step (0 without them)."""
    d_iso = 0.0
    if ti.static(cfg.th_strain):
        d_iso = pt.iso_strain_step[p]
    return d_iso


@ti.func
def _finite_step(cfg: ti.template(), pt: ti.template(), mat: ti.template(), p, f, J, dt):
    """:func:`hencky_update` of point p with its stored state: f = I + dt L (3x3), J = det F
    after the step."""
    return hencky_update(
        mat[pt.material[p]],
        pt.elastic_stretch[p],
        pt.stress_phase[p],
        pt.equivalent_plastic_strain[p],
        f,
        _iso_step(cfg, pt, p),
        pt.solid_fraction[p],
        pt.T[p],
        J,
        dt,
        cfg.plastic,
        cfg.dim,
    )


@ti.func
def _incremental_step(cfg: ti.template(), pt: ti.template(), mat: ti.template(), p, deps, dt):
    """:func:`perzyna_increment` of point p with its stored state, strain increment deps."""
    return perzyna_increment(
        mat[pt.material[p]],
        pt.stress[p],
        embed3(deps),
        _iso_step(cfg, pt, p),
        pt.equivalent_plastic_strain[p],
        pt.solid_fraction[p],
        pt.T[p],
        dt,
        cfg.plastic,
    )


@ti.func
def _total_step(cfg: ti.template(), pt: ti.template(), mat: ti.template(), p, eps, dt):
    """:func:`perzyna_update` of point p with its stored state at total strain eps."""
    return perzyna_update(
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


@ti.func
def stress_update(cfg: ti.template(), pt: ti.template(), mat: ti.template(), p, L, dt):
    """The stress of point p after a step of velocity gradient L: ``solver.strain`` finite
    (:func:`hencky_update`) or small (:func:`small_strain_update`); with a solvent viscosity
    also its stress (force only)."""
    if ti.static(cfg.strain == Strain.FINITE):
        I3 = ti.Matrix(IDENTITY[3])  # 2D: f_zz = 1, plane strain
        sig, Fe, dgam, n = _finite_step(cfg, pt, mat, p, I3 + dt * to3(L, cfg.dim), pt.J[p], dt)
        pt.stress[p] = sig
        pt.elastic_stretch[p] = Fe
        pt.stress_phase[p] = pt.solid_fraction[p]
        if ti.static(cfg.plastic):
            if dgam > 0.0:
                pt.plastic_strain[p] += dgam * n
                pt.equivalent_plastic_strain[p] += SQRT23 * dgam
    else:
        small_strain_update(cfg, pt, mat, p, L, dt)
    if ti.static(cfg.solvent):
        pt.viscous_stress[p] = solvent_stress(mat[pt.material[p]], L, pt.solid_fraction[p])


@ti.func
def small_strain_update(cfg: ti.template(), pt: ti.template(), mat: ti.template(), p, L, dt):
    """Strain increment (eqs. 16-17, 34) and the Perzyna update (eqs. 38-45) of point p, in the
    total form (stress from the accumulated elastic strain, the paper's) or the incremental one
    (``solver.stress_form``; it needs neither the accumulated strain nor the plastic strain,
    which it then touches only where the point yields)."""
    deps = 0.5 * (L + L.transpose()) * dt
    if ti.static(cfg.stress_form == StressForm.INCREMENTAL):
        sig, dgam, n = _incremental_step(cfg, pt, mat, p, deps, dt)
        pt.stress[p] = sig
        if ti.static(cfg.plastic):
            if dgam > 0.0:
                pt.plastic_strain[p] += dgam * n
                pt.equivalent_plastic_strain[p] += SQRT23 * dgam
    else:
        eps = pt.strain[p] + deps
        pt.strain[p] = eps
        sig, epl, a = _total_step(cfg, pt, mat, p, eps, dt)
        pt.stress[p] = sig
        pt.plastic_strain[p] = epl
        pt.equivalent_plastic_strain[p] = a


@ti.func
def trial_stress(cfg: ti.template(), pt: ti.template(), mat: ti.template(), p, L, dt):
    """The stress point p would take after a step of velocity gradient L, without keeping it
    (the implicit step's residual; :func:`stress_update` keeps the converged one). Returns
    (sigma, mu_t, K, eta): the in-plane Cauchy stress with the solvent's, the secant shear
    modulus of the Perzyna return mu |s| / |s_trial| (mu where the step stays elastic; a zero-
    yield melt at dt >> eta / 2 mu: ~eta / 2 dt, its Newtonian viscosity over dt, also at rest,
    :func:`perzyna_secant_at_zero`), the bulk modulus and the solvent viscosity, from which the
    implicit step builds its tangent."""
    mp = mat[pt.material[p]]
    xi = pt.solid_fraction[p]
    mu, K = bulk_shear(mp, xi)
    sig3 = ti.Matrix(ZERO_MATRIX[3, 3])
    dgam = 0.0
    kirchhoff = 1.0  # the return map acts on the Kirchhoff deviator J s in finite strain
    if ti.static(cfg.strain == Strain.FINITE):
        f = ti.Matrix(IDENTITY[3]) + dt * to3(L, cfg.dim)
        J = pt.J[p] * f.determinant()
        sig3, Fe, dgam, n = _finite_step(cfg, pt, mat, p, f, J, dt)
        kirchhoff = J
    else:
        deps = 0.5 * (L + L.transpose()) * dt
        if ti.static(cfg.stress_form == StressForm.INCREMENTAL):
            sig3, dgam, n = _incremental_step(cfg, pt, mat, p, deps, dt)
        else:
            sig3, epl, a = _total_step(cfg, pt, mat, p, pt.strain[p] + deps, dt)
            dgam = (a - pt.equivalent_plastic_strain[p]) / SQRT23
    ratio = 1.0
    if dgam > 0.0:
        tau = kirchhoff * sig3
        s_norm = (tau - tau.trace() / 3.0 * ti.Matrix(IDENTITY[3])).norm()
        ratio = s_norm / (s_norm + 2.0 * mu * dgam)
    elif ti.static(cfg.plastic):
        # no flow at this trial: elastic, unless the yield stress is zero and the trial deviator
        # is (a melt at rest), where the secant is the flow's limit, not mu: the implicit step
        # keeps the tangent of its first iterate, v^n, over its Newton iterations
        ratio = perzyna_secant_at_zero(mp, pt.equivalent_plastic_strain[p], mu, xi, pt.T[p], dt)
    sig = ti.Matrix(ZERO_MATRIX[cfg.dim, cfg.dim])
    for a, b in ti.static(ti.ndrange(cfg.dim, cfg.dim)):
        sig[a, b] = sig3[a, b]
    eta = 0.0
    if ti.static(cfg.solvent):
        sig += solvent_stress(mp, L, xi)
        eta = mp.solvent_viscosity_Pa_s * (1.0 - xi)
    return sig, mu * ratio, K, eta


@ti.func
def thermal_strain_step(cfg: ti.template(), pt: ti.template(), mat: ti.template(), p, dT, dxi):
    """Eqs. 36-37 over one heat step (dT, d xi_s), alpha at the step's mean solid fraction. The
    increment is spread over the heat_every mechanical steps that follow: added at once it is an
    impulse that rings the elastic melt (the scan case's kinetic energy tripled with heat every
    19 steps)."""
    pt.iso_strain_step[p] = thermal_strain_increment(pt, mat, p, dT, dxi) / cfg.heat_every


@ti.func
def thermal_strain_increment(pt: ti.template(), mat: ti.template(), p, dT, dxi):
    """The isotropic thermal and solidification strain of one heat step (eqs. 36-37), alpha at
    the step's mean solid fraction."""
    mp = mat[pt.material[p]]
    alpha = lerp_phase(
        pt.solid_fraction[p] - 0.5 * dxi, mp.expansion_solid_1_K, mp.expansion_liquid_1_K
    )
    return alpha * dT + mp.solidification_dilatation * dxi
