"""Surface tension: curvature from points, Laplace pressure, a square relaxing to a disc, and the
contact-line measure."""

import numpy as np
import pytest
from conftest import PAPER_SCENE, deep_update, make_case

from taichi_sls.monitor import column_material_length, contact_line
from taichi_sls.simulation import Simulation
from taichi_sls.step import surface_only

OPEN = {
    w: {"mechanical": "open", "thermal": "insulated"} for w in ("left", "right", "bottom", "top")
}


def _disc_case(R: float, h: float, surface: dict | None = None, **extra) -> dict:
    W = 2 * R + 12 * h
    # centre off the grid lines so that the seeding is not symmetric about a node
    data = {
        "grid": {"spacing_um": h},
        "domain": {"width_um": W, "height_um": W},
        "bodies": [{"center_um": [W / 2 + 0.123 * h, W / 2 + 0.377 * h], "radius_um": R}],
        "physics": {"thermal": False, "gravity_m_s2": [0.0, 0.0]},
        "surface_tension": surface or {},
        "boundary": OPEN,
    }
    return deep_update(data, extra)


def disc_curvature_error(R: float, h: float, **surface) -> tuple[float, float]:
    """(mean, RMS) relative curvature error over the interface nodes of a disc of points."""
    sim = Simulation(make_case(_disc_case(R, h, surface)))
    surface_only(sim.state)
    k = sim.state.kappa.to_numpy()
    iface = (sim.state.kvalid.to_numpy() & 2) > 0
    rel = k[iface] * R * 1e-6 - 1.0
    return float(rel.mean()), float(np.sqrt(np.mean(rel**2)))


@pytest.mark.parametrize(
    "R, h, mean_tol, rms_tol",
    [
        # measured (default smoothing): R/h = 10: mean +4.2 %, RMS 5.2 %; R/h = 20: +0.3 %, 7.6 %,
        # the same at h = 2 um and 1 um (the method is scale free: error depends on R/h only,
        # and does not converge at a fixed smoothing in cells). Tolerances: the targets
        # at R/h = 20 (2 % mean, 10 % RMS); at R/h = 10 the blur's shrinkage sigma^2 / 2R shows
        # as a +4 % bias, allowed up to 6 %.
        (20.0, 2.0, 0.06, 0.10),
        (10.0, 1.0, 0.06, 0.10),
        (20.0, 1.0, 0.02, 0.10),
        (40.0, 2.0, 0.02, 0.10),
    ],
)
def test_disc_curvature_from_points(R, h, mean_tol, rms_tol):
    mean, rms = disc_curvature_error(R, h)
    print(f"R/h = {R / h:.0f}, h = {h} um: curvature mean error {mean:+.4f}, RMS {rms:.4f}")
    assert abs(mean) < mean_tol
    assert rms < rms_tol


def test_unsmoothed_level_set_is_not_usable():
    """Why the smoothing is part of the method: eq. 21 redistanced, no smoothing, errs by order
    one and grows with R/h (the points' staircase amplified by (R/h)^2)."""
    raw = {"level_set_smoothing_passes": 0, "smoothing_passes": 0, "curvature_cap_h": 0.0}
    _, rms10 = disc_curvature_error(10.0, 1.0, **raw)
    _, rms20 = disc_curvature_error(20.0, 1.0, **raw)
    assert rms10 > 1.0 and rms20 > rms10


def test_laplace_pressure_of_a_static_disc():
    """A stiff elastic disc under surface tension settles to a uniform mean in-plane pressure
    gamma / R (2D Laplace law); the spurious velocities that remain are reported and bounded."""
    R, h, gamma, rho = 20.0, 2.0, 36.3e-3, 1020.0
    case = make_case(
        _disc_case(
            R,
            h,
            # PIC damps the start-up waves so that the static state can be read
            solver={"transfer": "pic_flip", "flip_ratio": 0.0},
            physics={"plasticity": False},
            materials={"PA12": {"youngs_solid_Pa": 1e6, "youngs_liquid_Pa": 1e6}},
        )
    )
    sim = Simulation(case)
    st = sim.state
    sim.advance(int(round(60e-6 / sim.dt)))  # the breathing mode has decayed by then
    ps, vs = [], []
    for _ in range(8):  # average the residual oscillation over 40 us
        sim.advance(int(round(5e-6 / sim.dt)))
        x = st.x.to_numpy()
        inner = np.linalg.norm(x - x.mean(axis=0), axis=1) < 0.5 * R * 1e-6
        sig = st.sigma.to_numpy()
        ps.append(np.mean(-0.5 * (sig[inner, 0, 0] + sig[inner, 1, 1])))
        vs.append(np.linalg.norm(st.v.to_numpy(), axis=1).max())
    err = np.mean(ps) / (gamma / (R * 1e-6)) - 1.0
    # spurious velocity against the capillary-inertial velocity sqrt(gamma / (rho R))
    we = max(vs) / np.sqrt(gamma / (rho * R * 1e-6))
    print(
        f"Laplace pressure error {err:+.4f} (R/h = 10), spurious |v|max {max(vs):.2e} m/s "
        f"= {we:.1e} of the capillary velocity"
    )
    # measured: +0.3 %, |v|max 1.7e-3 m/s (1.2e-3 of the capillary velocity). Tolerances: 2 %
    # on the pressure; spurious velocities under 1 % of the capillary velocity
    assert abs(err) < 0.02
    assert we < 1e-2


def test_square_relaxes_towards_a_disc():
    """A square of a soft, low-viscosity Perzyna fluid (zero yield) rounds off under surface
    tension, keeping its area."""
    h = 2.0
    case = make_case(
        {
            "grid": {"spacing_um": h},
            "domain": {"width_um": 48.0, "height_um": 48.0},
            "bodies": [{"shape": "rect", "min_um": [14.0, 14.0], "max_um": [34.0, 34.0]}],
            "materials": {
                # nearly incompressible Maxwell fluid: visco-capillary time eta R / gamma = 28 us
                "PA12": {
                    "youngs_solid_Pa": 1e5,
                    "poisson": 0.45,
                    "yield_solid_Pa": 0.0,
                    "yield_liquid_Pa": 0.0,
                    "hardening_solid_Pa": 0.0,
                    "viscosity_model": "constant",
                    "viscosity_Pas": 0.1,
                }
            },
            "physics": {"thermal": False, "gravity_m_s2": [0.0, 0.0]},
            "boundary": OPEN,
            "solver": {"transfer": "pic_flip", "flip_ratio": 0.5},
        }
    )
    sim = Simulation(case)
    st = sim.state

    def corner_excess() -> float:
        x = st.x.to_numpy()
        r = np.linalg.norm(x - x.mean(axis=0), axis=1)
        area = (st.vol0.to_numpy() * st.J.to_numpy()).sum()
        return r.max() / np.sqrt(area / np.pi), area

    e0, a0 = corner_excess()
    sim.advance(int(round(300e-6 / sim.dt)))
    e1, a1 = corner_excess()
    print(f"max radius / disc radius: {e0:.3f} -> {e1:.3f}; area change {a1 / a0 - 1:+.4f}")
    # measured: 1.191 -> 1.082 in 300 us, area -1.0 %. Tolerance: the corners pull in more than
    # half the way to the disc; the area (nearly incompressible) within 2 %
    assert e1 - 1.0 < 0.5 * (e0 - 1.0)
    assert abs(a1 / a0 - 1.0) < 0.02


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
    assert contact_line(phi, h, off, 5.0, 35.0) == pytest.approx(5.0)
    # a hole in the neck counts as missing material
    holed = phi.copy()
    holed[20, 20] = 1.0
    assert contact_line(holed, h, off, 5.0, 35.0) == pytest.approx(4.0)
    # a torn neck reads zero
    torn = phi.copy()
    torn[19:22, :] = 1.0
    assert contact_line(torn, h, off, 5.0, 35.0) == 0.0
    # linear phi: exact crossing
    # negative over 1 + 2 + 0.5 (crossings at 1/2 and 1/4 of their 2-wide intervals)
    assert column_material_length(np.array([1.0, -1.0, -1.0, 3.0]), 2.0) == pytest.approx(3.5)


def test_paper_scene_starts_near_8um():
    sim = Simulation(make_case(deep_update(PAPER_SCENE, {"physics": {"thermal": False}})))
    cl = sim.monitors()["contact_line_um"]
    assert 7.5 < cl < 9.0  # the paper's Fig. 4a: 8 um


def test_neck_span_counts_holes():
    h, off = 1.0, 0
    xs = np.arange(41) * h
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    inside = ((X < 15) | (X > 25)) & (np.abs(Y - 20) < 10)
    neck = (np.abs(X - 20) <= 5) & (np.abs(Y - 20) < 3)
    phi = np.where(inside | neck, -1.0, 1.0)
    phi[20, 20] = 1.0  # a hole: the material length drops, the span does not
    assert contact_line(phi, h, off, 5.0, 35.0) == pytest.approx(4.0)
    assert contact_line(phi, h, off, 5.0, 35.0, span=True) == pytest.approx(5.0)
