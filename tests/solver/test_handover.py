"""Explicit steps, then implicit ones (time.integrator = "hybrid", solver/handover.py): the
explicit phase is the explicit integrator bit for bit, the hand-over waits for the laser and the
motion, and the answer is the explicit run's at a fraction of its steps."""

import math

import numpy as np
import pytest
from helpers import advance_steps

from taichi_sls.config import CaseError, load_case
from taichi_sls.jobs.case_run import run_case
from taichi_sls.jobs.unheated import unheated_neck_um
from taichi_sls.solver.simulation import Simulation

HYBRID = ["time.integrator=hybrid"]


def test_the_explicit_phase_is_the_explicit_integrator_bit_for_bit():
    """Through the laser pulse the hybrid run steps the explicit kernels on its own view of the
    fields: after 150 steps (15 us, the pulse still on) every point array is the explicit
    run's, bit for bit."""
    runs = []
    for sets in ([], HYBRID):
        sim = Simulation(load_case("power25W_coarse", sets))
        sim.advance_to(150 * sim.dt)
        assert sim.steps == 150 and sim.explicit_now
        runs.append(sim.state.points.to_numpy())
    for k in ("x", "v", "T", "stress", "enthalpy", "F", "iso_strain"):
        assert np.array_equal(runs[0][k], runs[1][k]), k


@pytest.fixture(scope="module")
def explicit_1ms():
    """The coarse 25 W pair's explicit run to 1 ms: its monitors and steps."""
    explicit = Simulation(load_case("power25W_coarse"))
    advance_steps(explicit, round(1e-3 / explicit.dt))
    return explicit.monitors(), explicit.steps


def test_the_hybrid_neck_is_the_explicit_one_at_a_fraction_of_the_steps(explicit_1ms):
    """The coarse 25 W pair to 1 ms: the implicit step takes over after the laser is off and
    the kinetic energy has fallen below 1e-5 of the surface energy, and the neck and peak
    temperature are the explicit run's within 1 % (the peak falls in the explicit phase:
    equal), in under a fifth of its steps (measured 1,382 of 9,888; neck -0.1 %)."""
    hybrid = Simulation(load_case("power25W_coarse", HYBRID))
    # the adaptive step's smallest is the explicit one (dt_min_s = "auto" with the floor the
    # hybrid passes: tests/solver/test_adaptive.py)
    assert hybrid.adaptive.controls.dt_min == hybrid.dt
    hybrid.advance_to(1e-3)
    assert not hybrid.explicit_now and hybrid.handover.handbacks == 0
    assert 20e-6 <= hybrid.handover.at_s < 1e-3
    assert hybrid.t == pytest.approx(1e-3, rel=1e-12)
    a, steps = hybrid.monitors(), hybrid.steps
    b, explicit_steps = explicit_1ms
    print("hybrid:", steps, a["contact_line_um"], "explicit:", b["contact_line_um"])
    assert a["T_peak_C"] == b["T_peak_C"]
    assert a["contact_line_um"] == pytest.approx(b["contact_line_um"], rel=0.01)
    assert steps < explicit_steps / 5


def test_explicit_steps_take_back_a_step_too_short_for_the_implicit_one(explicit_1ms):
    """With time.handback_explicit_steps = 60, above the first implicit step (50 explicit
    steps), the adaptive step is too short at the hand-over: explicit steps take over again,
    their clock raised to start with a heat step, and a later stretch of them proposes a step
    long enough for the implicit one to resume. Through the alternation the run lands on 1 ms
    with the explicit run's neck within 1 %, as the plain hybrid does."""
    sim = Simulation(load_case("power25W_coarse", [*HYBRID, "time.handback_explicit_steps=60"]))
    sim.advance_to(sim.handover.lasers_off_s)
    while sim.explicit_now:
        advance_steps(sim, 1)
    advance_steps(sim, 1)  # the first implicit step would be 50 explicit ones: handed back instead
    assert sim.explicit_now and sim.handover.handbacks == 1
    assert (sim.state.scalars.step[None] - 1) % sim.explicit_state.cfg.heat_every == 0
    assert sim.state.scalars.dt[None] == sim.dt
    target = sim.t + 2.5 * sim.dt  # its clock is off the explicit grid: the steps reach it
    sim.advance_to(target)
    assert target <= sim.t < target + sim.dt
    sim.advance_to(1e-3)
    assert sim.t == pytest.approx(1e-3, rel=1e-12)
    a, (b, explicit_steps) = sim.monitors(), explicit_1ms
    print("hand-backs:", sim.handover.handbacks, sim.steps, a["contact_line_um"])
    assert sim.steps < explicit_steps / 2  # the implicit step resumed
    assert a["contact_line_um"] == pytest.approx(b["contact_line_um"], rel=0.01)


def test_hybrid_takes_the_implicit_restrictions():
    with pytest.raises(CaseError, match="surface_tension.method"):
        load_case("power25W_coarse", ["time.integrator=hybrid", "surface_tension.method=csf"])


@pytest.mark.slow  # a hybrid run to refreezing with verdicts: tests/jobs/test_bed_refrozen.py
def test_a_hybrid_run_to_refreezing_gives_its_verdict(tmp_path):
    """The coarse 25 W pair to refreezing as the main job: complete, with the unheated
    baseline (itself run hybrid, landing on fusion.baseline_s) within 1 % of the explicit
    one, so that the verdict is given."""
    sets = [*HYBRID, "time.stop=solidified", "output.png=false", "output.gif=false"]
    summary = run_case(load_case("power25W_coarse", sets), tmp_path, progress=False)
    outcome = summary["outcome"]
    assert summary["status"] == "complete" and outcome["fused"] is not None
    explicit = unheated_neck_um(load_case("power25W_coarse", ["time.stop=solidified"]))
    print("unheated neck, hybrid and explicit:", outcome["neck_unheated_um"], explicit)
    assert math.isfinite(explicit)
    assert outcome["neck_unheated_um"] == pytest.approx(explicit, rel=0.01)


def test_a_hybrid_run_resumes_in_its_implicit_phase(tmp_path):
    """A checkpoint written after the hand-over keeps the phase and the adaptive step's next
    size, and the hybrid's dt stays its explicit step: the resumed run takes the steps of the
    uninterrupted one (before, it came back with the implicit step as its explicit one and blew
    up). Not bit for bit: the linear solves reuse a factorization held in memory, not in the
    checkpoint, so the two agree to the Newton tolerance (1e-6 of each field's scale)."""
    case = load_case("power25W_coarse", [*HYBRID, "time.handover_kinetic_fraction=1e-3"])
    sim = Simulation(case)
    sim.advance_to(1e-4)
    assert not sim.explicit_now
    sim.save_checkpoint(tmp_path / "checkpoint.npz")
    sim.advance_to(2e-4)
    a, steps, dt = sim.state.points.to_numpy(), sim.steps, sim.dt
    again = Simulation(case)
    again.load_checkpoint(tmp_path / "checkpoint.npz")
    assert not again.explicit_now and again.dt == dt
    again.advance_to(2e-4)
    b = again.state.points.to_numpy()
    assert again.steps == steps
    for k in ("x", "v", "T", "F", "stress"):  # measured: 4e-7 (v) and below
        assert np.abs(a[k] - b[k]).max() <= 1e-6 * np.abs(a[k]).max(), k
