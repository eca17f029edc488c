"""Perzyna overstress viscoplasticity (the solver's backward-Euler return map): stress relaxation
at fixed strain, constant-rate pure shear (continuous closed form and step-by-step discrete);
its zero-yield limit, the Maxwell fluid (relaxation and simple shear)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ._util import out

_SQRT_2_3 = math.sqrt(2.0 / 3.0)


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
    return out(f0 * perzyna_relaxation_ratio(dt, tau, mu, H) ** n)


def perzyna_relaxation_continuous(
    t: ArrayLike, f0: float, tau: float, mu: float, H: float
) -> float | np.ndarray:
    """Continuous-time (dt -> 0) overstress relaxation at fixed strain.

    f(t) = f0 exp(-(1 + H/(3 mu)) t / tau), tau = eta/(2 mu): the dt -> 0 limit of
    :func:`perzyna_relaxation` (plastic rate dgamma/dt = f/eta).
    Source: Simo & Hughes 1998, ch. 2-3 (Perzyna model); Maeshima, Kim & Zohdi 2020, eq. 41.
    """
    t = np.asarray(t, dtype=float)
    return out(f0 * np.exp(-(1.0 + H / (3.0 * mu)) * t / tau))


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
    return out(s_norm), out(_SQRT_2_3 * gamma)


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


def maxwell_relaxation(t: ArrayLike, s0: float, tau: float) -> float | np.ndarray:
    """Deviatoric stress of a Maxwell fluid held at a fixed deformation: s0 exp(-t / tau),
    tau = eta / (2 mu) (the Perzyna model with sigma_Y = H = 0: ds/dt = 2 mu D - s / tau)."""
    return out(s0 * np.exp(-np.asarray(t, dtype=float) / tau))


def maxwell_shear_stress(t: ArrayLike, rate: float, mu: float, tau: float) -> float | np.ndarray:
    """Shear stress of a Maxwell fluid in simple shear v_x = rate y from rest, small strain:
    s_xy = mu rate tau (1 - exp(-t / tau)) = (eta / 2) rate (1 - exp(-t / tau)) (D_xy =
    rate / 2; the model's Newtonian viscosity is eta / 2, references.capillarity)."""
    return out(mu * rate * tau * -np.expm1(-np.asarray(t, dtype=float) / tau))
