"""The step chosen by the physics (solver/adaptive.py) and the backward-Euler heat
(solver/implicit_heat.py): the controller's rules, the state it restores to redo a step, a main
job that lands its frames and the laser's switch-off, and the heat against the erf solution at
steps far beyond its explicit limit."""

import dataclasses

import numpy as np
import pytest
from helpers import explicit_coarse_peak_C

import taichi_sls
from taichi_sls.config import CaseError, load_case
from taichi_sls.jobs.schedule import frame_steps
from taichi_sls.solver import checkpoint
from taichi_sls.solver.adaptive import (
    GROWTH,
    SAFETY,
    SHRINK,
    PointsPass,
    StepControls,
    copy_points,
    laser_switch_times,
    next_step,
)
from taichi_sls.solver.fields import POINT_MEMBERS, struct_type
from taichi_sls.solver.guard import SimulationError
from taichi_sls.solver.implicit import ImplicitStepper, NewtonError
from taichi_sls.solver.simulation import Simulation
from taichi_sls.solver.time_step import heat_step_max
from taichi_sls.studies import verification as ver

ADAPTIVE = ["time.integrator=implicit", "time.adaptive=true"]
CONTROLS = StepControls(dt_min=1e-9, dt_max=1e-3, temperature_K=5.0, strain=0.02, cells=0.25)


def test_next_step_follows_the_controls():
    """dt SAFETY / ratio, at most GROWTH and at least SHRINK times the last, within bounds."""
    assert next_step(1e-6, SAFETY, CONTROLS) == pytest.approx(1e-6)
    assert next_step(1e-6, 0.1, CONTROLS) == pytest.approx(GROWTH * 1e-6)
    assert next_step(1e-6, 1.8, CONTROLS) == pytest.approx(0.5e-6)
    assert next_step(1e-6, 100.0, CONTROLS) == pytest.approx(SHRINK * 1e-6)
    assert next_step(8e-4, 0.0, CONTROLS) == CONTROLS.dt_max
    assert next_step(2e-9, 100.0, CONTROLS) == CONTROLS.dt_min


def test_the_smallest_step_of_a_hybrid_is_its_explicit_step():
    """dt_min_s = "auto": the first step / 1000, or the floor given (the hybrid passes its
    explicit step: checked on the hybrid run of tests/solver/test_handover.py, which compiles
    one anyway); a number given in the case wins over both."""
    case = load_case("power25W_coarse", ADAPTIVE)
    assert StepControls.from_case(case, 1e-6).dt_min == pytest.approx(1e-9)
    assert StepControls.from_case(case, 1e-6, floor=1e-7).dt_min == 1e-7
    fixed = load_case("power25W_coarse", [*ADAPTIVE, "time.dt_min_s=3e-8"])
    assert StepControls.from_case(fixed, 1e-6, floor=1e-7).dt_min == 3e-8


def test_step_changes_measure_temperature_and_strain():
    """The strain increment is |F1 F0^-1 - I|: blind to the deformation a point already has
    (a rotated, stretched F0), equal to the step's own increment; the plastic one is the
    largest rise of the equivalent plastic strain (here of another point, so that the two
    measures tell apart); the temperature change is the largest of any point. The ratio reads
    the measure that time.strain_control names."""
    sim = Simulation(load_case("power25W_coarse", ADAPTIVE))
    n = sim.state.n_points
    rng = np.random.default_rng(3)
    c, s = np.cos(0.7), np.sin(0.7)
    F0 = np.array([[c, -s], [s, c]]) @ np.diag([1.5, 0.6])
    e = 0.01 * rng.normal(size=(2, 2))
    F = np.repeat(F0[None], n, axis=0)
    T = np.full(n, 400.0)
    sim.adaptive.save()
    sim.adaptive.before.F.from_numpy(F)
    sim.adaptive.before.T.from_numpy(T)
    F[7] = (np.eye(2) + e) @ F0
    T[11] -= 2.5
    plastic = np.full(n, 0.3)
    sim.adaptive.before.equivalent_plastic_strain.from_numpy(plastic)
    plastic[5] += 0.004
    sim.state.points.F.from_numpy(F)
    sim.state.points.T.from_numpy(T)
    sim.state.points.equivalent_plastic_strain.from_numpy(plastic)
    sim.state.points.v.fill(0.0)
    sim.adaptive.points_pass(PointsPass.CHANGES, 1e-6)
    dT, de, dx, dp, ex = sim.adaptive.changes[None]
    assert dT == pytest.approx(2.5)
    assert de == pytest.approx(np.linalg.norm(e), rel=1e-10)
    assert dx == 0.0
    assert dp == pytest.approx(0.004, rel=1e-10)
    assert ex == pytest.approx(0.5 * 0.004, rel=1e-10)  # from rest: half the increment
    c = sim.adaptive.controls
    assert sim.adaptive.changes_ratio(1e-6) == pytest.approx(
        max(2.5 / c.temperature_K, de / c.strain)
    )
    sim.adaptive.controls = dataclasses.replace(c, plastic=True)
    assert sim.adaptive.changes_ratio(1e-6) == pytest.approx(
        max(2.5 / c.temperature_K, dp / c.strain)
    )


def test_strain_error_is_backward_eulers_local_error():
    """strain_control = "error": the step's local error of the plastic strain, dt |r - r_last|
    / 2 with r = dp / dt the point's plastic rate over the step and r_last over the last one
    (the exact local error of backward Euler for a rate changing at a constant pace c: dt^2 c
    / 2), read as the square root of its ratio to max_strain_error (the error grows as dt^2,
    the other controls as dt) in place of the increment; an accepted step's rates become the
    next one's last."""
    case = load_case("power25W_coarse", [*ADAPTIVE, "time.strain_control=error"])
    sim = Simulation(case)
    ad = sim.adaptive
    assert ad.controls.strain_error == case.time.max_strain_error
    n, dt = sim.state.n_points, 1e-6
    last = np.zeros((n, 2))
    last[:, 0] = 50.0  # every point flowed at 50 / s over the last step
    ad.rates.from_numpy(last)
    plastic = np.full(n, 0.1)
    sim.state.points.equivalent_plastic_strain.from_numpy(plastic)
    sim.state.points.v.fill(0.0)
    ad.save()
    plastic += 50.0 * dt  # the same rate again: no error ...
    plastic[13] += 2e-3 * dt  # ... but at point 13, whose rate rose by 2e-3 / s
    sim.state.points.equivalent_plastic_strain.from_numpy(plastic)
    ratio = ad.changes_ratio(dt)
    ep = ad.changes[None][4]
    assert ep == pytest.approx(0.5 * 2e-3 * dt, rel=1e-6)
    assert ratio == pytest.approx(np.sqrt(ep / case.time.max_strain_error), rel=1e-6)
    ad.points_pass(PointsPass.ACCEPT)
    rates = ad.rates.to_numpy()
    assert rates[13, 0] == pytest.approx(50.0 + 2e-3, rel=1e-9)
    assert rates[0, 0] == pytest.approx(50.0, rel=1e-9)


def test_laser_switch_times():
    """Steps end where a laser switches: the paper's pulse stops at 20 us; a delayed one
    starts later."""
    assert laser_switch_times(load_case("power25W_coarse")) == [pytest.approx(20e-6)]
    late = load_case("power25W_coarse", ["lasers.0.on_s=1e-4", "lasers.0.off_s=2e-4"])
    assert laser_switch_times(late) == [pytest.approx(1e-4), pytest.approx(2e-4)]


@pytest.mark.parametrize(
    "sets, key",
    [
        (["time.adaptive=true"], "time.adaptive"),
        ([*ADAPTIVE, "time.dt_min_s=1e-5", "time.dt_max_s=1e-6"], "time.dt_min_s"),
        ([*ADAPTIVE, "time.max_strain_increment=0"], "max_strain_increment"),
        (["time.heat_integrator=crank"], "heat_integrator"),
    ],
)
def test_adaptive_input_errors_name_the_key(sets, key):
    with pytest.raises(CaseError, match=key):
        load_case("power25W_coarse", sets)


def test_a_redone_step_starts_from_the_state_before_it():
    """What the adaptive step keeps before a step (the points on the device, the rest by
    checkpoint.capture) is everything a step reads: steps taken after a restore repeat the
    first ones bit for bit (serial layout)."""
    sim = Simulation(load_case("power25W_coarse", [*ADAPTIVE, "solver.layout=serial"]))
    sim.advance_to(2 * sim.dt)
    before, dt_next = checkpoint.capture(sim.state, points=False), sim.adaptive.dt
    kept = struct_type(POINT_MEMBERS, 2).field(shape=sim.state.n_points)
    copy_points(sim.state.points, kept, True)
    end = sim.t + 3 * sim.dt
    sim.advance_to(end)
    first = sim.state.points.to_numpy()
    copy_points(sim.state.points, kept, False)
    checkpoint.restore(sim.state, before)
    sim.adaptive.dt = dt_next
    sim.advance_to(end)
    again = sim.state.points.to_numpy()
    for k in ("x", "v", "T", "stress", "enthalpy", "F"):
        assert np.array_equal(first[k], again[k]), k


# slow: the blocks layout's redo (~20 s); the serial redo stays in default
# (test_a_redone_step_starts_from_the_state_before_it)
@pytest.mark.slow
def test_a_step_refused_by_newton_keeps_the_energy_balance_in_blocks(monkeypatch):
    """A step whose Newton fails is redone after its heat has run: under the blocks layout the
    per-block sums of laser energy and heat out that it left must not reach the run's totals
    (they did: an h = 0.5 um run stopped on its energy guard at a relative error of 1e-6).
    The balance stays at round-off (1e-12, against the guard's 1e-6) with the laser on."""
    sim = Simulation(load_case("power25W_coarse", [*ADAPTIVE, "solver.layout=blocks"]))
    sim.monitors()  # the initial enthalpy, the balance's reference
    sim.advance_to(3 * sim.dt)
    newton = ImplicitStepper.newton
    calls = {"n": 0}

    def fail_once(self, sys_):
        calls["n"] += 1
        if calls["n"] == 1:
            raise NewtonError("refused on purpose")
        return newton(self, sys_)

    monkeypatch.setattr(ImplicitStepper, "newton", fail_once)
    sim.advance_to(sim.t + 2 * sim.dt)
    assert sim.adaptive.refused >= 1 and calls["n"] >= 3
    mon = sim.monitors()
    assert mon["laser_energy_J_per_m"] > 0.0
    assert abs(sim.energy_error(mon)) < 1e-12


def test_an_adaptive_run_resumes_on_the_frame_times_it_started_with(tmp_path):
    """The frames of an adaptive run lie on multiples of its first step (jobs/schedule.py); a
    resumed run keeps that step as its dt and the adaptive step's next size, not the last
    step's size (it did: the frames after a resume fell at other times, 1 ms at 0.97 ms)."""
    case = load_case("power25W_coarse", ADAPTIVE)
    sim = Simulation(case)
    first = sim.dt
    sim.advance_to(4.5 * first)  # the last step, cut to land there, is not the first's
    assert sim.adaptive.last_dt != first
    sim.save_checkpoint(tmp_path / "checkpoint.npz")
    t, next_dt = sim.t, sim.adaptive.dt  # read before a new Simulation starts Taichi afresh
    again = Simulation(case)
    again.load_checkpoint(tmp_path / "checkpoint.npz")
    assert again.dt == first and again.adaptive.dt == next_dt and again.t == t


def test_a_step_below_dt_min_ends_with_a_clear_error():
    """A Newton that cannot converge (a tolerance below round-off, two iterations allowed) is
    redone at smaller steps down to time.dt_min_s, then the run stops with an error that names
    the keys to change."""
    sets = [*ADAPTIVE, "time.newton_tolerance=1e-18", "time.newton_max_iterations=2"]
    sets.append("time.dt_min_s=1e-6")
    sim = Simulation(load_case("power25W_coarse", sets))
    with pytest.raises(SimulationError, match="time.dt_min_s"):
        sim.advance_to(5 * sim.dt)
    assert sim.adaptive.refused >= 1


def test_adaptive_main_job_lands_its_frames_and_grows_its_step(tmp_path):
    """The coarse 25 W pair to 2 ms, adaptive, heat by backward Euler, as the main job: every
    row of the time series on its frame's time (log-spaced from 1 us), the step ending at the
    laser's switch-off, shrinking through the pulse and growing as the melt settles (the
    series logs it), the energy balance to round-off (the guard checks it at every frame,
    1e-6; the summary's final error is checked to 1e-12), and the peak temperature within 1 %
    of the explicit run's (the same heat on points that moved differently, first order in
    time)."""
    sets = [*ADAPTIVE, "time.heat_integrator=implicit", "time.end_s=2e-3"]
    case = load_case("power25W_coarse", sets)
    summary = taichi_sls.run_case(case, tmp_path, progress=False)
    assert summary["status"] == "complete"
    series = taichi_sls.read_series(tmp_path / "timeseries.csv")
    dt0 = summary["dt_s"]
    want = np.array([0.0] + [k * dt0 for k in frame_steps(case, dt0)])
    assert np.allclose(series["t_s"], want, rtol=1e-12, atol=0)
    dt = series["dt_s"]
    assert dt[-1] > 100 * dt[1:].min()  # grown after the pulse
    assert summary["refused_steps"] >= 0 and summary["steps"] < 400
    mon = summary["final"]
    error = (mon["laser_energy_J_per_m"] - mon["heat_out_J_per_m"]) - (
        mon["enthalpy_J_per_m"] - summary["initial"]["enthalpy_J_per_m"]
    )
    assert abs(error) < 1e-12 * abs(summary["initial"]["enthalpy_J_per_m"])
    assert summary["T_peak_C"] == pytest.approx(explicit_coarse_peak_C(), rel=0.01)


@pytest.mark.parametrize("factor, tolerance", [(10, 2.5e-3), (100, 1.5e-2)])
def test_backward_euler_heat_against_erf_far_beyond_the_explicit_limit(factor, tolerance):
    """cases/verification/erf.toml (h = 2 um) with the mechanics on at rest (no forces), the
    implicit integrator and backward-Euler heat at 10x and 100x the explicit heat step (the
    latter 40x its stability limit): stable, and within the RMS error the first-order step
    allows (measured 1.9e-3 / 9.9e-3 of the jump, 0.87e-3 explicit; 5 steps at 100x)."""
    at_rest = {"physics": {"mechanics": True, "thermal_strain": False, "gravity_m_s2": [0, 0]}}
    dt = factor * heat_step_max(ver.load("erf", 2.0).case)
    over = {**at_rest, "time": {"integrator": "implicit", "heat_integrator": "implicit"}}
    over["time"]["dt_s"] = dt
    r = ver.run(ver.load("erf", 2.0, over))
    print(f"backward-Euler heat at {factor}x:", r.errors)
    assert r.errors["temperature_rms"] < tolerance
