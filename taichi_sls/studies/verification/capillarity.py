"""Verification of the surface tension: disc curvature, Laplace pressure, a square rounding off,
viscous decay and inviscid oscillation of a shape mode."""

from __future__ import annotations

import math
import time

import numpy as np
from numpy.polynomial import legendre

from ...config import CaseError, Material
from .. import references as ref
from .common import Result, material, result, run_to, samples
from .setups import simulation
from .spec import VerificationCase


def run_curvature(vc: VerificationCase) -> Result:
    """Curvature of a disc of points as the level set reconstructs it (eqs. 21-23): mean and RMS
    of kappa R - 1 over the interface nodes."""
    case = vc.case
    from ...solver.grid_views import surface_only

    t0 = time.perf_counter()
    sim = simulation(vc)
    surface_only(sim.state)
    k = sim.state.nodes.kappa.to_numpy()
    iface = (sim.state.nodes.flags.to_numpy() & 2) > 0
    rel = k[iface] * case.bodies[0].radius_um * 1e-6 - 1.0
    errors = {"curvature_mean": float(rel.mean()), "curvature_rms": float(np.sqrt(np.mean(rel**2)))}
    return result(case, sim, errors, t0)


def eta_newtonian(m: Material) -> float:
    """Newtonian shear viscosity of the zero-yield Perzyna model: eta/2 (references.
    viscous_decay_rate)."""
    if m.viscosity_model != "constant" or m.yield_solid_Pa != 0 or m.hardening_solid_Pa != 0:
        raise CaseError(
            "a viscous disc needs viscosity_model = 'constant', yield_solid_Pa = 0 and "
            "hardening_solid_Pa = 0 (a Maxwell fluid)"
        )
    return 0.5 * m.viscosity_Pas


def _mode_amplitude(st, n: int) -> float:
    amplitude = mode_amplitude_3d if st.cfg.dim == 3 else mode_amplitude
    return amplitude(
        st.points.x.to_numpy(), st.points.volume0.to_numpy() * st.points.J.to_numpy(), n
    )


def mode_amplitude_3d(x: np.ndarray, V: np.ndarray, n: int) -> float:
    """eps_n of r = R(1 + eps P_n(cos theta)), theta from the x axis, from points x (N, 3) of
    volumes V: the integral of the solid harmonic r^n P_n(cos theta) over the body is
    4 pi R^(n+3) eps / (2n + 1) to first order, taken about the volume centroid with
    R^3 = 3 V / (4 pi)."""
    d = x - (V[:, None] * x).sum(axis=0) / V.sum()
    r = np.linalg.norm(d, axis=1)
    cos = d[:, 0] / np.maximum(r, 1e-300)
    harmonic = r**n * legendre.legval(cos, [0.0] * n + [1.0])
    R3 = 3.0 * V.sum() / (4.0 * np.pi)
    return float((2 * n + 1) * (V * harmonic).sum() / (4.0 * np.pi * R3 ** (n / 3 + 1)))


def mode_amplitude(x: np.ndarray, V: np.ndarray, n: int) -> float:
    """eps_n of r = R(1 + eps cos n theta) from points x (N, 2) of volumes V: the integral of
    r^n cos(n theta) over the body is pi R^(n+2) eps to first order, taken about the volume
    centroid with R^2 = area/pi."""
    z = (x[:, 0] + 1j * x[:, 1]) - (V[:, None] * x).sum(axis=0) @ [1, 1j] / V.sum()
    R2 = V.sum() / np.pi
    return float((V * (z**n).real).sum() / (np.pi * R2 ** (n / 2 + 1)))


def _laplace(dim: int, gamma: float, R: float) -> float:
    return ref.laplace_pressure_3d(gamma, R) if dim == 3 else ref.laplace_pressure_2d(gamma, R)


def hemisphere_pressure(sim) -> np.ndarray:
    """The Laplace pressure that the surface force of a sphere carries, per axis a: the force
    on the nodes above the plane through the points' centroid normal to a (the upper
    hemisphere's share; the surface force alone: no stress, no gravity, ``surface_only`` run
    first) over the hemisphere's section pi R^2, R the seeded radius. The force on a cap cut
    off by that plane is the surface tension's pull along its rim, 2 pi R gamma, so the
    pressure is 2 gamma / R (to the smoothing of the node set's edge, O((h/R)^2))."""
    st = sim.state
    f = st.nodes.force.to_numpy()
    X = (np.indices(f.shape[:3]).transpose(1, 2, 3, 0) - st.cfg.off) * st.cfg.h
    xc = st.points.x.to_numpy().mean(axis=0)
    R = sim.case.bodies[0].radius_um * 1e-6
    return np.array([-f[..., a][X[..., a] > xc[a]].sum() / (np.pi * R * R) for a in range(3)])


def run_laplace(vc: VerificationCase) -> Result:
    """A disc at rest under surface tension: mean in-plane pressure -(s_xx + s_yy)/2 of the inner
    half against gamma/R, averaged over the last 40 % of the run; spurious velocity as a
    capillary number eta_N |v|max / gamma (a fluid disc) and against sqrt(gamma/(rho R)). In 3D a
    sphere: the mean pressure -tr(s)/3 against 2 gamma / R."""
    case = vc.case
    t0 = time.perf_counter()
    m = material(case)
    R = case.bodies[0].radius_um * 1e-6
    sim = simulation(vc)
    st = sim.state
    dim = case.domain.dim
    run_to(sim, 0.6 * case.time.end_s)
    ps, vs = [], []
    for _ in range(8):
        run_to(sim, 0.05 * case.time.end_s)
        x = st.points.x.to_numpy()
        inner = np.linalg.norm(x - x.mean(axis=0), axis=1) < 0.5 * R
        sig = st.points.stress.to_numpy()
        if dim == 3:
            ps.append(np.mean(-(sig[inner, 0, 0] + sig[inner, 1, 1] + sig[inner, 2, 2]) / 3.0))
        else:
            ps.append(np.mean(-0.5 * (sig[inner, 0, 0] + sig[inner, 1, 1])))
        vs.append(np.linalg.norm(st.points.v.to_numpy(), axis=1).max())
    gamma = m.surface_tension_N_m
    curvature = math.nan  # the CSF's curvature at the end (the surface-energy force has none)
    if case.surface_tension.method == "csf":
        from ...solver.grid_views import surface_only

        surface_only(st)  # the curvature the settled points give, where the CSF force acts
        k = st.nodes.kappa.to_numpy()
        w = st.nodes.mass.to_numpy() * np.linalg.norm(st.nodes.mass_gradient.to_numpy(), axis=2)
        w *= (st.nodes.flags.to_numpy() & 2) > 0
        curvature = float((w * k).sum() / w.sum() * R - 1.0)
    errors = {
        "pressure": float(np.mean(ps) / _laplace(dim, gamma, R) - 1.0),
        "capillary_number": eta_newtonian(m) * max(vs) / gamma,
    }
    return result(
        case,
        sim,
        errors,
        t0,
        v_max_m_s=max(vs),
        force_weighted_curvature_end=curvature,
        v_over_capillary=max(vs) / math.sqrt(gamma / (m.density_kg_m3 * R)),
    )


def run_square(vc: VerificationCase) -> Result:
    """A square of Maxwell fluid rounding off under surface tension: its n = 4 shape amplitude at
    the end relative to the start (a disc: 0), and the relative area change."""
    case = vc.case
    t0 = time.perf_counter()
    sim = simulation(vc)
    st = sim.state

    def area() -> float:
        return float((st.points.volume0.to_numpy() * st.points.J.to_numpy()).sum())

    e0, a0 = _mode_amplitude(st, 4), area()
    run_to(sim, case.time.end_s)
    e1, a1 = _mode_amplitude(st, 4), area()
    return result(
        case, sim, {"mode4_left": abs(e1 / e0), "area": abs(a1 / a0 - 1.0)}, t0, mode4_start=e0
    )


def _mode_history(vc: VerificationCase, n_out: int) -> tuple:
    case = vc.case
    sim = simulation(vc)
    n = case.bodies[0].mode
    ts, eps = samples(sim, n_out, case.time.end_s, lambda: _mode_amplitude(sim.state, n))
    return sim, ts, eps


def run_viscous_decay(vc: VerificationCase) -> Result:
    """Shape mode n of a disc of Maxwell fluid in the Stokes limit: the decay rate fitted to
    log eps(t) against n gamma/(2 eta_N R) (references.viscous_decay_rate), eta_N = eta/2; of a
    sphere (domain.dim = 3) against references.viscous_decay_rate_sphere."""
    case = vc.case
    t0 = time.perf_counter()
    m = material(case)
    b = case.bodies[0]
    R = b.radius_um * 1e-6
    sim, ts, eps = _mode_history(vc, 20)
    # skip the first tenth: the start-up breathing transient of the compressible body
    keep = ts >= 0.1 * case.time.end_s
    rate = -np.polyfit(ts[keep], np.log(np.abs(eps[keep])), 1)[0]
    eta_N = eta_newtonian(m)
    decay = ref.viscous_decay_rate_sphere if case.domain.dim == 3 else ref.viscous_decay_rate
    lam = decay(b.mode, m.surface_tension_N_m, eta_N, R)
    mu = m.youngs_solid_Pa / (2 * (1 + m.poisson))
    tau = m.viscosity_Pas / (2 * mu)
    errors = {"decay_rate": float(rate / lam - 1.0)}
    maxwell = ref.maxwell_decay_rate(lam, tau)
    return result(
        case,
        sim,
        errors,
        t0,
        rate_1_s=float(rate),
        newtonian_1_s=lam,
        maxwell_1_s=maxwell,
        vs_maxwell=float(rate / maxwell - 1.0),
    )


def run_inviscid(vc: VerificationCase) -> Result:
    """Oscillating shape mode n of a nearly inviscid disc: the period from the zero crossings of
    eps(t) against 2 pi / omega, omega^2 = n(n^2 - 1) gamma/(rho R^3) (references.
    inviscid_drop_omega; a sphere: n (n - 1)(n + 2), inviscid_sphere_omega); the amplitude lost
    per period is reported."""
    case = vc.case
    t0 = time.perf_counter()
    m = material(case)
    b = case.bodies[0]
    R = b.radius_um * 1e-6
    drop = ref.inviscid_sphere_omega if case.domain.dim == 3 else ref.inviscid_drop_omega
    omega = drop(b.mode, m.surface_tension_N_m, m.density_kg_m3, R)
    period = 2 * np.pi / omega
    sim, ts, eps = _mode_history(vc, max(40, int(80 * case.time.end_s / period)))
    s = np.sign(eps)
    i = np.nonzero(s[:-1] * s[1:] < 0)[0]
    if len(i) < 2:
        raise CaseError(
            f"verification.kind = 'inviscid': fewer than two zero crossings of the mode in "
            f"time.end_s = {case.time.end_s} (expected period {period:.3g} s); run longer"
        )
    tc = ts[i] - eps[i] * (ts[i + 1] - ts[i]) / (eps[i + 1] - eps[i])
    measured = 2.0 * float(np.mean(np.diff(tc)))
    # amplitude: extreme between the first two crossings (a trough) against the start
    trough = float(np.abs(eps[i[0] + 1 : i[1] + 1]).max())
    return result(
        case,
        sim,
        {"period": measured / period - 1.0},
        t0,
        period_s=measured,
        expected_s=period,
        amplitude_after_half_period=trough / abs(eps[0]),
    )
