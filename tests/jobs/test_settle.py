"""contact.settle: the run starts from the pair's own adhesive equilibrium (jobs/settle.py)."""

import json

import numpy as np

from taichi_sls.config import load_case
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
    case = load_case("power25W_resolved", COARSE)
    sim = Simulation(case)
    seeded = sim.monitors()
    record = settle(sim, case, progress=False)
    print(record)
    # quiet by the rule of a case no laser heats, and the seeded contact has moved to get there
    assert record["kinetic_ratio"] < case.time.settled_kinetic_fraction
    assert record["time_s"] > 0.0 and record["steps"] > 0
    assert abs(record["neck_um"] / seeded["contact_line_um"] - 1.0) > 1e-3
    # no laser heat while settling: the pair is still at its initial temperature
    now = sim.monitors()
    assert now["laser_energy_J_per_m"] == 0.0 and now["T_max_C"] < case.thermal.initial_C + 1e-6
    # the clock, the step count and the start positions begin again; explicit steps first
    assert sim.t == 0.0 and sim.steps == 0 and now["contact_line_um"] == record["neck_um"]
    pt = sim.state.points
    assert np.array_equal(pt.x0.to_numpy(), pt.x.to_numpy())
    assert sim.explicit_now and sim.handover.handbacks == 0 and np.isnan(sim.handover.at_s)
    # the laser heats again from its own on_s = 0
    sim.advance_to(5e-6)
    assert sim.monitors()["laser_energy_J_per_m"] > 0.0


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
