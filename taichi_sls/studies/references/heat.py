"""Heat conduction: the erf half-space and the spreading 2D Gaussian."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ._util import erf, out


def erf_slab(x: ArrayLike, t: ArrayLike, T0: float, Ts: float, alpha: float) -> float | np.ndarray:
    """Semi-infinite solid x >= 0, initially at T0, surface x=0 held at Ts from t=0 (t > 0).

    T(x,t) = Ts + (T0 - Ts) erf(x / (2 sqrt(alpha t))), alpha = k/(rho c).
    Source: Carslaw & Jaeger 1959, Conduction of Heat in Solids, sec. 2.5.
    """
    x = np.asarray(x, dtype=float)
    t = np.asarray(t, dtype=float)
    return out(Ts + (T0 - Ts) * erf(x / (2.0 * np.sqrt(alpha * t))))


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
    return out(E_per_length / (rho_c * 2.0 * np.pi * s2) * np.exp(-r2 / (2.0 * s2)))
