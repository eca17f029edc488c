"""The Stefan melting problem with a linear mushy zone (three-zone similarity solution)."""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from ._util import erf, erfcx, erfcx_scalar, out


class StefanSlab(NamedTuple):
    """The melting slab of :func:`mushy_stefan`: initial and surface temperature, the mushy
    range [T_c, T_m], and k, rho, c, L equal in every phase (SI; temperatures in any one unit)."""

    T_init: float
    T_s: float
    T_c: float
    T_m: float
    k: float
    rho: float
    c: float
    L: float


def mushy_enthalpy(T: ArrayLike, T_c: float, T_m: float, c: float, L: float) -> float | np.ndarray:
    """Specific enthalpy H(T) = c T + L (1 - xi_s(T)) (J/kg), xi_s = clip(1 - (T-T_c)/(T_m-T_c)).

    Latent heat L released linearly over [T_c, T_m] (solidus T_c, liquidus T_m).
    """
    T = np.asarray(T, dtype=float)
    xi_s = np.clip(1.0 - (T - T_c) / (T_m - T_c), 0.0, 1.0)
    return out(c * T + L * (1.0 - xi_s))


def _bisect(f, lo: float, hi: float) -> tuple[float, float]:
    """Bracket of the root of a decreasing f (f(lo) > 0 >= f(hi)), narrowed to round-off."""
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if f(mid) > 0.0:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 2e-16 * hi:
            break
    return lo, hi


@functools.lru_cache(maxsize=256)
def _mushy_lambdas(
    T_init: float, T_s: float, T_c: float, T_m: float, nu: float
) -> tuple[float, float]:
    dTl, dTm, dTs = T_s - T_m, T_m - T_c, T_c - T_init
    nu2 = nu * nu

    def front_c(lm: float) -> tuple[float, float] | None:
        """Given lam_m: (lam_c, b) where the mushy profile reaches T_c, or None if it never does."""
        b = dTl * math.exp(-lm * lm) / (nu * math.erf(lm))
        ex_m = erfcx_scalar(nu * lm)
        if b * ex_m <= dTm:
            return None
        logq = math.log(ex_m - dTm / b)

        def g(lc: float) -> float:  # decreasing in lc, g(lm) > 0
            return math.log(erfcx_scalar(nu * lc)) - nu2 * (lc * lc - lm * lm) - logq

        lo, hi = lm, lm + 1.0
        while g(hi) > 0.0:
            lo, hi = hi, lm + 2.0 * (hi - lm)
        lo, hi = _bisect(g, lo, hi)
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
            + math.log(erfcx_scalar(lc))
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
    lo, hi = _bisect(F, lo, hi)
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
    t: ArrayLike, slab: StefanSlab
) -> tuple[float | np.ndarray, float | np.ndarray]:
    """Liquidus and solidus front positions (X_m, X_c) = 2 (lam_m, lam_c) sqrt(alpha t) of
    :func:`mushy_stefan`, alpha = k/(rho c)."""
    T_init, T_s, T_c, T_m, k, rho, c, L = slab
    lm, lc = mushy_stefan_lambdas(T_init, T_s, T_c, T_m, c, L)
    s = 2.0 * np.sqrt(k / (rho * c) * np.asarray(t, dtype=float))
    return out(lm * s), out(lc * s)


def mushy_stefan(x: ArrayLike, t: ArrayLike, slab: StefanSlab) -> float | np.ndarray:
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
    T_init, T_s, T_c, T_m, k, rho, c, L = slab
    _mushy_check(T_init, T_s, T_c, T_m, L)
    lm, lc = mushy_stefan_lambdas(T_init, T_s, T_c, T_m, c, L)
    nu = math.sqrt(1.0 + L / (c * (T_m - T_c)))
    x, t = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(t, dtype=float))
    eta = x / (2.0 * np.sqrt(k / (rho * c) * t))
    liq = eta < lm
    sol = eta > lc
    mush = ~(liq | sol)
    T = np.empty(eta.shape)
    T[liq] = T_s - (T_s - T_m) * erf(eta[liq]) / math.erf(lm)
    b = (T_s - T_m) * math.exp(-lm * lm) / (nu * math.erf(lm))  # = B exp(-nu^2 lam_m^2)
    em = eta[mush]
    T[mush] = T_m - b * (
        erfcx_scalar(nu * lm) - erfcx(nu * em) * np.exp(nu * nu * (lm * lm - em * em))
    )
    es = eta[sol]
    T[sol] = T_init + (T_c - T_init) * erfcx(es) / erfcx_scalar(lc) * np.exp(lc * lc - es * es)
    return out(T)
