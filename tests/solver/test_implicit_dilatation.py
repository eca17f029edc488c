"""One dilatation per cell (``solver.dilatation = "cell"``, physics/dilatation.py) in the implicit
step (solver/implicit.py): its tangent is the derivative of its internal force, and a free body
keeps its momentum and moves rigidly (docs/record/verification.md, "Neck growth at any angle")."""

import numpy as np
import pytest
from helpers import advance_steps, make_case

from taichi_sls.solver.simulation import Simulation
from taichi_sls.studies import verification as ver

CELL = {"dilatation": "cell", "optimize": False}


def test_cell_tangent_is_the_derivative_of_the_internal_force():
    """The Laplace disc of Maxwell fluid with a solvent viscosity (as test_implicit.py's tangent
    check), two steps in: the internal force is affine in the grid velocity, so the assembled
    tangent (deviatoric per point, volumetric per cell) times a velocity change is the force's
    change to round-off (measured 4e-16), and symmetric. Tolerance 1e-9 relative: a wrong
    corner, sign or modulus (2 a_mu / 3 for 2 a_mu / dim in 2D) shows at order one."""
    sets = {
        "time": {"integrator": "implicit", "dt_s": 2e-6},
        "materials": {"fluid": {"solvent_viscosity_Pa_s": 0.05}},
        "solver": CELL,
    }
    sim = Simulation(ver.load("laplace", 10, sets).case)
    advance_steps(sim, 2)
    system = sim.implicit.prepare()
    dv = np.random.default_rng(1).normal(size=system.n) * 1e-3  # m/s, the disc's flow
    f0, tangent = sim.implicit.internal(system, system.v0)
    f1, _ = sim.implicit.internal(system, system.v0 + dv)
    K = system.matrix(tangent)
    assert abs(K - K.T).max() == 0.0  # the points write the upper triangle; a reader mirrors it
    change = -(f1 - f0)
    assert np.linalg.norm(change) > 0.0
    assert np.linalg.norm(K @ dv - change) <= 1e-9 * np.linalg.norm(change)


def _free_disc(spin: float) -> tuple[Simulation, np.ndarray]:
    """A PA12 disc in free flight (no surface tension, gravity or walls) under implicit steps
    with the cells' dilatation (its light corners floored, solver.dilatation_mass_floor), spun
    at ``spin`` rad/s about its centre; no light-node cut (``time.implicit_small_mass = 0``: a
    resting node would drop its momentum)."""
    case = make_case(
        {
            "domain": {"width_um": 80.0, "height_um": 80.0},
            "bodies": [{"center_um": [30.0, 50.0], "radius_um": 8.0, "velocity_m_s": [0.3, -0.2]}],
            "physics": {"thermal": False, "surface_tension": False, "gravity_m_s2": [0.0, 0.0]},
            "boundary": {w: {"mechanical": "open"} for w in ("left", "right", "bottom", "top")},
            "solver": {"transfer": "apic", **CELL},
            "time": {"end_s": 1e-4, "integrator": "implicit", "implicit_small_mass": 0.0},
        }
    )
    sim = Simulation(case)
    pt = sim.state.points
    x = pt.x.to_numpy()
    c = x.mean(axis=0)
    v = pt.v.to_numpy() + spin * np.stack([-(x[:, 1] - c[1]), x[:, 0] - c[0]], axis=1)
    pt.v.from_numpy(v)
    return sim, v


def test_free_body_under_implicit_cell_steps_keeps_momentum_and_rigid_motion():
    """Spinning: the floored corner gradients of every cell still sum to zero, so the cells'
    forces do: momentum to round-off (measured 3e-15 of sum m |v| over 30 steps of 2.5 us; bar
    1e-13). Translating only: no spurious motion, every
    point keeps the body's velocity and its volume (measured 2e-14 m/s against 0.36 m/s,
    |J - 1| 2e-13; bars 1e-12)."""
    sim, v = _free_disc(2e4)
    m = sim.state.points.mass.to_numpy()
    p0 = (m[:, None] * v).sum(axis=0)
    advance_steps(sim, 30)
    assert sim.implicit.last.iterations >= 1
    p1 = (m[:, None] * sim.state.points.v.to_numpy()).sum(axis=0)
    scale = (m * np.linalg.norm(v, axis=1)).sum()
    np.testing.assert_allclose(p1, p0, rtol=0, atol=1e-13 * scale)

    sim, v = _free_disc(0.0)
    advance_steps(sim, 30)
    pt = sim.state.points
    np.testing.assert_allclose(pt.v.to_numpy(), v, rtol=0, atol=1e-12 * np.abs(v).max())
    np.testing.assert_allclose(pt.J.to_numpy(), 1.0, rtol=0, atol=1e-12)


@pytest.mark.xfail(
    strict=True,
    reason="issue #55: from Hopper's outline (no clock alignment) the cells' dilatation runs "
    "ahead of Hopper early: hopper_pa12 at R0/h = 10 +7.3 / +4.7 % at tau = 0.5 / 1 (each "
    "point's own -2.3 / -2.3 %), as the explicit step does on hopper_shape (+13.7 / +5.4 %)",
)
def test_cell_dilatation_sinters_hopper_pa12_at_10_ms_steps():
    """cases/verification/hopper_pa12.toml at R0/h = 10 (Table 3's melt at 180 C, 10 ms steps,
    inertia negligible), r_n / R0 within the issue's 3 % of Hopper at tau = 0.5 and 1 and the
    area within 0.5 %, as each point's own dilatation meets (test_implicit.py). Without the
    implicit step's floor of the cell's gradient the neck tore by 0.2 s and Newton failed at
    0.5 s; with it the run completes, one Newton iteration a step, but ahead of Hopper from its
    first steps, as the explicit step is on Hopper's outline (docs/record/verification.md)."""
    r = ver.run(ver.load("hopper_pa12", 10, {"solver": CELL}))
    print("hopper_pa12, cell:", r.errors, r.steps)
    assert abs(r.errors["area"]) < 0.005
    for tau in (0.5, 1):
        assert abs(r.errors[f"neck_tau{tau:g}"]) < 0.03
