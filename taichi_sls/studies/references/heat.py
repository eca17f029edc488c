"""Heat conduction: the erf half-space, the spreading 2D Gaussian, and a stationary Gaussian
laser spot absorbed with depth in an insulated half-space (3D)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import quad
from scipy.special import erfcx

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


def gaussian_spot_halfspace(
    radius: float,
    depth: float,
    t: float,
    power: float,
    r0: float,
    eta: float,
    thickness: float,
    k: float,
    rho_c: float,
) -> float:
    """Temperature rise (K) at ``radius`` from the axis and ``depth`` below the surface of an
    insulated half-space, heated from t = 0 by the stationary source (W/m^3)

        q(r, z) = power 2 / (pi r0^2) exp(-2 r^2 / r0^2) exp(-z / eta) / eta,  0 <= z <= thickness

    (eq. 31's spot and depth law: power = 0.6 A P, the absorbed power over an infinite depth).
    The instantaneous point source in an infinite solid, exp(-R^2 / 4 alpha s) / (rho c (4 pi
    alpha s)^(3/2)) (Carslaw & Jaeger 1959, Conduction of Heat in Solids, sec. 10.2), and its
    image in the plane z = 0 (the insulated surface, sec. 10.10) give, after the Gaussian's
    integral over the plane in closed form (the convolution of two Gaussians, variances
    r0^2 / 4 and 2 alpha s per axis),

        dT = power 2 / (pi rho c sqrt(4 pi alpha)) int_0^t ds / sqrt(s)
             exp(-2 radius^2 / (r0^2 + 8 alpha s)) / (r0^2 + 8 alpha s) g(s),
        g(s) = int_0^thickness exp(-z / eta) / eta [G(depth - z) + G(depth + z)] dz,
        G(u) = exp(-u^2 / (4 alpha s)),

    g in closed form by erfc, the time integral by quadrature (s = u^2, smooth). A surface
    source (eta -> 0, thickness infinite) at depth 0 gives the centre rise sqrt(2) power /
    (pi^(3/2) k r0) arctan(sqrt(8 alpha t) / r0), whose steady value power / (sqrt(2 pi) k r0)
    is the stationary Gaussian source's (Carslaw & Jaeger sec. 10.5 for a disc source has the
    same form; e.g. Cline & Anthony 1977, J. Appl. Phys. 48, 3895, at zero speed)."""
    alpha = k / rho_c

    def g(s: float) -> float:
        w = 2.0 * math.sqrt(alpha * s)
        total = 0.0
        for a in (depth, -depth):  # the source's own term and its image
            b = a - 2.0 * alpha * s / eta  # exp(-z/eta - (z - a)^2 / w^2) peaks at z = b
            # exp(-a/eta + alpha s/eta^2) [erfc(-b/w) - erfc((thickness - b)/w)], each term
            # scaled by erfcx where its argument is >= 0 (the exponents then -a^2/w^2 and
            # -(thickness - a)^2/w^2 - thickness/eta, no overflow for a thin source)
            x0, x1 = -b / w, (thickness - b) / w
            if x0 >= 0.0:
                near = math.exp(-((a / w) ** 2)) * erfcx(x0)
            else:
                near = math.exp(-a / eta + alpha * s / eta**2) * math.erfc(x0)
            far = math.exp(-(((thickness - a) / w) ** 2) - thickness / eta) * erfcx(x1)
            total += 0.5 * w * math.sqrt(math.pi) / eta * (near - far)
        return total

    def integrand(u: float) -> float:
        s = u * u
        if s == 0.0:
            return 0.0
        spread = r0 * r0 + 8.0 * alpha * s
        return 2.0 * math.exp(-2.0 * radius**2 / spread) / spread * g(s)

    integral, _ = quad(integrand, 0.0, math.sqrt(t), epsabs=0.0, epsrel=1e-10, limit=200)
    return power * 2.0 / (math.pi * rho_c * math.sqrt(4.0 * math.pi * alpha)) * integral
