"""The one stepping verb (solver/stepper.py): every integrator's stepper offers the same
methods, ``Simulation.advance_to`` drives the case's one, and a study's ``before_step`` hook
runs once before every step, fixed or adaptive."""

import inspect

import pytest
from helpers import PAPER_SCENE, deep_update, make_case

from taichi_sls.solver.adaptive import AdaptiveStepper
from taichi_sls.solver.extrapolation import ExtrapolatedStepper
from taichi_sls.solver.handover import HybridStepper
from taichi_sls.solver.implicit import ImplicitStepper
from taichi_sls.solver.simulation import Simulation
from taichi_sls.solver.stepper import ExplicitStepper

STEPPERS = (ExplicitStepper, ImplicitStepper, ExtrapolatedStepper, AdaptiveStepper, HybridStepper)


@pytest.mark.parametrize("cls", STEPPERS, ids=lambda c: c.__name__)
def test_every_stepper_offers_the_protocol(cls):
    assert callable(cls.compile) and callable(cls.advance_to)
    # last_dt: a property, or an attribute that the constructor sets
    own = isinstance(inspect.getattr_static(cls, "last_dt", None), property)
    assert own or "last_dt" in cls.__init__.__code__.co_names
    params = list(inspect.signature(cls.advance_to).parameters.values())
    assert len(params) == 3 and params[2].name == "hooks"
    assert params[2].default is not inspect.Parameter.empty  # advance_to(t) alone steps too


@pytest.mark.parametrize(
    "time, kind",
    [
        ({}, ExplicitStepper),
        ({"integrator": "implicit", "adaptive": True, "dt_s": 1e-7}, AdaptiveStepper),
    ],
    ids=["explicit", "adaptive"],
)
def test_advance_to_calls_before_step_once_before_every_step(time, kind):
    data = deep_update(PAPER_SCENE, {"grid": {"spacing_um": 4.0}, "time": time})
    seen = []
    sim = Simulation(make_case(data), before_step=lambda s: seen.append((s.t, s.steps)))
    assert isinstance(sim.stepper, kind)
    end = 5 * sim.dt
    sim.advance_to(end)
    assert sim.t == pytest.approx(end, rel=1e-12)
    assert len(seen) == sim.steps > 0
    times = [t for t, _ in seen]
    assert times[0] == 0.0 and times == sorted(set(times))  # each before a step, none after
    assert sim.step_dt == sim.stepper.last_dt > 0.0
