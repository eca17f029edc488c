"""Analytic reference solutions used to verify the solver (all SI units).

Each function's docstring names its source and formula. Functions take scalars or numpy arrays
(broadcast) where that is natural; array-valued results are returned as ``float`` for scalar
input and ``numpy.ndarray`` otherwise. Only numpy and the standard library are used (no scipy):
erf/erfc come from :mod:`math`, root finding is a plain bisection.

Contents
--------
1. Fixed-free elastic bar, first axial mode (MPM vibrating-bar benchmark); a manufactured
   large-deformation solution of a fixed-fixed bar (Steffen, Kirby & Berzins 2008).
2. Heat conduction: erf half-space, spreading 2D Gaussian.
3. Perzyna overstress viscoplasticity (the solver's backward-Euler return map): stress relaxation
   at fixed strain, constant-rate pure shear (continuous closed form and step-by-step discrete).
4. Stefan melting problem with a linear mushy zone (three-zone similarity solution).
5. Capillarity of a 2D disc: Laplace pressure, viscous and inviscid shape oscillations.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numpy.typing import ArrayLike

_SQRT_2_3 = math.sqrt(2.0 / 3.0)
_SQRT_PI = math.sqrt(math.pi)

_erf_u = np.frompyfunc(math.erf, 1, 1)


def _out(a: ArrayLike) -> float | np.ndarray:
    """Return a python float for 0-d results, a float ndarray otherwise."""
    arr = np.asarray(a, dtype=float)
    return float(arr) if arr.ndim == 0 else arr


def _erf(x: ArrayLike) -> np.ndarray:
    return np.asarray(_erf_u(np.asarray(x, dtype=float)), dtype=float)


def _erfcx_scalar(x: float) -> float:
    """Scaled complementary error function exp(x^2) erfc(x), for x >= about -26."""
    if x < 25.0:
        return math.exp(x * x) * math.erfc(x)
    # asymptotic series (Abramowitz & Stegun 7.1.23); truncation error < 1e-13 for x >= 25
    y = 1.0 / (2.0 * x * x)
    s, term = 1.0, 1.0
    for m in range(1, 6):
        term *= -(2 * m - 1) * y
        s += term
    return s / (x * _SQRT_PI)


_erfcx_u = np.frompyfunc(_erfcx_scalar, 1, 1)


def _erfcx(x: ArrayLike) -> np.ndarray:
    return np.asarray(_erfcx_u(np.asarray(x, dtype=float)), dtype=float)


# ---------------------------------------------------------------------------------------------
# 1. Fixed-free axially vibrating bar
# ---------------------------------------------------------------------------------------------


def bar_omega(L: float, E: float, rho: float) -> float:
    """First angular eigenfrequency of a fixed-free bar: w1 = pi/(2L) sqrt(E/rho) (rad/s)."""
    return math.pi / (2.0 * L) * math.sqrt(E / rho)


def bar_velocity(
    x: ArrayLike, t: ArrayLike, L: float, E: float, rho: float, v0: float
) -> float | np.ndarray:
    """Velocity of a fixed-free bar vibrating in its first axial mode.

    Bar fixed at x=0, free at x=L, wave equation rho u_tt = E u_xx, u(x,0)=0 and initial
    velocity v(x,0) = v0 sin(pi x/(2L)) (the first mode). Then
    v(x,t) = v0 sin(pi x/(2L)) cos(w1 t), w1 = pi/(2L) sqrt(E/rho).
    Source: Bardenhagen 2002 (J. Comput. Phys. 180); Bardenhagen & Kober 2004 (CMES 5).
    """
    x = np.asarray(x, dtype=float)
    t = np.asarray(t, dtype=float)
    w1 = bar_omega(L, E, rho)
    return _out(v0 * np.sin(np.pi * x / (2.0 * L)) * np.cos(w1 * t))


def bar_displacement(
    x: ArrayLike, t: ArrayLike, L: float, E: float, rho: float, v0: float
) -> float | np.ndarray:
    """Displacement of the first-mode fixed-free bar (see :func:`bar_velocity`).

    u(x,t) = (v0/w1) sin(pi x/(2L)) sin(w1 t), w1 = pi/(2L) sqrt(E/rho).
    Source: Bardenhagen 2002; Bardenhagen & Kober 2004.
    """
    x = np.asarray(x, dtype=float)
    t = np.asarray(t, dtype=float)
    w1 = bar_omega(L, E, rho)
    return _out(v0 / w1 * np.sin(np.pi * x / (2.0 * L)) * np.sin(w1 * t))


def bar_com_velocity(t: ArrayLike, L: float, E: float, rho: float, v0: float) -> float | np.ndarray:
    """Centre-of-mass velocity of the first-mode fixed-free bar (see :func:`bar_velocity`).

    v_cm(t) = (1/L) int_0^L v dx = (2 v0/pi) cos(w1 t), w1 = pi/(2L) sqrt(E/rho).
    Source: Bardenhagen & Kober 2004 (CMES 5), Bardenhagen 2002 (J. Comput. Phys. 180).
    """
    t = np.asarray(t, dtype=float)
    return _out(2.0 * v0 / np.pi * np.cos(bar_omega(L, E, rho) * t))


def steffen_displacement(
    X: ArrayLike, t: ArrayLike, L: float, A: float, E: float, rho: float
) -> float | np.ndarray:
    """Manufactured displacement of a bar fixed at X = 0 and X = L (reference position X):

    u(X,t) = A sin(2 pi X/L) sin(pi c t/L), c = sqrt(E/rho).
    The form of Steffen, Kirby & Berzins 2008 (IJNME 76, sec. 6, the 1D manufactured solution
    u = A sin(2 pi X) sin(c pi t) on the unit bar), scaled to a bar of length L; its time
    frequency is not an eigenfrequency, so the body force of :func:`steffen_body_force` drives it.
    (The printed eqs. 47-49 could not be retrieved here; the body force below is derived for this
    solver's own constitutive law instead of theirs.)
    """
    X = np.asarray(X, dtype=float)
    t = np.asarray(t, dtype=float)
    c = math.sqrt(E / rho)
    return _out(A * np.sin(2.0 * np.pi * X / L) * np.sin(np.pi * c * t / L))


def steffen_velocity(
    X: ArrayLike, t: ArrayLike, L: float, A: float, E: float, rho: float
) -> float | np.ndarray:
    """du/dt of :func:`steffen_displacement`: A w sin(2 pi X/L) cos(w t), w = pi c/L."""
    X = np.asarray(X, dtype=float)
    t = np.asarray(t, dtype=float)
    w = math.pi * math.sqrt(E / rho) / L
    return _out(A * w * np.sin(2.0 * np.pi * X / L) * np.cos(w * t))


def steffen_body_force(
    X: ArrayLike, t: ArrayLike, L: float, A: float, E: float, rho: float
) -> float | np.ndarray:
    """Body force per unit mass (m/s^2) that makes :func:`steffen_displacement` exact.

    Derived for the solver's law in 1D (Poisson ratio 0, plane strain): the strain is accumulated
    as d(eps)/dt = sym(L) = (dF/dt)/F, so eps = ln F, F = 1 + du/dX, and the axial Cauchy stress
    sigma = E ln F equals the first Piola-Kirchhoff stress (J = F). Momentum in the reference
    configuration, rho du^2/dt^2 = dP/dX + rho b, with dP/dX = E u_XX / F and u_XX = -k^2 u,
    k = 2 pi/L, gives
    b = u (c^2 k^2 / F - w^2), c^2 = E/rho, w = pi c/L.
    Source: method of manufactured solutions for MPM, Steffen, Kirby & Berzins 2008 (IJNME 76).
    """
    X = np.asarray(X, dtype=float)
    t = np.asarray(t, dtype=float)
    c2 = E / rho
    k = 2.0 * np.pi / L
    w = math.pi * math.sqrt(c2) / L
    u = A * np.sin(k * X) * np.sin(w * t)
    F = 1.0 + A * k * np.cos(k * X) * np.sin(w * t)
    return _out(u * (c2 * k * k / F - w * w))


# ---------------------------------------------------------------------------------------------
# 2. Heat conduction
# ---------------------------------------------------------------------------------------------


def erf_slab(x: ArrayLike, t: ArrayLike, T0: float, Ts: float, alpha: float) -> float | np.ndarray:
    """Semi-infinite solid x >= 0, initially at T0, surface x=0 held at Ts from t=0 (t > 0).

    T(x,t) = Ts + (T0 - Ts) erf(x / (2 sqrt(alpha t))), alpha = k/(rho c).
    Source: Carslaw & Jaeger 1959, Conduction of Heat in Solids, sec. 2.5.
    """
    x = np.asarray(x, dtype=float)
    t = np.asarray(t, dtype=float)
    return _out(Ts + (T0 - Ts) * _erf(x / (2.0 * np.sqrt(alpha * t))))


def gaussian_spread_2d(
    r2: ArrayLike, t: ArrayLike, E_per_length: float, rho_c: float, alpha: float, sigma0: float
) -> float | np.ndarray:
    """Temperature rise of a spreading 2D Gaussian in an infinite medium (t >= 0).

    Initial rise dT(r,0) = E/(rho_c 2 pi s0^2) exp(-r^2/(2 s0^2)) carrying energy E per unit depth
    (J/m), rho_c the volumetric heat capacity (J/(m^3 K)). Its variance per axis grows as
    s^2(t) = s0^2 + 2 alpha t, so
    dT(r,t) = E/(rho_c 2 pi s^2) exp(-r^2/(2 s^2)), r2 = r^2 (m^2).
    Source: Carslaw & Jaeger 1959, sec. 10.3 (instantaneous line source, time-shifted by
    s0^2/(2 alpha)).
    """
    r2 = np.asarray(r2, dtype=float)
    t = np.asarray(t, dtype=float)
    s2 = sigma0**2 + 2.0 * alpha * t
    return _out(E_per_length / (rho_c * 2.0 * np.pi * s2) * np.exp(-r2 / (2.0 * s2)))


# ---------------------------------------------------------------------------------------------
# 3. Perzyna overstress viscoplasticity
# ---------------------------------------------------------------------------------------------


def perzyna_step(
    s_tr_norm: float, alpha: float, dt: float, mu: float, sigma_Y: float, H: float, eta: float
) -> tuple[float, float, float]:
    """One scalar step of the solver's Perzyna return map; returns (||s||, alpha, dgamma).

    f = ||s_tr|| - sqrt(2/3)(sigma_Y + H alpha_n); if f > 0:
    dgamma = (f/(2 mu)) / (tau/dt + 1 + H/(3 mu)), tau = eta/(2 mu),
    ||s_{n+1}|| = ||s_tr|| - 2 mu dgamma, alpha_{n+1} = alpha_n + sqrt(2/3) dgamma
    (the direction n = s_tr/||s_tr|| is unchanged). eta = 0 gives the rate-independent radial
    return. Source: Maeshima, Kim & Zohdi 2020, eq. 41 as printed; Simo & Hughes 1998, ch. 2-3.
    """
    f = s_tr_norm - _SQRT_2_3 * (sigma_Y + H * alpha)
    if f <= 0.0:
        return s_tr_norm, alpha, 0.0
    tau = eta / (2.0 * mu)
    dgamma = (f / (2.0 * mu)) / (tau / dt + 1.0 + H / (3.0 * mu))
    return s_tr_norm - 2.0 * mu * dgamma, alpha + _SQRT_2_3 * dgamma, dgamma


def perzyna_relaxation_ratio(dt: float, tau: float, mu: float, H: float) -> float:
    """Exact per-step ratio r = f_{n+1}/f_n of the Perzyna overstress at fixed total strain.

    Derivation (from :func:`perzyna_step`): with no strain increment the trial stress of step n+1
    is s_n, so its overstress is f_n = ||s_n|| - R(alpha_n), R(a) = sqrt(2/3)(sigma_Y + H a).
    The step lowers the norm by 2 mu dgamma and raises the radius by
    sqrt(2/3) H sqrt(2/3) dgamma = (2/3) H dgamma, hence
    f_{n+1} = f_n - 2 mu (1 + H/(3 mu)) dgamma, dgamma = (f_n/(2 mu)) / (tau/dt + 1 + H/(3 mu)),
    r = (tau/dt) / (tau/dt + 1 + H/(3 mu)) = tau / (tau + dt (1 + H/(3 mu))).
    This is backward Euler for df/dt = -(1 + H/(3 mu)) f / tau; as dt -> 0, r^(t/dt) ->
    exp(-(1 + H/(3 mu)) t / tau) (see :func:`perzyna_relaxation_continuous`).
    Source: Maeshima, Kim & Zohdi 2020, eq. 41; Simo & Hughes 1998, ch. 2-3.
    """
    return tau / (tau + dt * (1.0 + H / (3.0 * mu)))


def perzyna_relaxation(
    n_steps: ArrayLike, f0: float, dt: float, tau: float, mu: float, H: float
) -> float | np.ndarray:
    """Overstress f_n = f0 r^n after n steps at fixed total strain (r from
    :func:`perzyna_relaxation_ratio`).

    f0 is the overstress of the first trial state, ||s_tr|| - sqrt(2/3)(sigma_Y + H alpha_0).
    The stress norm and plastic strain follow as gamma_n = (f0 - f_n)/(2 mu + 2H/3),
    ||s_n|| = ||s_tr|| - 2 mu gamma_n, alpha_n = alpha_0 + sqrt(2/3) gamma_n.
    Source: Maeshima, Kim & Zohdi 2020, eq. 41; Simo & Hughes 1998, ch. 2-3.
    """
    n = np.asarray(n_steps, dtype=float)
    return _out(f0 * perzyna_relaxation_ratio(dt, tau, mu, H) ** n)


def perzyna_relaxation_continuous(
    t: ArrayLike, f0: float, tau: float, mu: float, H: float
) -> float | np.ndarray:
    """Continuous-time (dt -> 0) overstress relaxation at fixed strain.

    f(t) = f0 exp(-(1 + H/(3 mu)) t / tau), tau = eta/(2 mu): the dt -> 0 limit of
    :func:`perzyna_relaxation` (plastic rate dgamma/dt = f/eta).
    Source: Simo & Hughes 1998, ch. 2-3 (Perzyna model); Maeshima, Kim & Zohdi 2020, eq. 41.
    """
    t = np.asarray(t, dtype=float)
    return _out(f0 * np.exp(-(1.0 + H / (3.0 * mu)) * t / tau))


def perzyna_shear_constant_rate(
    t: ArrayLike, gamma_dot_eng: float, mu: float, sigma_Y: float, H: float, eta: float
) -> tuple[float | np.ndarray, float | np.ndarray]:
    """Deviatoric stress norm ||s|| and equivalent plastic strain alpha under constant-rate shear.

    Pure shear eps_xy = gamma_dot_eng t/2 from a stress-free, virgin state; continuous-time
    Perzyna model equal to the dt -> 0 limit of :func:`perzyna_step`:
    d||s||/dt = S - 2 mu dgamma/dt, dgamma/dt = <f>/eta, d alpha/dt = sqrt(2/3) dgamma/dt,
    f = ||s|| - R, R = sqrt(2/3)(sigma_Y + H alpha), S = 2 mu sqrt(2) |eps_xy_dot|
    = sqrt(2) mu |gamma_dot_eng|.
    Elastic (||s|| = S t) until t_y = R0/S, R0 = sqrt(2/3) sigma_Y. Afterwards
    df/dt = S - k f, k = (2 mu + 2H/3)/eta = (1 + H/(3 mu))/tau, so with t' = t - t_y:
    f = (S/k)(1 - exp(-k t')), gamma = (S/(k eta)) (t' - (1 - exp(-k t'))/k),
    ||s|| = R0 + (2/3) H gamma + f = S t - 2 mu gamma, alpha = sqrt(2/3) gamma.
    The overstress tends to S/k and the stress then drifts with hardening slope
    d||s||/dt -> S (2H/3)/(2 mu + 2H/3). eta = 0 gives the rate-independent limit (f = 0).
    s_xy = ||s||/sqrt(2). Source: Simo & Hughes 1998, ch. 2-3; Maeshima, Kim & Zohdi 2020.
    """
    t = np.asarray(t, dtype=float)
    S = math.sqrt(2.0) * mu * abs(gamma_dot_eng)
    R0 = _SQRT_2_3 * sigma_Y
    t_y = R0 / S
    tp = np.maximum(t - t_y, 0.0)
    c = 2.0 * mu + 2.0 * H / 3.0
    if eta == 0.0:
        gamma = S * tp / c
    else:
        k = c / eta
        gamma = S / (k * eta) * (tp + np.expm1(-k * tp) / k)
    s_norm = S * t - 2.0 * mu * gamma
    return _out(s_norm), _out(_SQRT_2_3 * gamma)


def perzyna_shear_discrete(
    n_steps: int, dt: float, gamma_dot_eng: float, mu: float, sigma_Y: float, H: float, eta: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step-by-step :func:`perzyna_step` under constant-rate pure shear from a virgin state.

    Each step adds the elastic trial increment d||s_tr|| = sqrt(2) mu |gamma_dot_eng| dt (the
    shear direction never changes) and applies the return map. Returns arrays
    (t_n, ||s_n||, alpha_n), n = 0..n_steps; a solver on the same dt should match to round-off.
    Converges at first order in dt to :func:`perzyna_shear_constant_rate` (backward Euler).
    Source: Maeshima, Kim & Zohdi 2020, eq. 41; Simo & Hughes 1998, ch. 2-3.
    """
    ds = math.sqrt(2.0) * mu * abs(gamma_dot_eng) * dt
    s_out = np.zeros(n_steps + 1)
    a_out = np.zeros(n_steps + 1)
    s, a = 0.0, 0.0
    for n in range(1, n_steps + 1):
        s, a, _ = perzyna_step(s + ds, a, dt, mu, sigma_Y, H, eta)
        s_out[n], a_out[n] = s, a
    return dt * np.arange(n_steps + 1), s_out, a_out


# ---------------------------------------------------------------------------------------------
# 4. Stefan problem with a linear mushy zone
# ---------------------------------------------------------------------------------------------


def mushy_enthalpy(T: ArrayLike, T_c: float, T_m: float, c: float, L: float) -> float | np.ndarray:
    """Specific enthalpy H(T) = c T + L (1 - xi_s(T)) (J/kg), xi_s = clip(1 - (T-T_c)/(T_m-T_c)).

    Latent heat L released linearly over [T_c, T_m] (solidus T_c, liquidus T_m).
    """
    T = np.asarray(T, dtype=float)
    xi_s = np.clip(1.0 - (T - T_c) / (T_m - T_c), 0.0, 1.0)
    return _out(c * T + L * (1.0 - xi_s))


@functools.lru_cache(maxsize=256)
def _mushy_lambdas(
    T_init: float, T_s: float, T_c: float, T_m: float, nu: float
) -> tuple[float, float]:
    dTl, dTm, dTs = T_s - T_m, T_m - T_c, T_c - T_init
    nu2 = nu * nu

    def front_c(lm: float) -> tuple[float, float] | None:
        """Given lam_m: (lam_c, b) where the mushy profile reaches T_c, or None if it never does."""
        b = dTl * math.exp(-lm * lm) / (nu * math.erf(lm))
        ex_m = _erfcx_scalar(nu * lm)
        if b * ex_m <= dTm:
            return None
        logq = math.log(ex_m - dTm / b)

        def g(lc: float) -> float:  # decreasing in lc, g(lm) > 0
            return math.log(_erfcx_scalar(nu * lc)) - nu2 * (lc * lc - lm * lm) - logq

        lo, hi = lm, lm + 1.0
        while g(hi) > 0.0:
            lo, hi = hi, lm + 2.0 * (hi - lm)
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if g(mid) > 0.0:
                lo = mid
            else:
                hi = mid
            if hi - lo <= 2e-16 * hi:
                break
        return 0.5 * (lo + hi), b

    def F(lm: float) -> float:
        """log(mushy flux / solid flux) at lam_c; decreasing in lam_m."""
        r = front_c(lm)
        if r is None:
            return -math.inf
        lc, b = r
        return (
            math.log(b * nu)
            - nu2 * (lc * lc - lm * lm)
            + math.log(_erfcx_scalar(lc))
            - math.log(dTs)
        )

    lo = 1e-6
    while F(lo) <= 0.0:
        lo *= 1e-3
        if lo < 1e-200:
            raise ValueError("mushy_stefan: cannot bracket lam_m")
    hi = 1.0
    while F(hi) > 0.0:
        lo, hi = hi, 2.0 * hi
        if hi > 1e6:
            raise ValueError("mushy_stefan: cannot bracket lam_m")
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if F(mid) > 0.0:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 2e-16 * hi:
            break
    r = front_c(lo)
    assert r is not None
    return lo, r[0]


def _mushy_check(T_init: float, T_s: float, T_c: float, T_m: float, L: float) -> None:
    if not (T_init < T_c < T_m < T_s):
        raise ValueError(f"need T_init < T_c < T_m < T_s, got {T_init}, {T_c}, {T_m}, {T_s}")
    if L < 0.0:
        raise ValueError(f"latent heat L must be >= 0, got {L}")


def mushy_stefan_lambdas(
    T_init: float, T_s: float, T_c: float, T_m: float, c: float, L: float
) -> tuple[float, float]:
    """Similarity constants (lam_m, lam_c) of :func:`mushy_stefan`; X = 2 lam sqrt(alpha t).

    They depend only on the temperatures and nu = sqrt(c_app/c), c_app = c + L/(T_m - T_c).
    """
    _mushy_check(T_init, T_s, T_c, T_m, L)
    nu = math.sqrt(1.0 + L / (c * (T_m - T_c)))
    return _mushy_lambdas(float(T_init), float(T_s), float(T_c), float(T_m), nu)


def mushy_stefan_fronts(
    t: ArrayLike,
    T_init: float,
    T_s: float,
    T_c: float,
    T_m: float,
    k: float,
    rho: float,
    c: float,
    L: float,
) -> tuple[float | np.ndarray, float | np.ndarray]:
    """Liquidus and solidus front positions (X_m, X_c) = 2 (lam_m, lam_c) sqrt(alpha t) of
    :func:`mushy_stefan`, alpha = k/(rho c)."""
    lm, lc = mushy_stefan_lambdas(T_init, T_s, T_c, T_m, c, L)
    s = 2.0 * np.sqrt(k / (rho * c) * np.asarray(t, dtype=float))
    return _out(lm * s), _out(lc * s)


def mushy_stefan(
    x: ArrayLike,
    t: ArrayLike,
    T_init: float,
    T_s: float,
    T_c: float,
    T_m: float,
    k: float,
    rho: float,
    c: float,
    L: float,
) -> float | np.ndarray:
    """Melting of a semi-infinite solid with a linear mushy zone: T(x,t) for x >= 0, t > 0.

    Solid initially at T_init < T_c, surface held at T_s > T_m; rho, c, k equal in all phases;
    latent heat L released linearly over [T_c, T_m] (:func:`mushy_enthalpy`), so the mushy zone
    has constant c_app = c + L/(T_m - T_c) and no latent jump sits at either front.
    With alpha = k/(rho c), eta = x/(2 sqrt(alpha t)), nu = sqrt(c_app/c) (the mushy similarity
    variable is nu eta), fronts X_m = 2 lam_m sqrt(alpha t) (T = T_m), X_c = 2 lam_c sqrt(alpha t)
    (T = T_c), each zone solves the heat equation with its own diffusivity:
      liquid  0 < eta < lam_m:   T = T_s - (T_s - T_m) erf(eta)/erf(lam_m)
      mushy   lam_m < eta < lam_c: T = T_m - B (erf(nu eta) - erf(nu lam_m)),
                                   B = (T_m - T_c)/(erf(nu lam_c) - erf(nu lam_m))
      solid   eta > lam_c:       T = T_init + (T_c - T_init) erfc(eta)/erfc(lam_c)
    Temperature continuity holds by construction; flux continuity (same k) gives
      (T_s - T_m) exp(-lam_m^2)/erf(lam_m) = nu B exp(-nu^2 lam_m^2),
      (T_c - T_init) exp(-lam_c^2)/erfc(lam_c) = nu B exp(-nu^2 lam_c^2).
    Solved by nested bisection: for a trial lam_m the first equation fixes B, T = T_c then fixes
    lam_c (inner bisection); the outer bisection on lam_m zeroes log of the second equation's
    ratio. Everything is evaluated with erfcx(z) = exp(z^2) erfc(z) to avoid under/overflow.
    L = 0 reduces to :func:`erf_slab`. Source: three-region extension of the Neumann solution,
    Carslaw & Jaeger 1959, sec. 11.2; Alexiades & Solomon 1993, Mathematical Modeling of Melting
    and Freezing Processes, ch. 2 (mushy-zone similarity solutions).
    """
    _mushy_check(T_init, T_s, T_c, T_m, L)
    lm, lc = mushy_stefan_lambdas(T_init, T_s, T_c, T_m, c, L)
    nu = math.sqrt(1.0 + L / (c * (T_m - T_c)))
    x, t = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(t, dtype=float))
    eta = x / (2.0 * np.sqrt(k / (rho * c) * t))
    liq = eta < lm
    sol = eta > lc
    mush = ~(liq | sol)
    T = np.empty(eta.shape)
    T[liq] = T_s - (T_s - T_m) * _erf(eta[liq]) / math.erf(lm)
    b = (T_s - T_m) * math.exp(-lm * lm) / (nu * math.erf(lm))  # = B exp(-nu^2 lam_m^2)
    em = eta[mush]
    T[mush] = T_m - b * (
        _erfcx_scalar(nu * lm) - _erfcx(nu * em) * np.exp(nu * nu * (lm * lm - em * em))
    )
    es = eta[sol]
    T[sol] = T_init + (T_c - T_init) * _erfcx(es) / _erfcx_scalar(lc) * np.exp(lc * lc - es * es)
    return _out(T)


# ---------------------------------------------------------------------------------------------
# 5. Capillarity of a 2D disc (cylinder)
# ---------------------------------------------------------------------------------------------


def disc_curvature(R: float) -> float:
    """Curvature of a circle of radius R: kappa = 1/R (1/m)."""
    return 1.0 / R


def laplace_pressure_2d(gamma: float, R: float) -> float:
    """Young-Laplace pressure jump of a 2D disc (one principal curvature): dp = gamma/R (Pa).

    Source: Young-Laplace equation dp = gamma kappa, kappa = 1/R (de Gennes, Brochard-Wyart &
    Quere 2004, Capillarity and Wetting Phenomena, ch. 1).
    """
    return gamma / R


def viscous_decay_rate(n: int, gamma: float, eta_N: float, R: float) -> float:
    """Decay rate of shape mode n >= 2 of a 2D viscous disc in vacuum, Stokes limit (1/s).

    r = R (1 + eps(t) cos n theta), eps(t) = eps0 exp(-rate t), rate = n gamma/(2 eta_N R).
    This is the rate the project uses to verify capillary-viscous relaxation. It follows from
    the plane Stokes solution psi = (A r^n + B r^(n+2)) sin n theta, p = 4 eta_N (n+1) B r^n
    cos n theta, with zero shear stress and sigma_rr = -gamma eps (n^2-1)/R cos n theta at
    r = R, and the kinematic condition R d eps/dt = u_r(R) (the usual 2D capillary-viscous drop
    relaxation, cf. Hopper 1990, J. Fluid Mech. 213, plane Stokes flow driven by capillarity).
    Checked by hand (accuracy issue): sigma_rtheta(R) = 0 gives B R^2 = -(n-1) A/(n+1); then
    sigma_rr(R) = 4 eta_N (n-1) A R^(n-2) cos n theta, u_r(R) = 2n A R^(n-1)/(n+1) cos n theta,
    and the normal balance gives d eps/dt = -n gamma eps/(2 eta_N R): the coefficient stands
    (n = 2: rate = gamma/(eta_N R)).

    eta_N is the Newtonian shear viscosity (deviatoric stress 2 eta_N D). The solver's Perzyna
    model with zero yield stress and no hardening is a Maxwell fluid, ds/dt = 2 mu D - s/tau,
    tau = eta/(2 mu) (eq. 41 in the limit of small steps): its steady stress is s = eta D, so
    eta_N = eta/2, half the paper's eta. It is Newtonian only for rate tau << 1; a Maxwell fluid
    in the Stokes limit decays at rate/(1 + rate tau) (:func:`maxwell_decay_rate`).
    """
    return n * gamma / (2.0 * eta_N * R)


def maxwell_decay_rate(newtonian_rate: float, tau: float) -> float:
    """Decay rate of a capillary shape mode of a Maxwell fluid (relaxation time tau) in the Stokes
    limit: s = lam/(1 + lam tau), lam the Newtonian rate of :func:`viscous_decay_rate`.

    The Maxwell fluid's viscosity in the Laplace domain is eta_N/(1 + s tau); putting it into
    s = -n gamma/(2 eta_N(s) R) gives s (1 + lam tau) = -lam. Source: correspondence principle of
    linear viscoelasticity (Christensen 1982, Theory of Viscoelasticity, ch. 2) applied to
    :func:`viscous_decay_rate`.
    """
    return newtonian_rate / (1.0 + newtonian_rate * tau)


def inviscid_drop_omega(n: int, gamma: float, rho: float, R: float) -> float:
    """Angular frequency of shape mode n of an inviscid 2D disc (cylinder, no outer fluid).

    omega^2 = n (n^2 - 1) gamma / (rho R^3).
    Source: Rayleigh 1879 (Proc. R. Soc. 29, capillary jets); Lamb 1932, Hydrodynamics, sec. 275.
    """
    return math.sqrt(n * (n * n - 1) * gamma / (rho * R**3))
