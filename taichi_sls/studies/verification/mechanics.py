"""Verification of the mechanics: the vibrating bar, the manufactured solution, the Perzyna
return map at one point, the finite-strain update at one point."""

import math
import time

import numpy as np

from ...config import CaseError, Material
from .. import references as ref
from .common import Result, material, result, samples, transfer_label
from .setups import simulation
from .spec import VerificationCase


def run_bar(vc: VerificationCase) -> Result:
    """Fixed-free bar in its first axial mode: centre-of-mass velocity against (2 v0/pi)
    cos(w t) (references.bar_com_velocity), max over 40 samples, relative to 2 v0/pi."""
    case = vc.case
    t0 = time.perf_counter()
    sim = simulation(vc)
    st = sim.state
    m = st.points.mass.to_numpy()
    mat = material(case)
    L = case.bodies[0].max_um[0] * 1e-6
    v0 = vc.spec.velocity_amplitude_m_s
    ts, vc = samples(
        sim, 40, case.time.end_s, lambda: float((m * st.points.v.to_numpy()[:, 0]).sum() / m.sum())
    )
    # symplectic Euler: the point velocities after a step sit half a step behind the positions
    # (leapfrog), so the analytic velocity is taken at t - dt/2; otherwise an O(dt) phase lag.
    # Backward Euler's velocity is the step's end
    lag = 0.0 if sim.implicit is not None else 0.5 * sim.dt
    exact = ref.bar_com_velocity(ts[1:] - lag, L, mat.youngs_solid_Pa, 1.0, v0)
    err = float(np.max(np.abs(vc[1:] - exact))) / (2 * v0 / np.pi)
    amp_cells = v0 / ref.bar_omega(L, mat.youngs_solid_Pa, mat.density_kg_m3) / st.cfg.h
    return result(case, sim, {"com_velocity": err}, t0, amplitude_cells=amp_cells)


def run_steffen(vc: VerificationCase) -> Result:
    """Manufactured solution of a fixed-fixed bar (references.steffen_displacement): RMS over the
    points of the displacement error, max over 20 samples, relative to the amplitude A."""
    case = vc.case
    t0 = time.perf_counter()
    sim = simulation(vc)
    st = sim.state
    mat = material(case)
    L = case.bodies[0].max_um[0] * 1e-6
    A = vc.spec.displacement_amplitude_um * 1e-6
    X = st.points.x0.to_numpy()[:, 0]

    def rms() -> float:
        u = st.points.x.to_numpy()[:, 0] - X
        exact = ref.steffen_displacement(X, sim.t, L, A, mat.youngs_solid_Pa, mat.density_kg_m3)
        return float(np.sqrt(np.mean((u - exact) ** 2)))

    _, errs = samples(sim, 20, case.time.end_s, rms)
    return result(case, sim, {"displacement_rms": float(errs.max()) / A}, t0)


def perzyna_history(mat: Material, strains: np.ndarray, dt: float) -> tuple[np.ndarray, ...]:
    """Drive one point of the solver's return map (constitutive.perzyna_update) through the
    pure-shear strains eps_xy; returns (||s||, alpha) after every step."""
    from taichi_sls.backend import ti

    from ...physics.codes import StressReading
    from ...physics.constitutive import embed3, perzyna_update
    from ...physics.materials import material_struct
    from ...solver.params import material_values
    from ...solver.simulation import init_taichi

    init_taichi(optimize=False)
    n = len(strains)
    mf = material_struct().field(shape=1)
    mf.from_numpy({k: np.array([v]) for k, v in material_values(mat, 0.0).items()})
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
                    mf[0], embed3(eps), epl, a, 0.0, 1.0, 300.0, dt, True, StressReading.MODEL
                )
                epl = epl2
                a = a2
                s = sig - sig.trace() / 3.0 * ti.Matrix.identity(float, 3)
                out[k, 0] = s.norm()
                out[k, 1] = a

    drive()
    r = out.to_numpy()
    return r[:, 0], r[:, 1]


def elastic_state(mat: Material, e0: np.ndarray, xi: float) -> tuple[np.ndarray, np.ndarray]:
    """(Fe, sigma) of a point at rest (J = 1) carrying the symmetric 3x3 elastic strain e0 at
    solid fraction xi: the stretch exp(e0) of the finite form and Hooke's stress, which is its
    Hencky stress too."""
    E = xi * mat.youngs_solid_Pa + (1 - xi) * mat.youngs_liquid_Pa
    nu = xi * mat.poisson + (1 - xi) * mat.poisson_liquid
    mu, K = E / (2 * (1 + nu)), E / (3 * (1 - 2 * nu))
    w, Q = np.linalg.eigh(e0)
    tr = np.trace(e0)
    sig = K * tr * np.eye(3) + 2 * mu * (e0 - tr / 3 * np.eye(3))
    return Q @ np.diag(np.exp(w)) @ Q.T, sig


def constitutive_history(
    mat: Material,
    incs: np.ndarray,
    dt: float,
    *,
    strain: str = "finite",
    e0: np.ndarray | None = None,
    xi: np.ndarray | None = None,
    plastic: bool = True,
    T_K: float = 300.0,
) -> np.ndarray:
    """Drive one point of the solver's stress update through prescribed relative deformation
    gradients ``incs`` (n, 3, 3; f = I + dt L, f_zz = 1 in plane strain) from the elastic
    strain e0 at rest (F = I). ``strain``: "finite" (constitutive.hencky_update) or "small" (the
    incremental form, constitutive.perzyna_increment, with d eps = sym(f) - I); ``xi``: the
    solid fraction of every step (default solid). Returns the Cauchy stress after every step
    (n, 3, 3)."""
    from ...physics.materials import material_struct
    from ...solver.params import material_values
    from ...solver.simulation import init_taichi

    init_taichi(optimize=False)
    n = len(incs)
    xs = np.ones(n) if xi is None else np.asarray(xi, dtype=float)
    Fe0, sig0 = elastic_state(mat, np.zeros((3, 3)) if e0 is None else e0, float(xs[0]))
    mf = material_struct().field(shape=1)
    mf.from_numpy({k: np.array([v]) for k, v in material_values(mat, 0.0).items()})
    out = np.zeros((n, 3, 3))
    _drive(
        mf,
        np.ascontiguousarray(incs, dtype=float),
        np.ascontiguousarray(xs),
        np.stack([Fe0, sig0]),
        out,
        dt,
        T_K,
        strain == "finite",
        plastic,
    )
    return out


def _drive_kernel():
    """The point driver of :func:`constitutive_history`, built once (ndarray arguments: one
    compile, which Taichi's offline cache keeps across re-initialisations)."""
    from taichi_sls.backend import ti

    from ...physics.constitutive import SQRT23, hencky_update, perzyna_increment

    @ti.func
    def mat3(a: ti.template(), k):
        m = ti.Matrix.zero(float, 3, 3)
        for i, j in ti.static(ti.ndrange(3, 3)):
            m[i, j] = a[k, i, j]
        return m

    @ti.kernel
    def drive(
        mf: ti.template(),
        f_in: ti.types.ndarray(),
        x_in: ti.types.ndarray(),
        start: ti.types.ndarray(),
        out: ti.types.ndarray(),
        dt: float,
        T_K: float,
        finite: ti.template(),
        plastic: ti.template(),
    ):
        ti.loop_config(serialize=True)
        for _ in range(1):
            I3 = ti.Matrix.identity(float, 3)
            Fe, sig, F = mat3(start, 0), mat3(start, 1), I3
            alpha, xl = 0.0, x_in[0]
            for k in range(f_in.shape[0]):
                f = mat3(f_in, k)
                F = f @ F
                dgam = 0.0
                if ti.static(finite):
                    sig, Fe, dgam, _n = hencky_update(
                        mf[0], Fe, xl, alpha, f, 0.0, x_in[k], T_K, F.determinant(), dt,
                        plastic, 2,
                    )  # fmt: skip
                    xl = x_in[k]
                else:
                    deps = 0.5 * (f + f.transpose()) - I3
                    sig, dgam, _n = perzyna_increment(
                        mf[0], sig, deps, 0.0, alpha, x_in[k], T_K, dt, plastic
                    )
                alpha += SQRT23 * dgam
                for i, j in ti.static(ti.ndrange(3, 3)):
                    out[k, i, j] = sig[i, j]

    return drive


def _drive(*args) -> None:
    global _DRIVE
    if _DRIVE is None:
        _DRIVE = _drive_kernel()
    _DRIVE(*args)


_DRIVE = None


def rotation_increment(dtheta: float) -> np.ndarray:
    """The exact in-plane rotation by dtheta as a relative deformation gradient (3x3)."""
    c, s = math.cos(dtheta), math.sin(dtheta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def shear_increment(rate: float, dt: float) -> np.ndarray:
    """f = I + dt L of simple shear v_x = rate y."""
    f = np.eye(3)
    f[0, 1] = rate * dt
    return f


def run_perzyna(vc: VerificationCase) -> Result:
    """Perzyna return map at one point (eqs. 40-45), time step dt = case.time.dt_s:

    - ``rate_vs_closed_form``: constant-rate pure shear against the continuous closed form
      (references.perzyna_shear_constant_rate), max |s| error over the run / final |s|;
    - ``rate_vs_discrete``: the same against the step-by-step reference (round-off);
    - ``relaxation_ratio``: at a held strain, max relative error of the overstress ratio per step
      against (tau/dt)/(tau/dt + 1 + H/3mu) (references.perzyna_relaxation_ratio).
    """
    case = vc.case
    t0 = time.perf_counter()
    mat = material(case)
    v = vc.spec
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
        transfer=transfer_label(case),  # no grid transfer: the label keeps the rows together
        precision=case.solver.precision,
        info={"tau_s": eta / (2 * mu), "overstress_at_hold": float(f[n_load - 1])},
    )


def run_finite_strain(vc: VerificationCase) -> Result:
    """The finite-strain update (solver.strain = "finite", constitutive.hencky_update) at one
    point of a Maxwell material (zero yield; viscosity_model = "constant"), dt = case.time.dt_s,
    n = end_s / dt steps:

    - ``maxwell_relaxation``: a point prestressed in shear (hold_strain) held at rest, max
      deviator error against s0 exp(-t / tau) (references.maxwell_relaxation) / s0;
    - ``maxwell_shear``: simple shear at shear_rate_1_s from rest, max shear stress error
      against mu rate tau (1 - exp(-t / tau)) (references.maxwell_shear_stress) / its steady
      value (first order in dt, plus the finite-strain terms of order (rate tau)^2);
    - ``quarter_turn``: the prestressed point (elastic) turned by a quarter turn in n exact
      rotation increments, max |sigma - R sigma0 R^T| / |sigma0| (round-off);
    - ``full_turn_invariants``: a full turn in n increments, max relative drift of pressure
      and von Mises stress (round-off).
    """
    case = vc.case
    t0 = time.perf_counter()
    mat = material(case)
    v = vc.spec
    if mat.viscosity_model != "constant":
        raise CaseError("verification.kind = 'finite_strain': needs viscosity_model = 'constant'")
    mu = mat.youngs_solid_Pa / (2 * (1 + mat.poisson))
    tau = mat.viscosity_Pas / (2 * mu)
    dt = float(case.time.dt_s)
    n = int(round(case.time.end_s / dt))
    t = dt * np.arange(1, n + 1)
    e0 = np.zeros((3, 3))
    e0[0, 1] = e0[1, 0] = v.hold_strain
    sig0 = elastic_state(mat, e0, 1.0)[1]
    rest = constitutive_history(mat, np.tile(np.eye(3), (n, 1, 1)), dt, e0=e0)
    relax = np.abs(rest[:, 0, 1] - ref.maxwell_relaxation(t, sig0[0, 1], tau)).max()
    shear = constitutive_history(mat, np.tile(shear_increment(v.shear_rate_1_s, dt), (n, 1, 1)), dt)
    steady = mu * v.shear_rate_1_s * tau
    shear_err = np.abs(shear[:, 0, 1] - ref.maxwell_shear_stress(t, v.shear_rate_1_s, mu, tau))
    quarter = rotation_increment(0.5 * math.pi)
    q = constitutive_history(
        mat, np.tile(rotation_increment(0.5 * math.pi / n), (n, 1, 1)), dt, e0=e0, plastic=False
    )[-1]
    full = constitutive_history(
        mat, np.tile(rotation_increment(2 * math.pi / n), (n, 1, 1)), dt, e0=e0, plastic=False
    )

    def drift(x: np.ndarray, x0: float) -> float:
        return float(np.abs(x / x0 - 1.0).max()) if x0 != 0.0 else float(np.abs(x).max())

    p = np.trace(full, axis1=1, axis2=2) / 3
    dev = full - p[:, None, None] * np.eye(3)
    dev0 = sig0 - np.trace(sig0) / 3 * np.eye(3)
    mises = np.sqrt(1.5 * (dev * dev).sum(axis=(1, 2)))
    scale = float(np.abs(sig0).max())
    errors = {
        "maxwell_relaxation": float(relax / abs(sig0[0, 1])),
        "maxwell_shear": float(shear_err.max()) / steady,
        "quarter_turn": float(np.abs(q - quarter @ sig0 @ quarter.T).max()) / scale,
        "full_turn_invariants": max(
            float(np.abs(p - np.trace(sig0) / 3).max()) / scale,
            drift(mises, float(np.sqrt(1.5 * (dev0 * dev0).sum()))),
        ),
    }
    return Result(
        case=case.case.name,
        h_um=case.grid.spacing_um,
        dt_s=dt,
        errors=errors,
        wall_s=time.perf_counter() - t0,
        steps=4 * n,
        transfer=transfer_label(case),  # no grid transfer: the label keeps the rows together
        precision=case.solver.precision,
    )
