"""uGIMP shape functions, conservation, the vibrating bar, and the Perzyna return map."""

import math

import numpy as np
import pytest
import taichi as ti
from conftest import make_case

from taichi_sls import references as ref
from taichi_sls.case import Material
from taichi_sls.constitutive import embed3, perzyna_update
from taichi_sls.materials import material_row
from taichi_sls.shape import STENCIL, node_weight, stencil
from taichi_sls.simulation import Simulation, init_taichi


def test_gimp_partition_of_unity_and_gradient_sum():
    init_taichi(optimize=False)
    n = 500
    xs = ti.Vector.field(2, float, n)
    out = ti.Vector.field(3, float, n)

    @ti.kernel
    def sums(h: float):
        for p in range(n):
            base, w, dw = stencil(xs[p], 1.0 / h, h, 0.25 * h, 4)
            s = ti.Vector.zero(float, 3)
            for o in ti.static(ti.grouped(STENCIL)):
                N, g = node_weight(w, dw, o)
                s += ti.Vector([N, g[0], g[1]])
            out[p] = s

    rng = np.random.default_rng(1)
    h = 2e-6
    xs.from_numpy(rng.uniform(0, 10 * h, (n, 2)))
    sums(h)
    s = out.to_numpy()
    np.testing.assert_allclose(s[:, 0], 1.0, atol=1e-12)  # partition of unity
    np.testing.assert_allclose(s[:, 1:] * h, 0.0, atol=1e-12)  # gradients sum to zero


def _free_disc(transfer):
    return make_case(
        {
            "domain": {"width_um": 40.0, "height_um": 40.0},
            "bodies": [{"center_um": [20.0, 20.0], "radius_um": 8.0, "velocity_m_s": [0.3, -0.2]}],
            "physics": {"thermal": False, "surface_tension": False, "gravity_m_s2": [0.0, 0.0]},
            "boundary": {w: {"mechanical": "open"} for w in ("left", "right", "bottom", "top")},
            # no small-mass cut-off: it drops the momentum of nearly empty nodes (~1e-11 here)
            "solver": {"transfer": transfer, "small_mass": 0.0},
            "time": {"end_s": 1e-5},
        }
    )


@pytest.mark.parametrize("transfer", ["apic", "flip", "pic_flip"])
def test_free_body_conserves_mass_and_momentum(transfer):
    sim = Simulation(_free_disc(transfer))
    st = sim.state
    m = st.mass.to_numpy()
    # spin the disc so that stresses and grid transfers are exercised
    x = st.x.to_numpy()
    c = x.mean(axis=0)
    v = st.v.to_numpy() + 2e4 * np.stack([-(x[:, 1] - c[1]), x[:, 0] - c[0]], axis=1)
    st.v.from_numpy(v)
    p0 = (m[:, None] * v).sum(axis=0)
    sim.advance(300)
    p1 = (m[:, None] * st.v.to_numpy()).sum(axis=0)
    # round-off only: 300 steps of sums over ~800 points, against the momentum scale sum m |v|
    scale = (m * np.linalg.norm(v, axis=1)).sum()
    np.testing.assert_allclose(p1, p0, rtol=0, atol=1e-13 * scale)
    assert st.mass.to_numpy().sum() == m.sum()


def _bar(cells: int, v0: float = 0.1):
    """Fixed-free elastic bar, L = 25 um, E = 100 Pa, rho = 1 (Bardenhagen & Kober 2004)."""
    L = 25.0
    h = L / cells
    case = make_case(
        {
            "grid": {"spacing_um": h},
            "domain": {"width_um": L + 4 * h, "height_um": 4 * h},
            "bodies": [
                {"shape": "rect", "min_um": [0.0, 0.0], "max_um": [L, h], "material": "bar"}
            ],
            "materials": {
                "bar": {
                    "density_kg_m3": 1.0,
                    "youngs_solid_Pa": 100.0,
                    "youngs_liquid_Pa": 100.0,
                    "poisson": 0.0,
                }
            },
            "physics": {
                "thermal": False,
                "surface_tension": False,
                "plasticity": False,
                "gravity_m_s2": [0.0, 0.0],
            },
            "boundary": {
                "left": {"mechanical": "stick"},
                "right": {"mechanical": "open"},
                "top": {"mechanical": "open"},
                "bottom": {"mechanical": "slip"},
            },
            "time": {"safety": 0.2},
            # APIC: the bar measures the mechanics, not the PIC blend's numerical damping
            "solver": {"transfer": "apic"},
        }
    )
    sim = Simulation(case)
    st = sim.state
    x = st.x.to_numpy()
    v = np.zeros_like(x)
    v[:, 0] = v0 * np.sin(np.pi * x[:, 0] / (2 * L * 1e-6))
    st.v.from_numpy(v)
    m = st.mass.to_numpy()
    period = 2 * np.pi / ref.bar_omega(L * 1e-6, 100.0, 1.0)
    n_out = 40
    per = max(1, int(round(period / n_out / sim.dt)))
    ts, vc = [], []
    for _ in range(n_out):
        sim.advance(per)
        ts.append(sim.t)
        vc.append((m * st.v.to_numpy()[:, 0]).sum() / m.sum())
    # symplectic Euler: the point velocities after a step sit half a step behind the positions
    # (leapfrog), so the analytic velocity is taken at t - dt/2; otherwise an O(dt) phase lag
    exact = ref.bar_com_velocity(np.array(ts) - 0.5 * sim.dt, L * 1e-6, 100.0, 1.0, v0)
    return np.max(np.abs(np.array(vc) - exact)) / (2 * v0 / np.pi)


def test_vibrating_bar_against_analytic_with_convergence():
    # v0 = 0.01 m/s: strain amplitude 1e-3, the linear regime the analytic solution describes
    errs = [_bar(n, v0=0.01) for n in (8, 16, 32)]
    orders = [math.log2(errs[i] / errs[i + 1]) for i in range(2)]
    print("bar COM velocity errors (fraction of amplitude):", errs, "orders:", orders)
    # measured: 1.4e-2, 3.4e-3, 9.2e-4 (orders 2.1, 1.9). Tolerances: second-order convergence
    # (observed order above 1.7) and under 0.2 % of the amplitude at 32 cells
    assert errs[-1] < 2e-3
    assert min(orders) > 1.7


def test_vibrating_bar_large_amplitude():
    # v0 = 0.1 m/s (strain amplitude 1 %): geometric nonlinearity leaves a floor of ~0.4 %
    # (measured 4.2e-3 at 32 cells); the target is under 1 % of the amplitude
    assert _bar(32, v0=0.1) < 0.01


# ------------------------------------------------------------------------------ Perzyna

MU_MAT = Material(
    youngs_solid_Pa=1e5,
    poisson=0.3,
    yield_solid_Pa=1e3,
    hardening_solid_Pa=2e4,
    viscosity_model="constant",
    viscosity_Pas=50.0,
)


def _perzyna_history(strains: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Drive one point through prescribed pure-shear strains eps_xy; return |s| and alpha."""
    init_taichi(optimize=False)
    n = len(strains)
    mat = ti.field(float, (1, len(material_row(MU_MAT, 0.0))))
    mat.from_numpy(material_row(MU_MAT, 0.0)[None, :])
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
                    mat, 0, embed3(eps), epl, a, 0.0, 1.0, 300.0, dt, True, False
                )
                epl = epl2
                a = a2
                s = sig - sig.trace() / 3.0 * ti.Matrix.identity(float, 3)
                out[k, 0] = s.norm()
                out[k, 1] = a

    drive()
    r = out.to_numpy()
    return r[:, 0], r[:, 1]


def _mu():
    return MU_MAT.youngs_solid_Pa / (2 * (1 + MU_MAT.poisson))


def test_perzyna_constant_rate_matches_discrete_and_converges():
    mu, sy, H, eta = _mu(), MU_MAT.yield_solid_Pa, MU_MAT.hardening_solid_Pa, 50.0
    rate = 2.0  # engineering shear rate (1/s)
    t_end = 0.05
    errs = []
    for n in (200, 400, 800):
        dt = t_end / n
        t = dt * np.arange(1, n + 1)
        s, a = _perzyna_history(rate * t / 2.0, dt)
        _, s_ref, a_ref = ref.perzyna_shear_discrete(n, dt, rate, mu, sy, H, eta)
        # the solver's update is the discrete reference step for step, to round-off
        np.testing.assert_allclose(s, s_ref[1:], rtol=1e-10, atol=1e-9)
        np.testing.assert_allclose(a, a_ref[1:], rtol=1e-10, atol=1e-15)
        s_c, _ = ref.perzyna_shear_constant_rate(t, rate, mu, sy, H, eta)
        errs.append(np.max(np.abs(s - s_c)))
    ratios = [errs[i] / errs[i + 1] for i in range(2)]
    print("Perzyna constant-rate errors:", errs, "ratios:", ratios)
    # backward Euler: first order in dt, the error halves with dt (ratio 2 within 10 %)
    assert all(1.8 < r < 2.2 for r in ratios)


def test_perzyna_relaxation_ratio_is_exact():
    mu, H, eta = _mu(), MU_MAT.hardening_solid_Pa, 50.0
    dt = 1e-4
    n_load, n_hold = 50, 30
    strains = np.concatenate(
        [np.linspace(0, 0.05, n_load + 1)[1:], np.full(n_hold, 0.05)]
    )  # load past yield, then hold the strain fixed
    s, a = _perzyna_history(strains, dt)
    R = math.sqrt(2 / 3) * (MU_MAT.yield_solid_Pa + H * a)
    f = s - R
    r = f[n_load:] / f[n_load - 1 : -1]
    expected = ref.perzyna_relaxation_ratio(dt, eta / (2 * mu), mu, H)
    np.testing.assert_allclose(r, expected, rtol=1e-9)


def test_paper_stress_reading_is_reachable():
    """solver.stress_reading = "paper": eq. 39 as printed and p = lambda tr(eps)."""
    init_taichi(optimize=False)
    mat = ti.field(float, (1, len(material_row(MU_MAT, 0.0))))
    mat.from_numpy(material_row(MU_MAT, 0.0)[None, :])
    out = ti.Matrix.field(3, 3, float, 2)

    @ti.kernel
    def stress(exx: float, eyy: float):
        e = embed3(ti.Matrix([[exx, 0.0], [0.0, eyy]]))
        z = ti.Matrix.zero(float, 3, 3)
        out[0] = perzyna_update(mat, 0, e, z, 0.0, 0.0, 1.0, 300.0, 1e-3, False, False)[0]
        out[1] = perzyna_update(mat, 0, e, z, 0.0, 0.0, 1.0, 300.0, 1e-3, False, True)[0]

    exx, eyy = 1e-3, -4e-4
    stress(exx, eyy)
    model, paper = out.to_numpy()
    E, nu = MU_MAT.youngs_solid_Pa, MU_MAT.poisson
    mu, lam = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    e = np.diag([exx, eyy, 0.0])
    tr = np.trace(e)
    # plane-strain Hooke's law for the model reading
    np.testing.assert_allclose(model, lam * tr * np.eye(3) + 2 * mu * e, rtol=1e-12)
    np.testing.assert_allclose(paper, lam * tr * np.eye(3) + 2 * mu * e - tr / 3 * np.eye(3))


def test_musl_conserves_momentum():
    """The MUSL option (remapped grid velocity) keeps momentum exactly as well."""
    case = _free_disc("apic")
    case.solver.update = "musl"
    sim = Simulation(case)
    st = sim.state
    m = st.mass.to_numpy()
    p0 = (m[:, None] * st.v.to_numpy()).sum(axis=0)
    sim.advance(200)
    p1 = (m[:, None] * st.v.to_numpy()).sum(axis=0)
    np.testing.assert_allclose(p1, p0, rtol=1e-12)
