"""Quiescent polymer crystallisation: the isothermal Avrami law, Nakamura's non-isothermal
extension, and the DSC crystallisation peak under a constant cooling rate (all SI, kelvin).

Avrami (isothermal): X(t) = 1 - exp(-K t^n), half time t_1/2 = (ln 2 / K)^(1/n).
Nakamura (non-isothermal, "isokinetic" hypothesis): with K_N(T) = K(T)^(1/n),
X(t) = 1 - exp(-theta(t)^n), theta(t) = int_0^t K_N(T(s)) ds (Nakamura, Watanabe, Katayama &
Amano 1972, J Appl Polym Sci 16:1077), or in differential form (Patel & Spruiell 1991)
dX/dt = n K_N(T) (1 - X) [-ln(1 - X)]^((n-1)/n). At constant T both reduce to Avrami.
The rate law K_N(T) is the Hoffman-Lauritzen form used for such models (e.g. Patel & Spruiell;
Guo, Isayev & Guo 1999), 1/t_1/2 = (1/t_1/2)_0 exp(-U/(R (T - T_inf))) exp(-K_g/(T dT f)),
dT = T_m0 - T, f = 2 T / (T + T_m0), K_N = (ln 2)^(1/n) / t_1/2.

:data:`PA12_CRYSTALLIZATION` holds the PA12 values of docs/record/pa12_process.md; which of them are
measured and which are modelling choices is said there and in :class:`CrystallizationKinetics`.
The solver's kernels evaluate the same law per point (physics/materials.py, the option
``materials.NAME.crystallization_kinetics``); this module is their host-side reference.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import cumulative_trapezoid, quad, solve_ivp
from scipy.optimize import minimize_scalar

from ._util import out

GAS_CONSTANT = 8.314462618  # J/(mol K)


@dataclass(frozen=True)
class CrystallizationKinetics:
    """Avrami exponent and Hoffman-Lauritzen half-time law of one polymer (kelvin, seconds).

    n: Avrami exponent. inv_t_half_0: pre-factor (1/t_1/2)_0 (1/s). U: activation energy of
    segmental transport (J/mol). T_inf: temperature where transport stops, T_g - 30 K (K).
    T_m0: equilibrium melting temperature (K). K_g: nucleation constant (K^2).
    """

    n: float
    inv_t_half_0: float
    U: float
    T_inf: float
    T_m0: float
    K_g: float

    def __post_init__(self) -> None:
        for name in ("n", "inv_t_half_0", "U", "K_g"):
            if not getattr(self, name) > 0.0:
                raise ValueError(f"{name} = {getattr(self, name)} must be > 0")
        if not 0.0 < self.T_inf < self.T_m0:
            raise ValueError(f"T_inf = {self.T_inf} K must lie in (0, T_m0 = {self.T_m0} K)")

    def half_time(self, T: ArrayLike) -> float | np.ndarray:
        """Isothermal half time t_1/2(T) (s); infinite at and outside (T_inf, T_m0)."""
        T = np.asarray(T, dtype=float)
        inside = (T > self.T_inf) & (T < self.T_m0)
        Ts = np.where(inside, T, 0.5 * (self.T_inf + self.T_m0))
        dT = self.T_m0 - Ts
        f = 2.0 * Ts / (Ts + self.T_m0)
        log_rate = (
            math.log(self.inv_t_half_0)
            - self.U / (GAS_CONSTANT * (Ts - self.T_inf))
            - self.K_g / (Ts * dT * f)
        )
        with np.errstate(over="ignore"):  # a slow rate's half time may pass float range
            return out(np.where(inside, np.exp(-log_rate), np.inf))

    def avrami_K(self, T: ArrayLike) -> float | np.ndarray:
        """Isothermal Avrami rate constant K(T) = ln 2 / t_1/2^n (1/s^n)."""
        return out(math.log(2.0) / np.asarray(self.half_time(T)) ** self.n)

    def nakamura_K(self, T: ArrayLike) -> float | np.ndarray:
        """Nakamura rate constant K_N(T) = K(T)^(1/n) = (ln 2)^(1/n) / t_1/2 (1/s)."""
        return out(math.log(2.0) ** (1.0 / self.n) / np.asarray(self.half_time(T)))


# PA12 (laser-sintering powder). n, T_m0, K_g are modelling choices and inv_t_half_0 is
# calibrated to one crystallisation temperature; docs/record/pa12_process.md gives the ranges tried.
PA12_CRYSTALLIZATION = CrystallizationKinetics(
    n=3.0,  # modelling choice (spherulitic growth; tried 2-3); Zhao et al. 2018's fit unread
    inv_t_half_0=9.072e4,  # calibrated: DSC peak 146 C at 10 K/min from 185 C (Maeshima T_c)
    U=6270.0,  # Hoffman's "universal" 1500 cal/mol, the value such models use (unverified here)
    T_inf=(43.0 - 30.0) + 273.15,  # T_g 43 C (NETZSCH PA12 DSC, 2nd heating) minus 30 K
    T_m0=200.0 + 273.15,  # modelling choice (tried 190-210 C); above the 178 C DSC peak
    K_g=2.0e5,  # modelling choice (tried 1e5-4e5 K^2)
)


def avrami_fraction(t: ArrayLike, K: float, n: float) -> float | np.ndarray:
    """Isothermal Avrami relative crystallinity X(t) = 1 - exp(-K t^n) (t >= 0)."""
    t = np.asarray(t, dtype=float)
    return out(-np.expm1(-K * t**n))


def avrami_half_time(K: float, n: float) -> float:
    """Half time of :func:`avrami_fraction`: t_1/2 = (ln 2 / K)^(1/n)."""
    return (math.log(2.0) / K) ** (1.0 / n)


def avrami_time_to(X: ArrayLike, K: float, n: float) -> float | np.ndarray:
    """Isothermal time to reach relative crystallinity X: t = (-ln(1 - X) / K)^(1/n); e.g.
    how long a melt held at a bed temperature stays (X = 0.01) essentially amorphous."""
    X = np.asarray(X, dtype=float)
    if np.any((X < 0.0) | (X >= 1.0)):
        raise ValueError(f"X = {X} must lie in [0, 1)")
    return out((-np.log1p(-X) / K) ** (1.0 / n))


def nakamura_rate(X: ArrayLike, K_N: ArrayLike, n: float) -> float | np.ndarray:
    """Nakamura's differential form dX/dt = n K_N (1 - X) [-ln(1 - X)]^((n-1)/n)."""
    X = np.clip(np.asarray(X, dtype=float), 0.0, 1.0)
    u = -np.log1p(-np.minimum(X, 1.0 - 1e-300))
    return out(n * np.asarray(K_N, dtype=float) * (1.0 - X) * u ** ((n - 1.0) / n))


def nakamura_fraction(t: ArrayLike, T: ArrayLike, kin: CrystallizationKinetics) -> np.ndarray:
    """Nakamura's integral form on a sampled history: X_i = 1 - exp(-theta_i^n),
    theta_i = int_{t_0}^{t_i} K_N(T(s)) ds by the trapezoidal rule (X = 0 at t_0)."""
    t = np.asarray(t, dtype=float)
    theta = cumulative_trapezoid(np.asarray(kin.nakamura_K(T)), t, initial=0.0)
    return -np.expm1(-(theta**kin.n))


def nakamura_integrate(
    t_eval: ArrayLike,
    T_of_t,
    kin: CrystallizationKinetics,
    X_seed: float = 1e-9,
    rtol: float = 1e-10,
) -> np.ndarray:
    """Integrate the differential form dX/dt = n K_N(T(t)) (1-X) [-ln(1-X)]^((n-1)/n) from
    t_eval[0] (RK45 in u = -ln(1 - X), so that X near 1 keeps its digits).

    X = 0 is a fixed point of the differential form for n > 1, so it starts from X_seed, placed
    where the integral form reaches it on the same history: dtheta/dt = K_N(T(t)) is integrated
    up to theta_seed = (-ln(1 - X_seed))^(1/n) (an event), the differential form after it.
    """
    t_eval = np.asarray(t_eval, dtype=float)
    n = kin.n
    u_seed = -math.log1p(-X_seed)
    span = (t_eval[0], t_eval[-1])

    def k_n(t: float) -> float:
        return float(kin.nakamura_K(T_of_t(t)))

    def seeded(t: float, y: np.ndarray) -> float:
        return y[0] - u_seed ** (1.0 / n)

    seeded.terminal = True
    pre = solve_ivp(lambda t, y: [k_n(t)], span, [0.0], events=seeded, rtol=rtol, atol=1e-30)
    X = np.zeros_like(t_eval)
    if pre.t_events[0].size == 0:
        return X  # never reaches the seed: X < X_seed throughout
    t_s = float(pre.t_events[0][0])

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        return np.array([n * k_n(t) * max(y[0], 0.0) ** ((n - 1.0) / n)])

    after = t_eval >= t_s
    if np.any(after):
        sol = solve_ivp(
            rhs, (t_s, t_eval[-1]), [u_seed], t_eval=t_eval[after], rtol=rtol, atol=1e-14
        )
        if not sol.success:
            raise RuntimeError(f"Nakamura integration failed: {sol.message}")
        X[after] = -np.expm1(-sol.y[0])
    return X


def crystallization_peak_temperature(
    cooling_rate: float, kin: CrystallizationKinetics, T_start: float
) -> float:
    """Temperature (K) of the DSC crystallisation peak, max dX/dt, cooling at cooling_rate
    (K/s > 0) from the melt at T_start (K). Nakamura: theta(T) = (1/q) int_T^T_start K_N dT',
    dX/dt = n K_N(T) theta^(n-1) exp(-theta^n); located on a 0.01 K grid, then refined."""
    if not cooling_rate > 0.0:
        raise ValueError(f"cooling_rate = {cooling_rate} K/s must be > 0")
    if not kin.T_inf < T_start < kin.T_m0:
        raise ValueError(f"T_start = {T_start} K must lie in (T_inf, T_m0) of the kinetics")
    n = kin.n
    T = np.arange(T_start, kin.T_inf, -0.01)
    k = np.asarray(kin.nakamura_K(T))
    theta = cumulative_trapezoid(k, -T, initial=0.0) / cooling_rate
    i = int(np.argmax(n * k * theta ** (n - 1.0) * np.exp(-(theta**n))))

    def minus_rate(Tp: float) -> float:
        th = quad(lambda s: float(kin.nakamura_K(s)), Tp, T_start, epsabs=0.0, epsrel=1e-12)[0]
        th /= cooling_rate
        return -n * float(kin.nakamura_K(Tp)) * th ** (n - 1.0) * math.exp(-(th**n))

    lo, hi = T[min(i + 1, T.size - 1)], T[max(i - 1, 0)]
    res = minimize_scalar(minus_rate, bounds=(lo, hi), method="bounded", options={"xatol": 1e-6})
    return float(res.x)


__all__ = [
    "GAS_CONSTANT",
    "CrystallizationKinetics",
    "PA12_CRYSTALLIZATION",
    "avrami_fraction",
    "avrami_half_time",
    "avrami_time_to",
    "nakamura_rate",
    "nakamura_fraction",
    "nakamura_integrate",
    "crystallization_peak_temperature",
]
