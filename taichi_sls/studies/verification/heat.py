"""Verification of the heat: erf half-space, mushy Stefan melting, spreading Gaussian, energy
balance, a 3D Gaussian laser spot on a half-space."""

from __future__ import annotations

import time

import numpy as np

from ...config import Case, CaseError, Material
from ...physics.materials import KELVIN
from .. import references as ref
from .common import Result, material, result, run_to
from .setups import simulation
from .spec import VerificationCase, stefan_slab


def _slab_parameters(case: Case) -> tuple[Material, float, float]:
    m = material(case)
    return m, case.thermal.initial_C, case.boundary.left.temperature_C


def _point_T_C(sim) -> np.ndarray:
    return sim.state.points.T.to_numpy() - KELVIN


def run_erf(vc: VerificationCase) -> Result:
    """Semi-infinite slab, face held at T_s: RMS error of the point temperatures against
    references.erf_slab, relative to the jump T_s - T_0 (no phase change in range)."""
    case = vc.case
    t0 = time.perf_counter()
    m, T0, Ts = _slab_parameters(case)
    if max(T0, Ts) >= m.crystallization_C:
        raise CaseError("verification.kind = 'erf': the slab must stay below crystallization_C")
    sim = simulation(vc)
    run_to(sim, case.time.end_s)
    x = sim.state.points.x.to_numpy()[:, 0]
    alpha = m.conductivity_solid_W_mK / (m.density_kg_m3 * m.heat_capacity_solid_J_kgK)
    exact = ref.erf_slab(x, sim.t, T0, Ts, alpha)
    rms = float(np.sqrt(np.mean((_point_T_C(sim) - exact) ** 2))) / abs(Ts - T0)
    return result(case, sim, {"temperature_rms": rms}, t0)


def run_stefan(vc: VerificationCase) -> Result:
    """Melting with the linear mushy zone (eq. 33) against references.mushy_stefan: RMS and max
    temperature error relative to T_s - T_0, and the melt front (T = T_m, interpolated between
    the point columns) relative to X_m."""
    case = vc.case
    t0 = time.perf_counter()
    m, T0, Ts = _slab_parameters(case)
    if m.conductivity_solid_W_mK != m.conductivity_liquid_W_mK or (
        m.heat_capacity_solid_J_kgK != m.heat_capacity_liquid_J_kgK
    ):
        raise CaseError("verification.kind = 'stefan': the similarity solution needs equal k, c")
    sim = simulation(vc)
    run_to(sim, case.time.end_s)
    x = sim.state.points.x.to_numpy()[:, 0]
    T = _point_T_C(sim)
    slab = stefan_slab(case)
    exact = ref.mushy_stefan(x, sim.t, slab)
    jump = Ts - T0
    xs, inv = np.unique(x, return_inverse=True)
    Tx = np.bincount(inv, T) / np.bincount(inv)  # mean over the points of one column
    i = int(np.argmax(Tx < m.melt_C))
    xf = xs[i - 1] + (m.melt_C - Tx[i - 1]) * (xs[i] - xs[i - 1]) / (Tx[i] - Tx[i - 1])
    Xm, _ = ref.mushy_stefan_fronts(sim.t, slab)
    errors = {
        "temperature_rms": float(np.sqrt(np.mean((T - exact) ** 2))) / jump,
        "temperature_max": float(np.abs(T - exact).max()) / jump,
        "melt_front": abs(xf - Xm) / Xm,
    }
    return result(case, sim, errors, t0, melt_depth_cells=Xm / sim.state.cfg.h)


def run_gaussian(vc: VerificationCase) -> Result:
    """A Gaussian temperature rise spreading in a frozen, insulated square: RMS error of the
    point temperatures against references.gaussian_spread_2d, relative to the initial peak."""
    case = vc.case
    t0 = time.perf_counter()
    m = material(case)
    v = vc.spec
    sim = simulation(vc)
    run_to(sim, case.time.end_s)
    x = sim.state.points.x.to_numpy() * 1e6
    r2 = (((x - np.asarray(v.center_um)) * 1e-6) ** 2).sum(axis=1)
    rho_c = m.density_kg_m3 * m.heat_capacity_solid_J_kgK
    alpha = m.conductivity_solid_W_mK / rho_c
    s0 = v.sigma_um * 1e-6
    E = v.rise_C * rho_c * 2 * np.pi * s0**2  # energy per depth of the initial rise
    exact = case.thermal.initial_C + ref.gaussian_spread_2d(r2, sim.t, E, rho_c, alpha, s0)
    rms = float(np.sqrt(np.mean((_point_T_C(sim) - exact) ** 2))) / v.rise_C
    peak = float(_point_T_C(sim).max() - case.thermal.initial_C)
    exact_peak = float(ref.gaussian_spread_2d(0.0, sim.t, E, rho_c, alpha, s0))
    return result(case, sim, {"temperature_rms": rms, "peak": abs(peak / exact_peak - 1)}, t0)


def run_energy(vc: VerificationCase) -> Result:
    """Laser energy delivered against enthalpy rise plus heat out through fixed walls (eqs.
    29-32), relative to the laser energy."""
    case = vc.case
    t0 = time.perf_counter()
    sim = simulation(vc)
    H0 = sim.monitors()["enthalpy_J_per_m"]
    run_to(sim, case.time.end_s)
    mon = sim.monitors()
    rise = mon["enthalpy_J_per_m"] - H0
    laser = mon["laser_energy_J_per_m"]
    if not laser > 0:
        raise CaseError("verification.kind = 'energy': needs a laser that is on during the run")
    err = abs(rise + mon["heat_out_J_per_m"] - laser) / laser
    return result(
        case, sim, {"energy_balance": err}, t0, heat_out_fraction=mon["heat_out_J_per_m"] / laser
    )


def run_spot3d(vc: VerificationCase) -> Result:
    """A stationary 3D laser spot on an insulated block against
    references.gaussian_spot_halfspace: the rise of the top row of points relative to the exact
    rise on the axis, at the points nearest the axis ("centre", signed) and the largest over
    the top points within r0 of the axis ("surface_max")."""
    case = vc.case
    t0 = time.perf_counter()
    m = material(case)
    las = case.lasers[0]
    sim = simulation(vc)
    run_to(sim, case.time.end_s)
    x = sim.state.points.x.to_numpy()
    rise = _point_T_C(sim) - case.thermal.initial_C
    top = x[:, 1] >= x[:, 1].max() - 1e-12
    r0, eta = las.spot_radius_um * 1e-6, las.penetration_depth_um * 1e-6
    radius = np.hypot(x[:, 0] - las.x_start_um * 1e-6, x[:, 2] - las.z_start_um * 1e-6)
    near = top & (radius <= r0)
    y_l = case.top_um() * 1e-6
    rho_c = m.density_kg_m3 * m.heat_capacity_solid_J_kgK

    def exact(r: float, y: float) -> float:
        return ref.gaussian_spot_halfspace(
            r,
            y_l - y,
            sim.t,
            las.depth_factor * las.absorptivity * las.power_W,
            r0,
            eta,
            y_l - case.bodies[0].min_um[1] * 1e-6,
            m.conductivity_solid_W_mK,
            rho_c,
        )

    axis = exact(0.0, y_l)
    errors = np.array([rise[p] - exact(radius[p], x[p, 1]) for p in np.flatnonzero(near)])
    closest = radius[near] <= radius[near].min() + 1e-12
    return result(
        case,
        sim,
        {
            "centre": float(errors[closest].mean() / axis),
            "surface_max": float(np.abs(errors).max() / axis),
        },
        t0,
        rise_axis_K=axis,
    )
