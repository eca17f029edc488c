"""Capillarity of a 2D disc (cylinder): Laplace pressure, viscous and inviscid shape modes; the
sphere's Laplace pressure and inviscid shape modes."""

from __future__ import annotations

import math


def disc_curvature(R: float) -> float:
    """Curvature of a circle of radius R: kappa = 1/R (1/m)."""
    return 1.0 / R


def laplace_pressure_2d(gamma: float, R: float) -> float:
    """Young-Laplace pressure jump of a 2D disc (one principal curvature): dp = gamma/R (Pa).

    Source: Young-Laplace equation dp = gamma kappa, kappa = 1/R (de Gennes, Brochard-Wyart &
    Quere 2004, Capillarity and Wetting Phenomena, ch. 1).
    """
    return gamma / R


def laplace_pressure_3d(gamma: float, R: float) -> float:
    """Young-Laplace pressure jump of a sphere (two principal curvatures 1/R): dp = 2 gamma/R
    (Pa; same source)."""
    return 2.0 * gamma / R


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


def viscous_decay_rate_sphere(n: int, gamma: float, eta_N: float, R: float) -> float:
    """Decay rate of shape mode n >= 2 (Legendre P_n) of a viscous sphere in vacuum, Stokes limit
    (1/s): rate = n (n + 2)(2n + 1) gamma / (2 (2n^2 + 4n + 3) eta_N R); n = 2: 20 gamma /
    (19 eta_N R).

    Derived as :func:`viscous_decay_rate`, in 3D: Lamb's interior Stokes solution (Lamb 1932,
    Hydrodynamics, sec. 336) with pressure the solid harmonic A r^n P_n and potential part
    B r^n P_n; zero shear stress at r = R gives B = -C R^2 n (n + 2) / ((n + 1)(n - 1)),
    C = A / (2 eta_N (2n + 3)); then sigma_rr(R) = -2 eta_N C R^n (2n^2 + 4n + 3) / (n + 1) P_n
    balances the curvature's -gamma (n - 1)(n + 2) eps P_n / R, and R d eps/dt = u_r(R) =
    -n C R^(n+1) (2n + 1) / ((n + 1)(n - 1)). Checked for n = 2 against the slow relaxation of a
    drop of viscosity ratio lambda (Rallison 1984, Annu. Rev. Fluid Mech. 16: rate
    40 (lambda + 1) gamma / ((2 lambda + 3)(19 lambda + 16) mu R)) as lambda -> infinity:
    20 gamma / (19 eta R).
    """
    return n * (n + 2) * (2 * n + 1) * gamma / (2.0 * (2 * n * n + 4 * n + 3) * eta_N * R)


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


def inviscid_sphere_omega(n: int, gamma: float, rho: float, R: float) -> float:
    """Angular frequency of shape mode n (Legendre P_n) of an inviscid sphere (no outer fluid).

    omega^2 = n (n - 1) (n + 2) gamma / (rho R^3); n = 2: 8 gamma / (rho R^3).
    Source: Rayleigh 1879 (Proc. R. Soc. 29, 71-97); Lamb 1932, Hydrodynamics, sec. 275.
    """
    return math.sqrt(n * (n - 1) * (n + 2) * gamma / (rho * R**3))
