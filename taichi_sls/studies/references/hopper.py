"""Viscous sintering of two equal cylinders: Hopper's exact plane Stokes solution.

Hopper 1984 (J. Am. Ceram. Soc. 67, C-262, "Coalescence of two equal cylinders: exact results
for creeping viscous plane flow driven by capillarity") and 1990 (J. Fluid Mech. 213, 349). The
outline is the image of the unit circle under z = c zeta / (1 + nu zeta^2), 0 < nu <= 1: nu = 1
is two touching circles of radius R0, nu -> 0 the final circle of radius sqrt(2) R0. The area
pi c^2 (1 + nu^2) / (1 - nu^2)^2 of that image is kept at 2 pi R0^2, which fixes c. Time enters as
tau = gamma t / (eta_N R0), eta_N the Newtonian shear viscosity (the solver's zero-yield Perzyna
fluid: eta/2, see viscous_decay_rate), and

    tau(nu) = (pi / (2 sqrt 2)) int_{nu^2}^{1} dm / (m sqrt(1 + m) K(m)),

K the complete elliptic integral of the first kind with parameter m (scipy.special.ellipk). At
late times d nu / d tau -> -nu / sqrt 2: the n = 2 mode of the final circle decaying at
viscous_decay_rate(2, gamma, eta_N, sqrt 2 R0).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike
from scipy import integrate, optimize, special

from ._util import out


def hopper_tau(nu: float) -> float:
    """Dimensionless time tau = gamma t / (eta_N R0) at which the outline has parameter nu
    (0 < nu <= 1; tau(1) = 0, tau -> infinity as nu -> 0). Integrated in s = ln m up to m = 1/2
    (the 1/m end becomes smooth) and in d = 1 - m from there (K(1 - d) by scipy's ellipkm1,
    accurate at K's logarithmic end)."""
    if not 0.0 < nu <= 1.0:
        raise ValueError(f"nu = {nu}: must lie in (0, 1]")
    m0 = nu * nu
    opts = {"epsabs": 0.0, "epsrel": 1e-11, "limit": 400}

    def in_s(s: float) -> float:
        m = math.exp(s)
        return 1.0 / (math.sqrt(1.0 + m) * special.ellipk(m))

    def in_d(d: float) -> float:
        return 1.0 / ((1.0 - d) * math.sqrt(2.0 - d) * special.ellipkm1(d)) if d > 0 else 0.0

    total = 0.0
    if m0 < 0.5:
        total += integrate.quad(in_s, math.log(m0), math.log(0.5), **opts)[0]
    d1 = 1.0 - max(m0, 0.5)
    if d1 > 0.0:
        total += integrate.quad(in_d, 0.0, d1, **opts)[0]
    return math.pi / (2.0 * math.sqrt(2.0)) * total


def hopper_nu(tau: float) -> float:
    """Inverse of :func:`hopper_tau` (tau(nu) decreases monotonically)."""
    if tau < 0.0:
        raise ValueError(f"tau = {tau}: must be >= 0")
    if tau == 0.0:
        return 1.0
    lo = -1.0  # ln nu
    while hopper_tau(math.exp(lo)) < tau:
        lo *= 2.0
    s = optimize.brentq(lambda x: hopper_tau(math.exp(x)) - tau, lo, 0.0, xtol=1e-15, rtol=1e-14)
    return math.exp(s)


def hopper_neck(nu: ArrayLike) -> float | np.ndarray:
    """Neck half-width over R0: r_n / R0 = sqrt(2) (1 - nu) / sqrt(1 + nu^2) (the image of
    zeta = 1, c / (1 + nu) with c = hopper_scale)."""
    nu = np.asarray(nu, dtype=float)
    return out(math.sqrt(2.0) * (1.0 - nu) / np.sqrt(1.0 + nu * nu))


def hopper_neck_at(tau: ArrayLike) -> float | np.ndarray:
    """r_n / R0 at the dimensionless times tau."""
    t = np.atleast_1d(np.asarray(tau, dtype=float))
    vals = np.array([hopper_neck(hopper_nu(float(x))) for x in t])
    return out(vals.reshape(np.shape(tau)))


def hopper_tau_at_neck(neck: float) -> float:
    """tau at which r_n / R0 first equals ``neck`` (0 <= neck < sqrt 2)."""
    # hopper_neck(nu) = neck is a quadratic in nu: (2 - k^2) nu^2 - 4 nu + (2 - k^2) = 0
    k2 = neck * neck
    a = 2.0 - k2
    nu = (2.0 - math.sqrt(4.0 - a * a)) / a
    return hopper_tau(nu)


def hopper_scale(nu: float, R0: float) -> float:
    """c of the map z = c zeta / (1 + nu zeta^2) for total area 2 pi R0^2."""
    return math.sqrt(2.0) * R0 * (1.0 - nu * nu) / math.sqrt(1.0 + nu * nu)


def hopper_outline(
    nu: float, R0: float, n: int = 720, center: tuple[float, float] = (0.0, 0.0)
) -> np.ndarray:
    """The outline at parameter nu as n points (n, 2) counter-clockwise, equally spaced in arc
    length, the line of centres along x and the neck on x = center[0] (the map rotated by -90
    degrees: its lobes lie along the imaginary axis). At nu = 1 it is two circles of radius R0
    touching at ``center``."""
    c = hopper_scale(nu, R0)
    th = np.linspace(0.0, 2.0 * np.pi, 40 * n + 1)
    # for nu near 1 the lobes are the images of |theta -/+ pi/2| of order 1 - nu: sample there
    # as densely (theta = pi/2 + (1 - nu) tan u)
    u = np.linspace(-0.5 * np.pi, 0.5 * np.pi, 20 * n + 2)[1:-1]
    lobe = (1.0 - nu) * np.tan(u)
    lobe = lobe[np.abs(lobe) < 0.5 * np.pi]
    th = np.unique(np.concatenate([th, 0.5 * np.pi + lobe, 1.5 * np.pi + lobe]))
    zeta = np.exp(1j * th)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = -1j * c * zeta / (1.0 + nu * zeta * zeta)
    if nu == 1.0:  # the limit: two circles (the map degenerates)
        phi = np.linspace(0.0, 2.0 * np.pi, 20 * n + 1)
        right = R0 + R0 * np.exp(1j * (phi - np.pi))
        z = np.concatenate([right, -right])
    z = z[np.isfinite(z)]
    s = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(z)))])
    si = np.linspace(0.0, s[-1], n + 1)[:-1]
    zr = np.interp(si, s, z.real) + 1j * np.interp(si, s, z.imag)
    return np.stack([zr.real + center[0], zr.imag + center[1]], axis=1)


def polygon_area(v: np.ndarray) -> float:
    """Signed area of a closed polygon (shoelace; positive counter-clockwise)."""
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
