"""How a simulation steps: one protocol that each integrator's stepper offers, so that
:meth:`~taichi_sls.solver.simulation.Simulation.advance_to` is the one stepping verb.

    compile()               compile the step's kernels, so that the first step does not pay
    advance_to(t, hooks)    step until the clock reaches t (s); returns the steps taken
    last_dt                 the last step's length (s): the fixed dt, or the adaptive step's

The steppers: :class:`ExplicitStepper` (the explicit step of solver/step.py, fixed dt),
:class:`~taichi_sls.solver.implicit.ImplicitStepper` (backward Euler, fixed dt),
:class:`~taichi_sls.solver.extrapolation.ExtrapolatedStepper` (its Richardson extrapolation),
:class:`~taichi_sls.solver.adaptive.AdaptiveStepper` (either, at a step the physics chooses) and
:class:`~taichi_sls.solver.handover.HybridStepper` (explicit steps, then adaptive implicit ones).
A fixed step reaches t in the whole number of steps nearest to it; an adaptive step lands on it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from .fields import State
from .step import advance


@dataclass(frozen=True)
class StepHooks:
    """What runs between steps: ``before`` every step (a study's time-dependent load),
    ``after`` every step (the blocks layout's sort of drifted points). With neither, a fixed
    stepper takes all its steps in one call. ``stop``, asked after every adaptive step (and
    every explicit chunk of a hybrid run): True ends ``advance_to`` there, short of t, at a
    step's end, so that a stop request (Ctrl-C, SIGTERM) waits for one step, not a frame."""

    before: Callable[[], None] | None = None
    after: Callable[[], None] | None = None
    stop: Callable[[], bool] | None = None

    def stopping(self) -> bool:
        return self.stop is not None and self.stop()


NO_HOOKS = StepHooks()


class Stepper(Protocol):
    """Module docstring."""

    @property
    def last_dt(self) -> float: ...

    def compile(self) -> None: ...

    def advance_to(self, t: float, hooks: StepHooks = NO_HOOKS) -> int: ...


def fixed_steps_to(t_now: float, t: float, dt: float) -> int:
    """The whole number of steps of dt nearest to the time from t_now to t."""
    return round((t - t_now) / dt)


def whole_steps(take: Callable[[int], None], n: int, hooks: StepHooks) -> int:
    """n steps of ``take(k)`` (k steps a call): one call unless a hook runs between steps;
    returns n (0 when n <= 0)."""
    if n <= 0:
        return 0
    if hooks.before is None and hooks.after is None:
        take(n)
        return n
    for _ in range(n):
        if hooks.before is not None:
            hooks.before()
        take(1)
        if hooks.after is not None:
            hooks.after()
    return n


class ExplicitStepper:
    """Explicit steps of a fixed dt (the protocol above) on ``st``:
    the run's state, or the hybrid's explicit view of it."""

    def __init__(self, st: State, dt: float) -> None:
        self.st = st
        self.dt = dt

    @property
    def last_dt(self) -> float:
        return self.dt

    def compile(self) -> None:
        advance(self.st, 0)

    def take(self, n: int) -> None:
        """n steps, as :func:`advance` takes them."""
        advance(self.st, n)

    def advance_to(self, t: float, hooks: StepHooks = NO_HOOKS) -> int:
        """The whole steps nearest to t (s)."""
        n = fixed_steps_to(float(self.st.scalars.t[None]), t, self.dt)
        return whole_steps(self.take, n, hooks)
