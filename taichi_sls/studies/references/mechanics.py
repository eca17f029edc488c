"""Elastic bars: the fixed-free bar in its first axial mode and a manufactured large-deformation
solution of a fixed-fixed bar (Steffen, Kirby & Berzins 2008)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ._util import out


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
    return out(v0 * np.sin(np.pi * x / (2.0 * L)) * np.cos(w1 * t))


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
    return out(v0 / w1 * np.sin(np.pi * x / (2.0 * L)) * np.sin(w1 * t))


def bar_com_velocity(t: ArrayLike, L: float, E: float, rho: float, v0: float) -> float | np.ndarray:
    """Centre-of-mass velocity of the first-mode fixed-free bar (see :func:`bar_velocity`).

    v_cm(t) = (1/L) int_0^L v dx = (2 v0/pi) cos(w1 t), w1 = pi/(2L) sqrt(E/rho).
    Source: Bardenhagen & Kober 2004 (CMES 5), Bardenhagen 2002 (J. Comput. Phys. 180).
    """
    t = np.asarray(t, dtype=float)
    return out(2.0 * v0 / np.pi * np.cos(bar_omega(L, E, rho) * t))


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
    return out(A * np.sin(2.0 * np.pi * X / L) * np.sin(np.pi * c * t / L))


def steffen_velocity(
    X: ArrayLike, t: ArrayLike, L: float, A: float, E: float, rho: float
) -> float | np.ndarray:
    """du/dt of :func:`steffen_displacement`: A w sin(2 pi X/L) cos(w t), w = pi c/L."""
    X = np.asarray(X, dtype=float)
    t = np.asarray(t, dtype=float)
    w = math.pi * math.sqrt(E / rho) / L
    return out(A * w * np.sin(2.0 * np.pi * X / L) * np.cos(w * t))


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
    return out(u * (c2 * k * k / F - w * w))
