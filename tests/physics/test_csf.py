"""The paper's surface tension (``surface_tension.method = "csf"``): curvature from points, the
Laplace pressure, a square relaxing to a disc; the contact-line measure; the discs' equilibrium
start; the nolaser pair."""

import numpy as np
import pytest
from helpers import PAPER_SCENE, advance_steps, deep_update, make_case, neck_and_kinetic_energy

from taichi_sls.config import load_case
from taichi_sls.solver.monitor import column_material_length, neck_measures
from taichi_sls.solver.simulation import Simulation
from taichi_sls.studies import verification as ver

CSF = {"surface_tension": {"method": "csf"}}


def disc_curvature_error(R: float, h: float, **surface) -> tuple[float, float]:
    """(mean, RMS) relative curvature error over the interface nodes of a disc of points
    (cases/verification/curvature.toml with radius R and spacing h)."""
    body = {"shape": "disc", "radius_um": R, "center_um": [0.0, 0.0]}  # centred by the loader
    sets = {"bodies": [body], "surface_tension": {"method": "csf", **surface}}
    e = ver.run(ver.load("curvature", R / h, sets)).errors
    return e["curvature_mean"], e["curvature_rms"]


@pytest.mark.parametrize(
    "R, h, mean_tol, rms_tol",
    [
        # measured (default smoothing): R/h = 10: mean +4.2 %, RMS 5.2 %; R/h = 20: +0.3 %, 7.6 %,
        # the same at h = 2 um and 1 um (the method is scale free: error depends on R/h only,
        # and does not converge at a fixed smoothing in cells). Tolerances: the targets
        # at R/h = 20 (2 % mean, 10 % RMS); at R/h = 10 the blur's shrinkage sigma^2 / 2R shows
        # as a +4 % bias, allowed up to 6 %.
        (20.0, 2.0, 0.06, 0.10),
        pytest.param(10.0, 1.0, 0.06, 0.10, marks=pytest.mark.slow),
        pytest.param(20.0, 1.0, 0.02, 0.10, marks=pytest.mark.slow),
        pytest.param(40.0, 2.0, 0.02, 0.10, marks=pytest.mark.slow),
    ],
)
def test_disc_curvature_from_points(R, h, mean_tol, rms_tol):
    mean, rms = disc_curvature_error(R, h)
    print(f"R/h = {R / h:.0f}, h = {h} um: curvature mean error {mean:+.4f}, RMS {rms:.4f}")
    assert abs(mean) < mean_tol
    assert rms < rms_tol


@pytest.mark.slow  # the CSF option's longer runs; curvature and Laplace stay in the default
def test_unsmoothed_level_set_is_not_usable():
    """Why the smoothing is part of the method: eq. 21 redistanced, no smoothing, errs by order
    one and grows with R/h (the points' staircase amplified by (R/h)^2)."""
    raw = {"level_set_smoothing_passes": 0, "smoothing_passes": 0, "curvature_cap_h": 0.0}
    _, rms10 = disc_curvature_error(10.0, 1.0, **raw)
    _, rms20 = disc_curvature_error(20.0, 1.0, **raw)
    assert rms10 > 1.0 and rms20 > rms10


def test_laplace_pressure_of_a_static_disc():
    """A disc of Maxwell fluid at rest under surface tension carries the mean in-plane pressure
    gamma / R (2D Laplace law; cases/verification/laplace.toml at R/h = 10); the spurious
    velocities that remain are reported and bounded."""
    r = ver.run(ver.load("laplace", 10, CSF))
    print("Laplace, R/h = 10:", r.errors, r.info)
    # measured: pressure -1.1 %, |v|max 4.5e-3 m/s = 3.4e-3 of the capillary velocity
    # sqrt(gamma / rho R), capillary number eta_N |v| / gamma = 0.037 (the 1e-3 is
    # missed; docs/record/verification.md). Tolerances: 2 % on the pressure; spurious velocities
    # under 1 % of the capillary velocity
    assert abs(r.errors["pressure"]) < 0.02
    assert r.info["v_over_capillary"] < 1e-2


@pytest.mark.slow  # the CSF option's longer runs; curvature and Laplace stay in the default
def test_square_relaxes_towards_a_disc():
    """A square of soft, low-viscosity Maxwell fluid (cases/verification/square.toml) rounds off
    under surface tension, keeping its area."""
    r = ver.run(ver.load("square", 2.0, CSF))
    print("square:", r.errors, r.info)
    # measured: n = 4 amplitude 0.47 of its start after 300 us (0.92 at h = 4 um), area +1.0 %.
    # Tolerance: the amplitude falls below 0.6 of its start; the area (nearly incompressible)
    # within 2 %
    assert r.errors["mode4_left"] < 0.6
    assert r.errors["area"] < 0.02


def test_contact_line_on_constructed_shapes():
    h = 1.0
    off = 0
    # phi on a 41 x 41 grid: a dumbbell with a neck 6 units tall at x in [18, 22]
    xs = np.arange(41) * h
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    inside = ((X < 15) | (X > 25)) & (np.abs(Y - 20) < 10)
    neck = (np.abs(X - 20) <= 5) & (np.abs(Y - 20) < 3)
    phi = np.where(inside | neck, -1.0, 1.0)
    # a sharp +-1 phi puts crossings half way between nodes: the neck spans y in 17.5..22.5
    assert neck_measures(phi, h, off, 5.0, 35.0)[0] == pytest.approx(5.0)
    # a hole in the neck counts as missing material
    holed = phi.copy()
    holed[20, 20] = 1.0
    assert neck_measures(holed, h, off, 5.0, 35.0)[0] == pytest.approx(4.0)
    # a torn neck reads zero
    torn = phi.copy()
    torn[19:22, :] = 1.0
    assert neck_measures(torn, h, off, 5.0, 35.0)[0] == 0.0
    # linear phi: exact crossing
    # negative over 1 + 2 + 0.5 (crossings at 1/2 and 1/4 of their 2-wide intervals)
    assert column_material_length(np.array([1.0, -1.0, -1.0, 3.0]), 2.0) == pytest.approx(3.5)


def test_paper_scene_starts_near_8um():
    """The level set of eq. 21 (r_p = 0.375 h) reads the paper's Fig. 4a: 8 um."""
    sim = Simulation(make_case(deep_update(PAPER_SCENE, {"physics": {"thermal": False}, **CSF})))
    cl = sim.monitors()["contact_line_um"]
    assert 7.5 < cl < 9.0


def test_neck_span_counts_holes():
    h, off = 1.0, 0
    xs = np.arange(41) * h
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    inside = ((X < 15) | (X > 25)) & (np.abs(Y - 20) < 10)
    neck = (np.abs(X - 20) <= 5) & (np.abs(Y - 20) < 3)
    phi = np.where(inside | neck, -1.0, 1.0)
    phi[20, 20] = 1.0  # a hole: the material length drops, the span does not
    assert neck_measures(phi, h, off, 5.0, 35.0)[0] == pytest.approx(4.0)
    assert neck_measures(phi, h, off, 5.0, 35.0)[1] == pytest.approx(5.0)


def _floating_disc(initial_stress: str):
    """A PA12 disc (R = 20 um, h = 2 um) at 140 C, far from every wall, no gravity: surface
    tension alone."""
    return make_case(
        {
            "domain": {"width_um": 60.0, "height_um": 60.0},
            "bodies": [{"center_um": [30.0, 30.0], "radius_um": 20.0}],
            "physics": {"thermal": False, "gravity_m_s2": [0.0, 0.0]},
            "surface_tension": {"initial_stress": initial_stress, "method": "csf"},
            "time": {"dt_s": 5e-8, "end_s": 4e-5},
        }
    )


@pytest.mark.slow  # the CSF option's longer runs; curvature and Laplace stay in the default
def test_laplace_initial_stress_is_the_equilibrium_pressure():
    """initial_stress = "laplace": a disc starts with the in-plane pressure gamma/R (2D
    Young-Laplace), carried by the plane-strain elastic strain -p / 2(lambda + mu)."""
    case = _floating_disc("laplace")
    st = Simulation(case).state
    m = case.materials["PA12"]
    p = m.surface_tension_N_m / 20e-6
    E, nu = m.youngs_solid_Pa, m.poisson  # 140 C: solid
    lam_mu = E / (2 * (1 + nu) * (1 - 2 * nu))
    sig, eps = st.points.stress.to_numpy(), st.points.strain.to_numpy()
    np.testing.assert_allclose(sig[:, 0, 0], -p, rtol=1e-12)
    np.testing.assert_allclose(sig[:, 1, 1], -p, rtol=1e-12)
    np.testing.assert_allclose(sig[:, 0, 1], 0.0, atol=1e-12 * p)
    np.testing.assert_allclose(eps[:, 0, 0], -p / (2 * lam_mu), rtol=1e-12)
    assert np.all(Simulation(_floating_disc("none")).state.points.stress.to_numpy() == 0.0)


def test_laplace_initial_stress_keeps_a_disc_at_rest():
    """Started stress-free, a disc is compressed by its own Laplace pressure: its area swings to
    about twice the static strain gamma / (R (lambda + mu)) = 0.82 % (PA12 solid at 140 C).
    Started in equilibrium it stays: the area change left is what the CSF misses of gamma/R
    (about 10 % at R/h = 10, Accuracy in the README): measured 0.096 %, 0.12 of the static
    strain, against 1.3 % started stress-free; allowed: under a quarter of it."""
    m = _floating_disc("none").materials["PA12"]
    E, nu = m.youngs_solid_Pa, m.poisson
    static = m.surface_tension_N_m / 20e-6 / (E / (2 * (1 + nu) * (1 - 2 * nu)))
    swing = {}
    for kind in ("none", "laplace"):
        sim = Simulation(_floating_disc(kind))
        st = sim.state
        a0 = float((st.points.volume0.to_numpy() * st.points.J.to_numpy()).sum())
        worst = 0.0
        for _ in range(40):
            advance_steps(sim, 20)
            a = float((st.points.volume0.to_numpy() * st.points.J.to_numpy()).sum())
            worst = max(worst, abs(a / a0 - 1.0))
        swing[kind] = worst
    print(f"static strain {static:.4f}; largest area change: {swing}")
    assert swing["none"] > 0.8 * static
    assert swing["laplace"] < 0.25 * static


@pytest.mark.slow  # the CSF option's longer runs; curvature and Laplace stay in the default
def test_nolaser_neck_holds_and_kinetic_energy_decays():
    """Issue #4's laser-off check with the paper's force (cases/nolaser.toml, 1 ms): the
    contact line stays within 2 % of its start (measured: 8.27 -> 8.27-8.40 um) and the kinetic
    energy does not grow from noise (measured: 3.1e-10 J/m at 0.1 ms, 3.9e-13 J/m at 1 ms)."""
    sim = Simulation(
        load_case("nolaser", ["surface_tension.method=csf", "contact.neck_section=column"])
    )
    m0 = sim.monitors()
    lines, ke = neck_and_kinetic_energy(sim, 1e-4, 10)
    assert max(abs(c / m0["contact_line_um"] - 1.0) for c in lines) < 0.02
    assert ke[-1] < ke[0] and ke[-1] < 1e-11
