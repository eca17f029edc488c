"""Self-consistency checks of the analytic reference solutions in taichi_sls.references."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from taichi_sls.studies import references as ref

# ---------------------------------------------------------------------------------------------
# 1. bar
# ---------------------------------------------------------------------------------------------

BAR = {"L": 1.0, "E": 100.0, "rho": 1.0, "v0": 0.1}


def test_bar_com_velocity_is_mean_of_velocity():
    x = np.linspace(0.0, BAR["L"], 20001)
    for t in (0.0, 0.037, 0.21):
        v = ref.bar_velocity(x, t, **BAR)
        mean = np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(x)) / BAR["L"]
        assert mean == pytest.approx(ref.bar_com_velocity(t, **BAR), abs=1e-9)
    assert ref.bar_com_velocity(0.0, **BAR) == pytest.approx(2 * BAR["v0"] / math.pi)


def test_bar_displacement_solves_wave_equation():
    L, E, rho = BAR["L"], BAR["E"], BAR["rho"]
    x = np.array([0.2, 0.5, 0.9])
    t, h, dt = 0.13, 1e-4, 1e-5
    u = ref.bar_displacement(x, t, **BAR)
    u_xx = ref.bar_displacement(x + h, t, **BAR) - 2 * u + ref.bar_displacement(x - h, t, **BAR)
    u_xx /= h**2
    u_tt = ref.bar_displacement(x, t + dt, **BAR) - 2 * u + ref.bar_displacement(x, t - dt, **BAR)
    u_tt /= dt**2
    np.testing.assert_allclose(rho * u_tt, E * u_xx, rtol=1e-5)
    v_fd = (ref.bar_displacement(x, t + dt, **BAR) - ref.bar_displacement(x, t - dt, **BAR)) / (
        2 * dt
    )
    np.testing.assert_allclose(v_fd, ref.bar_velocity(x, t, **BAR), rtol=1e-7)
    # fixed end, free end (zero strain), initial state
    assert ref.bar_displacement(0.0, t, **BAR) == 0.0
    dudx_L = (ref.bar_displacement(L + h, t, **BAR) - ref.bar_displacement(L - h, t, **BAR)) / (
        2 * h
    )
    assert abs(dudx_L) < 1e-5 * BAR["v0"] / ref.bar_omega(L, E, rho)
    np.testing.assert_allclose(ref.bar_displacement(x, 0.0, **BAR), 0.0)
    np.testing.assert_allclose(ref.bar_velocity(x, 0.0, **BAR), 0.1 * np.sin(np.pi * x / 2))


# ---------------------------------------------------------------------------------------------
# 2. heat conduction
# ---------------------------------------------------------------------------------------------


def test_erf_slab():
    T0, Ts, a = 300.0, 1000.0, 1e-5
    t = 0.2
    assert ref.erf_slab(0.0, t, T0, Ts, a) == Ts
    assert ref.erf_slab(1.0, t, T0, Ts, a) == pytest.approx(T0)
    x, h, dt = np.array([1e-4, 1e-3, 3e-3]), 1e-6, 1e-5
    T = ref.erf_slab(x, t, T0, Ts, a)
    T_xx = (ref.erf_slab(x + h, t, T0, Ts, a) - 2 * T + ref.erf_slab(x - h, t, T0, Ts, a)) / h**2
    T_t = (ref.erf_slab(x, t + dt, T0, Ts, a) - ref.erf_slab(x, t - dt, T0, Ts, a)) / (2 * dt)
    np.testing.assert_allclose(T_t, a * T_xx, rtol=1e-5)


def test_gaussian_spread_2d_energy_and_pde():
    E, rho_c, a, s0 = 2.0, 3e6, 1e-5, 2e-5
    t = 1e-4
    xs = np.linspace(-5e-4, 5e-4, 1001)
    X, Y = np.meshgrid(xs, xs)
    dT = ref.gaussian_spread_2d(X**2 + Y**2, t, E, rho_c, a, s0)
    assert rho_c * dT.sum() * (xs[1] - xs[0]) ** 2 == pytest.approx(E, rel=1e-6)
    # 2D heat equation, Cartesian finite differences at a few points
    x, y, h, dt = np.array([0.0, 1e-5, 4e-5]), np.array([0.0, 2e-5, -1e-5]), 1e-7, 1e-8

    def f(xx, yy, tt):
        return ref.gaussian_spread_2d(xx**2 + yy**2, tt, E, rho_c, a, s0)

    lap = (
        f(x + h, y, t) + f(x - h, y, t) + f(x, y + h, t) + f(x, y - h, t) - 4 * f(x, y, t)
    ) / h**2
    T_t = (f(x, y, t + dt) - f(x, y, t - dt)) / (2 * dt)
    np.testing.assert_allclose(T_t, a * lap, rtol=1e-4)
    assert ref.gaussian_spread_2d(0.0, 0.0, E, rho_c, a, s0) == pytest.approx(
        E / (rho_c * 2 * math.pi * s0**2)
    )


# ---------------------------------------------------------------------------------------------
# 3. Perzyna
# ---------------------------------------------------------------------------------------------

MAT = {"mu": 26e9, "sigma_Y": 100e6, "H": 2e9}


def test_perzyna_relaxation_ratio_matches_discrete_loop():
    mu, sY, H = MAT["mu"], MAT["sigma_Y"], MAT["H"]
    eta, dt = 2 * mu * 1e-6, 1e-7
    tau = eta / (2 * mu)
    r = ref.perzyna_relaxation_ratio(dt, tau, mu, H)
    s, a = 3.0 * sY, 0.01  # fixed-strain trial state above yield
    f0 = s - math.sqrt(2 / 3) * (sY + H * a)
    f_prev = f0
    for n in range(1, 11):
        s, a, _ = ref.perzyna_step(s, a, dt, mu, sY, H, eta)
        f = s - math.sqrt(2 / 3) * (sY + H * a)
        assert f / f_prev == pytest.approx(r, rel=1e-13, abs=0)
        assert f == pytest.approx(ref.perzyna_relaxation(n, f0, dt, tau, mu, H), rel=1e-12)
        f_prev = f


def test_perzyna_relaxation_continuous_limit():
    mu, H, tau, f0 = MAT["mu"], MAT["H"], 1e-6, 5e7
    t = 2e-6
    fc = ref.perzyna_relaxation_continuous(t, f0, tau, mu, H)
    errs = []
    for n in (100, 200, 400):
        errs.append(abs(ref.perzyna_relaxation(n, f0, t / n, tau, mu, H) - fc))
    assert errs[0] / errs[1] == pytest.approx(2.0, rel=0.05)
    assert errs[1] / errs[2] == pytest.approx(2.0, rel=0.05)
    assert errs[2] < 1e-2 * fc


def test_perzyna_shear_closed_form_consistency():
    mu, sY, H = MAT["mu"], MAT["sigma_Y"], MAT["H"]
    eta, gd = 2 * mu * 1e-6, 1e3
    S = math.sqrt(2) * mu * gd
    t_y = math.sqrt(2 / 3) * sY / S
    t = np.linspace(0.0, t_y + 20e-6, 2001)
    s, a = ref.perzyna_shear_constant_rate(t, gd, mu, sY, H, eta)
    el = t <= t_y
    np.testing.assert_allclose(s[el], S * t[el], rtol=1e-14)
    np.testing.assert_array_equal(a[el], 0.0)
    # ODE: d||s||/dt = S - 2 mu gamma_dot, gamma_dot = f/eta, alpha_dot = sqrt(2/3) gamma_dot
    tt, dt = t_y + np.array([0.3e-6, 2e-6, 15e-6]), 1e-10
    s_p, a_p = ref.perzyna_shear_constant_rate(tt + dt, gd, mu, sY, H, eta)
    s_m, a_m = ref.perzyna_shear_constant_rate(tt - dt, gd, mu, sY, H, eta)
    s0, a0 = ref.perzyna_shear_constant_rate(tt, gd, mu, sY, H, eta)
    f = s0 - math.sqrt(2 / 3) * (sY + H * a0)
    gamma_dot = f / eta
    np.testing.assert_allclose((a_p - a_m) / (2 * dt), math.sqrt(2 / 3) * gamma_dot, rtol=1e-5)
    np.testing.assert_allclose((s_p - s_m) / (2 * dt), S - 2 * mu * gamma_dot, rtol=1e-5)
    # late-time hardening slope and rate-independent limit
    k = (2 * mu + 2 * H / 3) / eta
    assert f[-1] == pytest.approx(S / k, rel=1e-6)
    s_ri, _ = ref.perzyna_shear_constant_rate(t[-1], gd, mu, sY, H, 0.0)
    a_ri = math.sqrt(2 / 3) * S * (t[-1] - t_y) / (2 * mu + 2 * H / 3)
    assert s_ri == pytest.approx(math.sqrt(2 / 3) * (sY + H * a_ri), rel=1e-12)


def test_perzyna_shear_discrete_first_order_convergence():
    mu, sY, H = MAT["mu"], MAT["sigma_Y"], MAT["H"]
    tau = 1e-6
    eta = 2 * mu * tau
    t_y = tau  # choose the rate so that yield happens on a step boundary for every dt
    gd = math.sqrt(2 / 3) * sY / (math.sqrt(2) * mu * t_y)
    t_end = 4 * tau
    s_ex, a_ex = ref.perzyna_shear_constant_rate(t_end, gd, mu, sY, H, eta)
    es, ea = [], []
    for n in (40, 80, 160, 320):
        t, s, a = ref.perzyna_shear_discrete(n, t_end / n, gd, mu, sY, H, eta)
        assert t[-1] == pytest.approx(t_end)
        es.append(abs(s[-1] - s_ex))
        ea.append(abs(a[-1] - a_ex))
    for e in (es, ea):
        ratios = [e[i] / e[i + 1] for i in range(len(e) - 1)]
        assert all(1.8 <= q <= 2.2 for q in ratios), ratios
    assert es[-1] < 1e-2 * s_ex


def test_perzyna_step_elastic_and_rate_independent():
    mu, sY, H = MAT["mu"], MAT["sigma_Y"], MAT["H"]
    assert ref.perzyna_step(0.5 * sY, 0.0, 1e-7, mu, sY, H, 1e3) == (0.5 * sY, 0.0, 0.0)
    s, a, _ = ref.perzyna_step(2 * sY, 0.0, 1e-7, mu, sY, H, 0.0)  # radial return: on yield
    assert s == pytest.approx(math.sqrt(2 / 3) * (sY + H * a), rel=1e-14)


# ---------------------------------------------------------------------------------------------
# 4. mushy-zone Stefan problem
# ---------------------------------------------------------------------------------------------

# Ti-6Al-4V-like, narrow mushy range (nu ~ 3.3) and a wide one (nu ~ 1.3)
_PROPS = {"T_init": 300.0, "T_s": 2500.0, "k": 20.0, "rho": 4000.0, "c": 600.0}
STEFAN = [
    {**_PROPS, "T_c": 1878.0, "T_m": 1928.0, "L": 2.9e5},
    {**_PROPS, "T_c": 1000.0, "T_m": 1800.0, "L": 3e5},
]
T_EVAL = 1e-3


def _alpha(p):
    return p["k"] / (p["rho"] * p["c"])


@pytest.mark.parametrize("L", [0.0, 1e-6])
def test_mushy_stefan_reduces_to_erf_slab(L):
    p = dict(STEFAN[0], L=L)
    slab = ref.StefanSlab(**p)
    x = np.linspace(0.0, 6e-4, 301)
    T = ref.mushy_stefan(x, T_EVAL, slab)
    T_erf = ref.erf_slab(x, T_EVAL, p["T_init"], p["T_s"], _alpha(p))
    np.testing.assert_allclose(T, T_erf, rtol=0, atol=1e-8 * (p["T_s"] - p["T_init"]))


@pytest.mark.parametrize("p", STEFAN)
def test_mushy_stefan_satisfies_pde(p):
    slab = ref.StefanSlab(**p)
    Xm, Xc = ref.mushy_stefan_fronts(T_EVAL, slab)
    far = Xc + 4 * math.sqrt(_alpha(p) * T_EVAL)
    pts = [f * Xm for f in (0.2, 0.5, 0.8)]
    pts += [Xm + f * (Xc - Xm) for f in (0.2, 0.5, 0.8)]
    pts += [Xc + f * (far - Xc) for f in (0.05, 0.3, 0.6)]
    x = np.array(pts)
    h = 1e-3 * min(Xm, Xc - Xm)
    dt = 1e-4 * T_EVAL

    def T(xx, tt):
        return ref.mushy_stefan(xx, tt, slab)

    def H(TT):
        return ref.mushy_enthalpy(TT, p["T_c"], p["T_m"], p["c"], p["L"])

    lhs = p["rho"] * (H(T(x, T_EVAL + dt)) - H(T(x, T_EVAL - dt))) / (2 * dt)
    rhs = p["k"] * (T(x + h, T_EVAL) - 2 * T(x, T_EVAL) + T(x - h, T_EVAL)) / h**2
    np.testing.assert_allclose(lhs, rhs, rtol=1e-4)


@pytest.mark.parametrize("p", STEFAN)
def test_mushy_stefan_front_continuity(p):
    slab = ref.StefanSlab(**p)
    Xm, Xc = ref.mushy_stefan_fronts(T_EVAL, slab)
    assert 0 < Xm < Xc
    tol = 1e-9 * (p["T_s"] - p["T_init"])
    for X, TX in ((Xm, p["T_m"]), (Xc, p["T_c"])):
        T_lr = ref.mushy_stefan(np.array([X * (1 - 1e-13), X * (1 + 1e-13)]), T_EVAL, slab)
        np.testing.assert_allclose(T_lr, TX, rtol=0, atol=tol)
        # flux continuity: one-sided gradients agree
        h = 1e-5 * X
        g_l = (ref.mushy_stefan(X, T_EVAL, slab) - ref.mushy_stefan(X - h, T_EVAL, slab)) / h
        g_r = (ref.mushy_stefan(X + h, T_EVAL, slab) - ref.mushy_stefan(X, T_EVAL, slab)) / h
        assert g_l == pytest.approx(g_r, rel=1e-3)
    # fronts scale with sqrt(t) and the boundary / far-field values hold
    Xm4, Xc4 = ref.mushy_stefan_fronts(4 * T_EVAL, slab)
    assert (Xm4, Xc4) == pytest.approx((2 * Xm, 2 * Xc), rel=1e-14)
    assert ref.mushy_stefan(0.0, T_EVAL, slab) == p["T_s"]
    assert ref.mushy_stefan(1.0, T_EVAL, slab) == pytest.approx(p["T_init"], abs=1e-12)


def _gauss(f, a, b, n_sub=16, n=32):
    xg, wg = np.polynomial.legendre.leggauss(n)
    edges = np.linspace(a, b, n_sub + 1)
    tot = 0.0
    for lo, hi in itertools.pairwise(edges):
        xs = 0.5 * (hi - lo) * xg + 0.5 * (hi + lo)
        tot += 0.5 * (hi - lo) * np.sum(wg * f(xs))
    return tot


@pytest.mark.parametrize("p", STEFAN)
def test_mushy_stefan_global_energy(p):
    slab = ref.StefanSlab(**p)
    t = T_EVAL
    Xm, Xc = ref.mushy_stefan_fronts(t, slab)
    H0 = ref.mushy_enthalpy(p["T_init"], p["T_c"], p["T_m"], p["c"], p["L"])

    def dE(xx):
        TT = ref.mushy_stefan(xx, t, slab)
        return p["rho"] * (ref.mushy_enthalpy(TT, p["T_c"], p["T_m"], p["c"], p["L"]) - H0)

    far = Xc + 40 * math.sqrt(_alpha(p) * t)
    gained = _gauss(dE, 0.0, Xm) + _gauss(dE, Xm, Xc) + _gauss(dE, Xc, far)

    def q_surface(tt):  # -k dT/dx at x=0, 4th-order one-sided difference
        X_m = ref.mushy_stefan_fronts(tt, slab)[0]
        h = 1e-3 * X_m
        T = [ref.mushy_stefan(j * h, tt, slab) for j in range(5)]
        dTdx = (-25 * T[0] + 48 * T[1] - 36 * T[2] + 16 * T[3] - 3 * T[4]) / (12 * h)
        return -p["k"] * dTdx

    # int_0^t q dt' with t' = s^2 (removes the 1/sqrt(t') singularity)
    supplied = _gauss(lambda s: np.array([q_surface(si**2) * 2 * si for si in s]), 0, math.sqrt(t))
    assert gained == pytest.approx(supplied, rel=1e-5)


def test_mushy_stefan_rejects_bad_temperatures():
    slab = ref.StefanSlab(**dict(STEFAN[0], T_init=1900.0))
    with pytest.raises(ValueError):
        ref.mushy_stefan(0.0, 1.0, slab)


# ---------------------------------------------------------------------------------------------
# 5. capillarity
# ---------------------------------------------------------------------------------------------


def test_viscous_sphere_decay_is_the_viscous_drop_limit():
    """The l = 2 sphere's Stokes decay, 20 gamma / (19 eta R), is the limit of a drop of
    viscosity lambda mu in a fluid mu (Rallison 1984: 40 (lambda + 1) gamma / ((2 lambda + 3)
    (19 lambda + 16) mu R)) as the outer fluid vanishes, lambda -> infinity at fixed lambda mu."""
    gamma, R, eta = 0.0363, 20e-6, 0.3
    lam = 1e9
    mu = eta / lam
    drop = 40 * (lam + 1) * gamma / ((2 * lam + 3) * (19 * lam + 16) * mu * R)
    assert ref.viscous_decay_rate_sphere(2, gamma, eta, R) == pytest.approx(drop, rel=1e-8)
    assert ref.viscous_decay_rate_sphere(2, gamma, eta, R) == pytest.approx(
        20 * gamma / (19 * eta * R), rel=1e-14
    )
    # mode 3: 3 * 5 * 7 / (2 * 33)
    assert ref.viscous_decay_rate_sphere(3, gamma, eta, R) == pytest.approx(
        105 / 66 * gamma / (eta * R), rel=1e-14
    )


def test_capillary_formulas():
    gamma, R, eta, rho = 1.5, 2e-5, 5e-3, 4000.0
    assert ref.disc_curvature(R) == pytest.approx(5e4)
    assert ref.laplace_pressure_2d(gamma, R) == pytest.approx(gamma * ref.disc_curvature(R))
    assert ref.viscous_decay_rate(2, gamma, eta, R) == pytest.approx(2 * gamma / (2 * eta * R))
    assert ref.viscous_decay_rate(4, gamma, eta, R) == pytest.approx(
        2 * ref.viscous_decay_rate(2, gamma, eta, R)
    )
    assert ref.inviscid_drop_omega(2, gamma, rho, R) == pytest.approx(
        math.sqrt(6 * gamma / (rho * R**3))
    )
    assert ref.inviscid_drop_omega(1, gamma, rho, R) == 0.0


def test_viscous_decay_rate_from_stokes_modes():
    """Solve the linear plane-Stokes boundary-value problem numerically for mode n."""
    gamma, eta, R = 1.5, 5e-3, 2e-5
    for n in (2, 3, 5):
        # unknowns A, B of psi = (A r^n + B r^(n+2)) sin(n theta), per unit eps
        M = np.array(
            [
                [2 * n * (n - 1) * R ** (n - 2), 2 * n * (n + 1) * R**n],  # sigma_r_theta = 0
                # sigma_rr = -p + 2 eta du_r/dr, p = 4 eta (n+1) B r^n cos(n theta)
                [2 * eta * n * (n - 1) * R ** (n - 2), eta * (2 * n - 4) * (n + 1) * R**n],
            ]
        )
        rhs = np.array([0.0, -gamma * (n * n - 1) / R])  # sigma_rr = -gamma kappa'
        A, B = np.linalg.solve(M, rhs)
        rate = -n * (A * R ** (n - 1) + B * R ** (n + 1)) / R  # R d eps/dt = u_r(R)
        assert rate == pytest.approx(ref.viscous_decay_rate(n, gamma, eta, R), rel=1e-10)


# ---- Hopper's coalescence of two equal cylinders


def test_hopper_tau_against_a_direct_quadrature():
    """tau(nu) integrated in ln m (the module's form) against quad in m itself."""
    from scipy import integrate, special

    for nu in (0.999, 0.9, 0.5, 0.1, 0.01):
        q = integrate.quad(
            lambda x: 1 / (x * math.sqrt(1 + x) * special.ellipk(x)), nu * nu, 1, limit=400
        )[0]
        assert ref.hopper_tau(nu) == pytest.approx(math.pi / (2 * math.sqrt(2)) * q, rel=1e-8)


@pytest.mark.parametrize("nu", [0.95, 0.69, 0.3, 0.05])
def test_hopper_outline_keeps_the_area(nu):
    """Area of the image of the unit circle: 2 pi R0^2 for every nu (the scale c); the neck is
    the outline's narrowest point on the mid-plane, r_n of hopper_neck."""
    R0 = 20.0
    v = ref.hopper_outline(nu, R0, 4000)
    assert ref.polygon_area(v) == pytest.approx(2 * math.pi * R0**2, rel=2e-5)
    near = np.abs(v[:, 0]) < 0.05
    assert np.abs(v[near, 1]).min() == pytest.approx(ref.hopper_neck(nu) * R0, rel=1e-3)


def test_hopper_starts_from_two_touching_circles():
    R0 = 20.0
    assert ref.hopper_tau(1.0) == 0.0 and ref.hopper_neck(1.0) == 0.0
    for nu in (1.0, 1 - 1e-7):
        v = ref.hopper_outline(nu, R0, 2000)
        d = np.minimum(
            np.abs(np.hypot(v[:, 0] - R0, v[:, 1]) - R0),
            np.abs(np.hypot(v[:, 0] + R0, v[:, 1]) - R0),
        )
        assert d.max() < 1e-3 * R0


def test_hopper_early_time_limit():
    """nu -> 1: K(m) ~ ln(4 / sqrt(1 - m)) gives tau ~ pi (r_n/R0) / ln(8 R0 / r_n); the ratio
    tends to 1 with an O(1 / ln) error."""
    ratios = []
    for e in (1e-3, 1e-6, 1e-9, 1e-12):
        rn = ref.hopper_neck(1 - e)
        ratios.append(ref.hopper_tau(1 - e) / (math.pi * rn / math.log(8 / rn)))
    assert all(b > a for a, b in zip(ratios[:-1], ratios[1:], strict=True))
    assert 0.95 < ratios[-1] < 1.0


def test_hopper_late_time_limit():
    """tau -> infinity: r_n -> sqrt(2) R0 (the circle of the pair's area), and nu decays as the
    n = 2 mode of that circle: d nu / d tau = -nu / sqrt(2), the viscous_decay_rate of R =
    sqrt(2) R0 in units of gamma / (eta_N R0)."""
    assert ref.hopper_neck_at(30.0) == pytest.approx(math.sqrt(2), rel=1e-6)
    a, b = ref.hopper_tau(1e-3), ref.hopper_tau(1e-4)
    rate = math.log(10) / (b - a)
    assert rate == pytest.approx(ref.viscous_decay_rate(2, 1.0, 1.0, math.sqrt(2)), rel=1e-6)
    for tau in (0.3, 1.0, 3.0):
        assert ref.hopper_tau(ref.hopper_nu(tau)) == pytest.approx(tau, rel=1e-10)
        assert ref.hopper_tau_at_neck(ref.hopper_neck_at(tau)) == pytest.approx(tau, rel=1e-9)
    assert ref.hopper_neck_at(1.0) == pytest.approx(0.8258, abs=1e-4)


def test_gaussian_spot_halfspace_surface_limit_and_depth():
    """The 3D spot's reference: as the depth law thins (eta -> 0, depth 0) the centre rise
    tends, linearly in eta, to the surface source's closed form sqrt(2) P / (pi^(3/2) k r0)
    arctan(sqrt(8 alpha t) / r0) (derived from the same point source; its steady limit P /
    (sqrt(2 pi) k r0)); the rise falls off the axis and with depth; it is linear in P."""
    k, rho_c, r0, P = 0.28, 1020 * 2700.0, 20e-6, 1e-3
    alpha, t = k / rho_c, 5e-4
    surface = math.sqrt(2) * P / (math.pi**1.5 * k * r0) * math.atan(math.sqrt(8 * alpha * t) / r0)
    errs = [
        ref.gaussian_spot_halfspace(0.0, 0.0, t, P, r0, eta, 1.0, k, rho_c) / surface - 1
        for eta in (1e-8, 1e-9)
    ]
    assert abs(errs[1]) < 2e-4 and errs[0] == pytest.approx(10 * errs[1], rel=0.01)
    centre = ref.gaussian_spot_halfspace(0.0, 1e-6, t, P, r0, 10e-6, 40e-6, k, rho_c)
    assert ref.gaussian_spot_halfspace(10e-6, 1e-6, t, P, r0, 10e-6, 40e-6, k, rho_c) < centre
    assert ref.gaussian_spot_halfspace(0.0, 10e-6, t, P, r0, 10e-6, 40e-6, k, rho_c) < centre
    double = ref.gaussian_spot_halfspace(0.0, 1e-6, t, 2 * P, r0, 10e-6, 40e-6, k, rho_c)
    assert double == pytest.approx(2 * centre, rel=1e-9)
