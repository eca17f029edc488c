"""Verification runners: each case of ``cases/verification/`` against its analytic reference.

A runner takes a validated :class:`~taichi_sls.case.Case` (usually from :func:`load`, which sets
the resolution), runs it and returns a :class:`Result` with named error measures. The default
tests (tests/test_verification.py and the physics test files) and the accuracy study
(:mod:`taichi_sls.accuracy`, ``python -m taichi_sls.bench accuracy``) call the same runners.

Resolution parameter of :func:`load`, by kind:
- ``bar``, ``steffen``: cells along the bar (the cross-section is one cell of points);
- ``stefan``: cells across the melt depth X_m at the end time (the slab is 5 X_m long);
- ``curvature``, ``laplace``, ``viscous_decay``, ``inviscid``: R/h of the disc;
- ``perzyna``: time steps over the constant-rate drive;
- every other kind: the grid spacing in um.
"""

from __future__ import annotations

import copy
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import references as ref
from .case import Case, CaseError, case_from_dict, read_toml
from .materials import KELVIN, Material

CASES = Path(__file__).resolve().parents[1] / "cases" / "verification"


@dataclass
class Result:
    """One verification run: error measures (dimensionless unless the name says otherwise)."""

    case: str
    h_um: float
    dt_s: float
    errors: dict[str, float]
    wall_s: float
    steps: int
    transfer: str
    precision: str
    info: dict[str, float] = field(default_factory=dict)


# ------------------------------------------------------------------------------ loading


def case_path(name: str) -> Path:
    return CASES / f"{name}.toml"


def case_names() -> list[str]:
    return sorted(p.stem for p in CASES.glob("*.toml"))


def deep_update(base: dict, extra: dict) -> dict:
    """A copy of ``base`` with the nested dict ``extra`` merged in (lists are replaced)."""
    out = copy.deepcopy(base)
    for k, v in extra.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = deep_update(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def _disc_geometry(data: dict, R_over_h: float) -> None:
    """Disc of the case at R/h: domain 2R(1 + |eps|) + 12 h square, centre off the grid lines so
    that the seeding is not symmetric about a node."""
    b = data["bodies"][0]
    R = b["radius_um"]
    h = R / R_over_h
    W = h * math.ceil((2 * R * (1 + abs(b.get("perturbation", 0.0))) + 12 * h) / h)
    data["grid"]["spacing_um"] = h
    data["domain"] = {"width_um": W, "height_um": W}
    b["center_um"] = [W / 2 + 0.123 * h, W / 2 + 0.377 * h]


def _bar_geometry(data: dict, cells: int, fixed_fixed: bool) -> None:
    b = data["bodies"][0]
    L = b["max_um"][0]
    h = L / cells
    data["grid"]["spacing_um"] = h
    data["domain"] = {"width_um": L if fixed_fixed else L + 4 * h, "height_um": 4 * h}
    b["max_um"] = [L, h]


def _slab_length(data: dict, h: float, length: float) -> None:
    """A 1D slab along x: `length` rounded up to whole cells, two cells of points tall."""
    W = h * math.ceil(length / h - 1e-9)
    data["grid"]["spacing_um"] = h
    data["domain"] = {"width_um": W, "height_um": 4 * h}
    data["bodies"][0]["min_um"] = [0.0, 0.0]
    data["bodies"][0]["max_um"] = [W, 2 * h]


def _stefan_melt_depth_um(case: Case) -> float:
    m, T0, Ts = _slab_parameters(case)
    Xm, _ = ref.mushy_stefan_fronts(
        case.time.end_s,
        T0,
        Ts,
        m.crystallization_C,
        m.melt_C,
        m.conductivity_solid_W_mK,
        m.density_kg_m3,
        m.heat_capacity_solid_J_kgK,
        m.latent_heat_J_kg,
    )
    return float(Xm) * 1e6


def load(name: str, resolution: float | None = None, sets: dict | None = None) -> Case:
    """Verification case ``name`` (cases/verification/NAME.toml) at a resolution (module
    docstring), with ``sets`` (nested dict) merged in first."""
    path = case_path(name)
    if not path.is_file():
        raise CaseError(
            f"verification case {name!r} does not exist; available: {', '.join(case_names())}"
        )
    data = deep_update(read_toml(path, "verification case"), sets or {})
    data.setdefault("case", {}).setdefault("name", name)
    data.setdefault("grid", {})
    kind = data.get("verification", {}).get("kind", "none")
    if resolution is not None:
        if kind in ("bar", "steffen"):
            _bar_geometry(data, int(resolution), kind == "steffen")
        elif kind in ("curvature", "laplace", "viscous_decay", "inviscid"):
            _disc_geometry(data, float(resolution))
        elif kind == "stefan":
            Xm = _stefan_melt_depth_um(case_from_dict(data))
            _slab_length(data, Xm / float(resolution), 5.0 * Xm)
        elif kind == "erf":
            _slab_length(data, float(resolution), data["domain"]["width_um"])
        elif kind == "perzyna":
            data.setdefault("time", {})["dt_s"] = data["time"]["end_s"] / int(resolution)
            data["time"]["allow_unstable_dt"] = True  # a point-level drive: no grid limit
        else:
            data["grid"]["spacing_um"] = float(resolution)
    return case_from_dict(data)


# ------------------------------------------------------------------------------ helpers


def _material(case: Case) -> Material:
    return case.materials[case.bodies[0].material]


def _sim(case: Case):
    from .simulation import Simulation

    return Simulation(case)


def _result(case: Case, sim, errors: dict[str, float], t0: float, **info: float) -> Result:
    return Result(
        case=case.case.name,
        h_um=case.grid.spacing_um,
        dt_s=sim.dt,
        errors=errors,
        wall_s=time.perf_counter() - t0,
        steps=sim.steps,
        transfer=_transfer_label(case),
        precision=case.solver.precision,
        info=dict(info),
    )


def _transfer_label(case: Case) -> str:
    s = case.solver
    return f"pic_flip {s.flip_ratio:g}" if s.transfer == "pic_flip" else s.transfer


def _samples(sim, n_out: int, end_s: float, read: Callable[[], float]) -> tuple:
    """Advance to ``end_s`` in ``n_out`` equal chunks of whole steps; read after each."""
    per = max(1, int(round(end_s / n_out / sim.dt)))
    ts, vals = [sim.t], [read()]
    for _ in range(n_out):
        sim.advance(per)
        ts.append(sim.t)
        vals.append(read())
    return np.array(ts), np.array(vals)


# ------------------------------------------------------------------------------ mechanics


def run_bar(case: Case) -> Result:
    """Fixed-free bar in its first axial mode: centre-of-mass velocity against (2 v0/pi)
    cos(w t) (references.bar_com_velocity), max over 40 samples, relative to 2 v0/pi."""
    t0 = time.perf_counter()
    sim = _sim(case)
    st = sim.state
    m = st.mass.to_numpy()
    mat = _material(case)
    L = case.bodies[0].max_um[0] * 1e-6
    v0 = case.verification.velocity_amplitude_m_s
    ts, vc = _samples(
        sim, 40, case.time.end_s, lambda: float((m * st.v.to_numpy()[:, 0]).sum() / m.sum())
    )
    # symplectic Euler: the point velocities after a step sit half a step behind the positions
    # (leapfrog), so the analytic velocity is taken at t - dt/2; otherwise an O(dt) phase lag
    exact = ref.bar_com_velocity(ts[1:] - 0.5 * sim.dt, L, mat.youngs_solid_Pa, 1.0, v0)
    err = float(np.max(np.abs(vc[1:] - exact))) / (2 * v0 / np.pi)
    amp_cells = v0 / ref.bar_omega(L, mat.youngs_solid_Pa, mat.density_kg_m3) / st.h
    return _result(case, sim, {"com_velocity": err}, t0, amplitude_cells=amp_cells)


def run_steffen(case: Case) -> Result:
    """Manufactured solution of a fixed-fixed bar (references.steffen_displacement): RMS over the
    points of the displacement error, max over 20 samples, relative to the amplitude A."""
    t0 = time.perf_counter()
    sim = _sim(case)
    st = sim.state
    mat = _material(case)
    L = case.bodies[0].max_um[0] * 1e-6
    A = case.verification.displacement_amplitude_um * 1e-6
    X = st.x0.to_numpy()[:, 0]

    def rms() -> float:
        u = st.x.to_numpy()[:, 0] - X
        exact = ref.steffen_displacement(X, sim.t, L, A, mat.youngs_solid_Pa, mat.density_kg_m3)
        return float(np.sqrt(np.mean((u - exact) ** 2)))

    _, errs = _samples(sim, 20, case.time.end_s, rms)
    return _result(case, sim, {"displacement_rms": float(errs.max()) / A}, t0)


def perzyna_history(mat: Material, strains: np.ndarray, dt: float) -> tuple[np.ndarray, ...]:
    """Drive one point of the solver's return map (constitutive.perzyna_update) through the
    pure-shear strains eps_xy; returns (||s||, alpha) after every step."""
    import taichi as ti

    from .constitutive import embed3, perzyna_update
    from .materials import material_row
    from .simulation import init_taichi

    init_taichi(optimize=False)
    n = len(strains)
    row = material_row(mat, 0.0)
    mf = ti.field(float, (1, len(row)))
    mf.from_numpy(row[None, :])
    e = ti.field(float, n)
    e.from_numpy(strains)
    out = ti.field(float, (n, 2))

    @ti.kernel
    def drive():
        ti.loop_config(serialize=True)
        for _ in range(1):
            epl = ti.Matrix.zero(float, 3, 3)
            a = 0.0
            for k in range(n):
                eps = ti.Matrix([[0.0, e[k]], [e[k], 0.0]])
                sig, epl2, a2 = perzyna_update(
                    mf, 0, embed3(eps), epl, a, 0.0, 1.0, 300.0, dt, True, False
                )
                epl = epl2
                a = a2
                s = sig - sig.trace() / 3.0 * ti.Matrix.identity(float, 3)
                out[k, 0] = s.norm()
                out[k, 1] = a

    drive()
    r = out.to_numpy()
    return r[:, 0], r[:, 1]


def run_perzyna(case: Case) -> Result:
    """Perzyna return map at one point (eqs. 40-45), time step dt = case.time.dt_s:

    - ``rate_vs_closed_form``: constant-rate pure shear against the continuous closed form
      (references.perzyna_shear_constant_rate), max |s| error over the run / final |s|;
    - ``rate_vs_discrete``: the same against the step-by-step reference (round-off);
    - ``relaxation_ratio``: at a held strain, max relative error of the overstress ratio per step
      against (tau/dt)/(tau/dt + 1 + H/3mu) (references.perzyna_relaxation_ratio).
    """
    t0 = time.perf_counter()
    mat = _material(case)
    v = case.verification
    mu = mat.youngs_solid_Pa / (2 * (1 + mat.poisson))
    sy, H, eta = mat.yield_solid_Pa, mat.hardening_solid_Pa, mat.viscosity_Pas
    if mat.viscosity_model != "constant":
        raise CaseError("verification.kind = 'perzyna': needs viscosity_model = 'constant'")
    dt = float(case.time.dt_s)
    n = int(round(case.time.end_s / dt))
    t = dt * np.arange(1, n + 1)
    s, a = perzyna_history(mat, v.shear_rate_1_s * t / 2.0, dt)
    _, s_ref, a_ref = ref.perzyna_shear_discrete(n, dt, v.shear_rate_1_s, mu, sy, H, eta)
    s_c, _ = ref.perzyna_shear_constant_rate(t, v.shear_rate_1_s, mu, sy, H, eta)
    scale = float(np.abs(s_ref).max())
    discrete = max(
        float(np.abs(s - s_ref[1:]).max()) / scale,
        float(np.abs(a - a_ref[1:]).max()) / max(float(a_ref.max()), 1e-300),
    )
    # load to the held strain in 50 steps, then hold it for 30
    n_load, n_hold = 50, 30
    strains = np.concatenate(
        [np.linspace(0, v.hold_strain, n_load + 1)[1:], [v.hold_strain] * n_hold]
    )
    s2, a2 = perzyna_history(mat, strains, dt)
    f = s2 - math.sqrt(2 / 3) * (sy + H * a2)
    ratio = f[n_load:] / f[n_load - 1 : -1]
    exact = ref.perzyna_relaxation_ratio(dt, eta / (2 * mu), mu, H)
    errors = {
        "rate_vs_closed_form": float(np.abs(s - s_c).max()) / scale,
        "rate_vs_discrete": discrete,
        "relaxation_ratio": float(np.abs(ratio / exact - 1.0).max()),
    }
    return Result(
        case=case.case.name,
        h_um=case.grid.spacing_um,
        dt_s=dt,
        errors=errors,
        wall_s=time.perf_counter() - t0,
        steps=n + n_load + n_hold,
        transfer=_transfer_label(case),  # no grid transfer: the label keeps the rows together
        precision=case.solver.precision,
        info={"tau_s": eta / (2 * mu), "overstress_at_hold": float(f[n_load - 1])},
    )


# ------------------------------------------------------------------------------ heat


def _slab_parameters(case: Case) -> tuple[Material, float, float]:
    m = _material(case)
    return m, case.thermal.initial_C, case.boundary.left.temperature_C


def _point_T_C(sim) -> np.ndarray:
    return sim.state.T.to_numpy() - KELVIN


def _run_to(sim, end_s: float) -> None:
    sim.advance(int(round(end_s / sim.dt)))


def run_erf(case: Case) -> Result:
    """Semi-infinite slab, face held at T_s: RMS error of the point temperatures against
    references.erf_slab, relative to the jump T_s - T_0 (no phase change in range)."""
    t0 = time.perf_counter()
    m, T0, Ts = _slab_parameters(case)
    if max(T0, Ts) >= m.crystallization_C:
        raise CaseError("verification.kind = 'erf': the slab must stay below crystallization_C")
    sim = _sim(case)
    _run_to(sim, case.time.end_s)
    x = sim.state.x.to_numpy()[:, 0]
    alpha = m.conductivity_solid_W_mK / (m.density_kg_m3 * m.heat_capacity_solid_J_kgK)
    exact = ref.erf_slab(x, sim.t, T0, Ts, alpha)
    rms = float(np.sqrt(np.mean((_point_T_C(sim) - exact) ** 2))) / abs(Ts - T0)
    return _result(case, sim, {"temperature_rms": rms}, t0)


def run_stefan(case: Case) -> Result:
    """Melting with the linear mushy zone (eq. 33) against references.mushy_stefan: RMS and max
    temperature error relative to T_s - T_0, and the melt front (T = T_m, interpolated between
    the point columns) relative to X_m."""
    t0 = time.perf_counter()
    m, T0, Ts = _slab_parameters(case)
    if m.conductivity_solid_W_mK != m.conductivity_liquid_W_mK or (
        m.heat_capacity_solid_J_kgK != m.heat_capacity_liquid_J_kgK
    ):
        raise CaseError("verification.kind = 'stefan': the similarity solution needs equal k, c")
    sim = _sim(case)
    _run_to(sim, case.time.end_s)
    x = sim.state.x.to_numpy()[:, 0]
    T = _point_T_C(sim)
    k, rho, c = m.conductivity_solid_W_mK, m.density_kg_m3, m.heat_capacity_solid_J_kgK
    args = (T0, Ts, m.crystallization_C, m.melt_C, k, rho, c, m.latent_heat_J_kg)
    exact = ref.mushy_stefan(x, sim.t, *args)
    jump = Ts - T0
    xs, inv = np.unique(x, return_inverse=True)
    Tx = np.bincount(inv, T) / np.bincount(inv)  # mean over the points of one column
    i = int(np.argmax(Tx < m.melt_C))
    xf = xs[i - 1] + (m.melt_C - Tx[i - 1]) * (xs[i] - xs[i - 1]) / (Tx[i] - Tx[i - 1])
    Xm, _ = ref.mushy_stefan_fronts(sim.t, *args)
    errors = {
        "temperature_rms": float(np.sqrt(np.mean((T - exact) ** 2))) / jump,
        "temperature_max": float(np.abs(T - exact).max()) / jump,
        "melt_front": abs(xf - Xm) / Xm,
    }
    return _result(case, sim, errors, t0, melt_depth_cells=Xm / sim.state.h)


def run_gaussian(case: Case) -> Result:
    """A Gaussian temperature rise spreading in a frozen, insulated square: RMS error of the
    point temperatures against references.gaussian_spread_2d, relative to the initial peak."""
    t0 = time.perf_counter()
    m = _material(case)
    v = case.verification
    sim = _sim(case)
    _run_to(sim, case.time.end_s)
    x = sim.state.x.to_numpy() * 1e6
    r2 = (((x - np.asarray(v.center_um)) * 1e-6) ** 2).sum(axis=1)
    rho_c = m.density_kg_m3 * m.heat_capacity_solid_J_kgK
    alpha = m.conductivity_solid_W_mK / rho_c
    s0 = v.sigma_um * 1e-6
    E = v.rise_C * rho_c * 2 * np.pi * s0**2  # energy per depth of the initial rise
    exact = case.thermal.initial_C + ref.gaussian_spread_2d(r2, sim.t, E, rho_c, alpha, s0)
    rms = float(np.sqrt(np.mean((_point_T_C(sim) - exact) ** 2))) / v.rise_C
    peak = float(_point_T_C(sim).max() - case.thermal.initial_C)
    exact_peak = float(ref.gaussian_spread_2d(0.0, sim.t, E, rho_c, alpha, s0))
    return _result(case, sim, {"temperature_rms": rms, "peak": abs(peak / exact_peak - 1)}, t0)


def run_energy(case: Case) -> Result:
    """Laser energy delivered against enthalpy rise plus heat out through fixed walls (eqs.
    29-32), relative to the laser energy."""
    t0 = time.perf_counter()
    sim = _sim(case)
    H0 = sim.monitors()["enthalpy_J_per_m"]
    _run_to(sim, case.time.end_s)
    mon = sim.monitors()
    rise = mon["enthalpy_J_per_m"] - H0
    laser = mon["laser_energy_J_per_m"]
    if not laser > 0:
        raise CaseError("verification.kind = 'energy': needs a laser that is on during the run")
    err = abs(rise + mon["heat_out_J_per_m"] - laser) / laser
    return _result(
        case, sim, {"energy_balance": err}, t0, heat_out_fraction=mon["heat_out_J_per_m"] / laser
    )


# ------------------------------------------------------------------------------ surface tension


def run_curvature(case: Case) -> Result:
    """Curvature of a disc of points as the level set reconstructs it (eqs. 21-23): mean and RMS
    of kappa R - 1 over the interface nodes."""
    from .step import surface_only

    t0 = time.perf_counter()
    sim = _sim(case)
    surface_only(sim.state)
    k = sim.state.kappa.to_numpy()
    iface = (sim.state.kvalid.to_numpy() & 2) > 0
    rel = k[iface] * case.bodies[0].radius_um * 1e-6 - 1.0
    errors = {"curvature_mean": float(rel.mean()), "curvature_rms": float(np.sqrt(np.mean(rel**2)))}
    return _result(case, sim, errors, t0)


def _eta_newtonian(m: Material) -> float:
    """Newtonian shear viscosity of the zero-yield Perzyna model: eta/2 (references.
    viscous_decay_rate)."""
    if m.viscosity_model != "constant" or m.yield_solid_Pa != 0 or m.hardening_solid_Pa != 0:
        raise CaseError(
            "a viscous disc needs viscosity_model = 'constant', yield_solid_Pa = 0 and "
            "hardening_solid_Pa = 0 (a Maxwell fluid)"
        )
    return 0.5 * m.viscosity_Pas


def _mode_amplitude(st, n: int) -> float:
    return mode_amplitude(st.x.to_numpy(), st.vol0.to_numpy() * st.J.to_numpy(), n)


def mode_amplitude(x: np.ndarray, V: np.ndarray, n: int) -> float:
    """eps_n of r = R(1 + eps cos n theta) from points x (N, 2) of volumes V: the integral of
    r^n cos(n theta) over the body is pi R^(n+2) eps to first order, taken about the volume
    centroid with R^2 = area/pi."""
    z = (x[:, 0] + 1j * x[:, 1]) - (V[:, None] * x).sum(axis=0) @ [1, 1j] / V.sum()
    R2 = V.sum() / np.pi
    return float((V * (z**n).real).sum() / (np.pi * R2 ** (n / 2 + 1)))


def run_laplace(case: Case) -> Result:
    """A disc at rest under surface tension: mean in-plane pressure -(s_xx + s_yy)/2 of the inner
    half against gamma/R, averaged over the last 40 % of the run; spurious velocity as a
    capillary number eta_N |v|max / gamma (a fluid disc) and against sqrt(gamma/(rho R))."""
    t0 = time.perf_counter()
    m = _material(case)
    R = case.bodies[0].radius_um * 1e-6
    sim = _sim(case)
    st = sim.state
    _run_to(sim, 0.6 * case.time.end_s)
    ps, vs = [], []
    for _ in range(8):
        _run_to(sim, 0.05 * case.time.end_s)
        x = st.x.to_numpy()
        inner = np.linalg.norm(x - x.mean(axis=0), axis=1) < 0.5 * R
        sig = st.sigma.to_numpy()
        ps.append(np.mean(-0.5 * (sig[inner, 0, 0] + sig[inner, 1, 1])))
        vs.append(np.linalg.norm(st.v.to_numpy(), axis=1).max())
    gamma = m.surface_tension_N_m
    from .step import surface_only

    surface_only(st)  # the curvature the settled points give, where the CSF force acts
    k = st.kappa.to_numpy()
    w = st.gm.to_numpy() * np.linalg.norm(st.gradm.to_numpy(), axis=2)
    w *= (st.kvalid.to_numpy() & 2) > 0
    errors = {
        "pressure": float(np.mean(ps) / ref.laplace_pressure_2d(gamma, R) - 1.0),
        "capillary_number": _eta_newtonian(m) * max(vs) / gamma,
    }
    return _result(
        case,
        sim,
        errors,
        t0,
        v_max_m_s=max(vs),
        force_weighted_curvature_end=float((w * k).sum() / w.sum() * R - 1.0),
        v_over_capillary=max(vs) / math.sqrt(gamma / (m.density_kg_m3 * R)),
    )


def run_square(case: Case) -> Result:
    """A square of Maxwell fluid rounding off under surface tension: its n = 4 shape amplitude at
    the end relative to the start (a disc: 0), and the relative area change."""
    t0 = time.perf_counter()
    sim = _sim(case)
    st = sim.state

    def area() -> float:
        return float((st.vol0.to_numpy() * st.J.to_numpy()).sum())

    e0, a0 = _mode_amplitude(st, 4), area()
    _run_to(sim, case.time.end_s)
    e1, a1 = _mode_amplitude(st, 4), area()
    return _result(
        case, sim, {"mode4_left": abs(e1 / e0), "area": abs(a1 / a0 - 1.0)}, t0, mode4_start=e0
    )


def _mode_history(case: Case, n_out: int) -> tuple:
    sim = _sim(case)
    n = case.bodies[0].mode
    ts, eps = _samples(sim, n_out, case.time.end_s, lambda: _mode_amplitude(sim.state, n))
    return sim, ts, eps


def run_viscous_decay(case: Case) -> Result:
    """Shape mode n of a disc of Maxwell fluid in the Stokes limit: the decay rate fitted to
    log eps(t) against n gamma/(2 eta_N R) (references.viscous_decay_rate), eta_N = eta/2."""
    t0 = time.perf_counter()
    m = _material(case)
    b = case.bodies[0]
    R = b.radius_um * 1e-6
    sim, ts, eps = _mode_history(case, 20)
    # skip the first tenth: the start-up breathing transient of the compressible body
    keep = ts >= 0.1 * case.time.end_s
    rate = -np.polyfit(ts[keep], np.log(np.abs(eps[keep])), 1)[0]
    eta_N = _eta_newtonian(m)
    lam = ref.viscous_decay_rate(b.mode, m.surface_tension_N_m, eta_N, R)
    mu = m.youngs_solid_Pa / (2 * (1 + m.poisson))
    tau = m.viscosity_Pas / (2 * mu)
    errors = {"decay_rate": float(rate / lam - 1.0)}
    maxwell = ref.maxwell_decay_rate(lam, tau)
    return _result(
        case,
        sim,
        errors,
        t0,
        rate_1_s=float(rate),
        newtonian_1_s=lam,
        maxwell_1_s=maxwell,
        vs_maxwell=float(rate / maxwell - 1.0),
    )


def run_inviscid(case: Case) -> Result:
    """Oscillating shape mode n of a nearly inviscid disc: the period from the zero crossings of
    eps(t) against 2 pi / omega, omega^2 = n(n^2 - 1) gamma/(rho R^3) (references.
    inviscid_drop_omega); the amplitude lost per period is reported."""
    t0 = time.perf_counter()
    m = _material(case)
    b = case.bodies[0]
    R = b.radius_um * 1e-6
    omega = ref.inviscid_drop_omega(b.mode, m.surface_tension_N_m, m.density_kg_m3, R)
    period = 2 * np.pi / omega
    sim, ts, eps = _mode_history(case, max(40, int(80 * case.time.end_s / period)))
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
    return _result(
        case,
        sim,
        {"period": measured / period - 1.0},
        t0,
        period_s=measured,
        expected_s=period,
        amplitude_after_half_period=trough / abs(eps[0]),
    )


RUNNERS: dict[str, Callable[[Case], Result]] = {
    "bar": run_bar,
    "steffen": run_steffen,
    "perzyna": run_perzyna,
    "erf": run_erf,
    "gaussian": run_gaussian,
    "stefan": run_stefan,
    "energy": run_energy,
    "curvature": run_curvature,
    "laplace": run_laplace,
    "square": run_square,
    "viscous_decay": run_viscous_decay,
    "inviscid": run_inviscid,
}


def run(case: Case) -> Result:
    """Run the verification comparison that ``case.verification.kind`` names."""
    kind = case.verification.kind
    if kind not in RUNNERS:
        raise CaseError(
            f"verification.kind = {kind!r}: no comparison to run; one of {', '.join(RUNNERS)}"
        )
    return RUNNERS[kind](case)
