"""contact.settle: the run starts from the pair's own adhesive equilibrium (jobs/settle.py)."""

import json

import numpy as np
import pytest

from taichi_sls.config import CaseError, load_case
from taichi_sls.jobs.case_run import run_case
from taichi_sls.jobs.settle import settle
from taichi_sls.solver.simulation import Simulation

# the resolved 25 W pair on the coarse grid (688 points): it settles within about 0.1 ms
COARSE = [
    "contact.settle=true",
    "grid.spacing_um=4",
    "solver.optimize=false",
    "output.png=false",
    "output.gif=false",
]


def test_settling_restarts_the_clock_at_a_quiet_state_and_puts_the_laser_back():
    """Explicit settling (the hybrid's explicit steps), then implicit settling (its adaptive
    implicit steps from the start): the same neck, and after the implicit one the hybrid is back
    in its explicit phase at t = 0."""
    case = load_case("power25W_resolved", [*COARSE, "contact.settle_steps=explicit"])
    sim = Simulation(case)
    seeded = sim.monitors()
    explicit = settle(sim, case, progress=False)
    case = load_case("power25W_resolved", [*COARSE, "contact.settle_steps=implicit"])
    sim = Simulation(case)
    record = settle(sim, case, progress=False)
    print(explicit, record)
    # quiet by the rule of a case no laser heats, and the seeded contact has moved to get there
    for r in (explicit, record):
        assert r["kinetic_ratio"] < case.time.settled_kinetic_fraction
        assert r["time_s"] > 0.0 and r["steps"] > 0
        assert abs(r["neck_um"] / seeded["contact_line_um"] - 1.0) > 1e-3
    # backward Euler damps the ringing the explicit steps go through, to the same contact: the
    # necks agree within 0.1 %, in fewer steps (half here; a tenth and less on finer grids,
    # where the explicit contact rings longer: docs/record/convergence.md)
    assert abs(record["neck_um"] / explicit["neck_um"] - 1.0) < 1e-3
    assert record["steps"] < explicit["steps"]
    # no laser heat while settling: the pair is still at its initial temperature
    now = sim.monitors()
    assert now["laser_energy_J_per_m"] == 0.0 and now["T_max_C"] < case.thermal.initial_C + 1e-6
    # the clock, the step count and the start positions begin again; explicit steps first
    assert sim.t == 0.0 and sim.steps == 0 and now["contact_line_um"] == record["neck_um"]
    pt = sim.state.points
    assert np.array_equal(pt.x0.to_numpy(), pt.x.to_numpy())
    assert sim.explicit_now and sim.handover.handbacks == 0 and np.isnan(sim.handover.at_s)
    assert sim.state.scalars.dt[None] == sim.dt
    # the laser heats again from its own on_s = 0
    sim.advance_to(5e-6)
    assert sim.monitors()["laser_energy_J_per_m"] > 0.0


def test_implicit_settling_needs_implicit_steps():
    with pytest.raises(CaseError, match="contact.settle_steps"):
        load_case("power25W", ["contact.settle=true", "contact.settle_steps=implicit"])


def test_the_settled_neck_is_the_verdicts_unheated_baseline(tmp_path, capsys):
    case = load_case("power25W_resolved", COARSE)
    s = run_case(case, tmp_path / "run", progress=False)
    o = s["outcome"]
    print(json.dumps(s["settle"]), json.dumps(o, indent=1))
    assert s["status"] == "complete" and o["solidified"]
    # no separate unheated run: the settled pair is the unheated one
    assert "unheated baseline" not in capsys.readouterr().err
    assert o["neck_unheated_um"] == s["settle"]["neck_um"] == o["neck_initial_um"]
    assert o["fused"] is not None  # a verdict, against that neck
    # the hand-over to implicit steps comes after this run's laser, not the settling's quiet
    assert s["handover_s"] >= case.lasers_off_s()
    assert json.loads((tmp_path / "run" / "summary.json").read_text())["settle"] == s["settle"]


def test_a_pair_that_does_not_settle_in_time_fails_with_its_reason(tmp_path):
    case = load_case("power25W_resolved", [*COARSE, "time.max_s=3e-5"])
    s = run_case(case, tmp_path / "short", progress=False)
    assert s["status"] == "failed"
    assert "contact.settle" in s["error"] and "time.max_s = 3e-05" in s["error"]
    saved = json.loads((tmp_path / "short" / "summary.json").read_text())
    assert saved["status"] == "failed" and saved["error"] == s["error"]
