"""Explicit steps, then implicit ones (``time.integrator = "hybrid"``).

The paper's melt collapses inertially while it melts: its answer needs steps of 1e-8-1e-7 s
there (docs/record/implicit.md), where an explicit step costs far less than an implicit one.
Once every laser is off and the motion has died down (the kinetic energy, times the inertia
scale, below ``time.handover_kinetic_fraction`` of the surface energy) nothing is left that
the explicit limits need to resolve, and the adaptive implicit step (solver/adaptive.py) takes
over to run on to refreezing or through a long hold in steps of milliseconds.

Both integrators step the same fields: the explicit one through a second view of the state
with the explicit step's configuration (its heat clock, mass cut-off, FLIP share), compiled on
its own. The hand-over falls at the end of a heat step (a multiple of ``heat_every`` steps), so
that no heat is lost; the thermal strain increment that the last explicit heat step spread over
its mechanical steps has then been applied in full and is cleared for the implicit step, which
sums its own.

The hand-over is not one way. After it, contacts that form as a layer sinks (two melt surfaces
snapping shut) are jumps that the controls follow at steps near the explicit one, where each
implicit step costs a Newton solve. So when the adaptive step would fall below
``time.handback_explicit_steps`` explicit steps, explicit steps take over again (their clocks
aligned to start with a heat step), and every ``CHECK_S`` the changes over that stretch are
read as if it had been one step: once a step of the proposed size meets the controls and is
longer than the hand-back's bound, the implicit step resumes at that size.
"""

import copy
import math
from collections.abc import Callable

import numpy as np

from ..config import Case
from . import struct_copy
from .adaptive import AdaptiveStepper, next_step
from .fields import State
from .scene import Scene
from .step_config import step_config
from .stepper import NO_HOOKS, ExplicitStepper, StepHooks, whole_steps
from .time_step import (
    resolve_curvature_every,
    resolve_heat_every,
    substeps_within,
    time_step_limits,
)

CHECK_S = 1e-5  # simulated time between checks of the hand-over rule (s)


def explicit_part(case: Case) -> Case:
    """The case as the explicit integrator runs it."""
    time = case.time.model_copy(update={"integrator": "explicit", "adaptive": False})
    return case.model_copy(update={"time": time})


def explicit_view(case: Case, state: State, scene: Scene, dt: float) -> State:
    """The same fields, with the explicit step's configuration at step dt."""
    explicit = explicit_part(case)
    limits = time_step_limits(explicit)
    heat_every = resolve_heat_every(explicit, dt, limits)
    curvature_every = resolve_curvature_every(explicit, dt, limits)
    thermal = limits.get("thermal", math.inf)
    view = copy.copy(state)
    view.cfg = step_config(explicit, scene, heat_every, curvature_every, dt, thermal, dt)
    view.implicit = None
    return view


class Handover:
    """Which integrator steps now, and the moments to change (module docstring)."""

    def __init__(
        self,
        case: Case,
        view: State,
        adaptive: AdaptiveStepper,
        dt: float,
        kinetic_ratio: Callable[[], float],
    ) -> None:
        self.view = view
        self.adaptive = adaptive
        self.dt = dt
        self.lasers_off_s = case.lasers_off_s()
        self.fraction = case.time.handover_kinetic_fraction
        self.kinetic_ratio = kinetic_ratio
        adaptive.handback_below = case.time.handback_explicit_steps * dt
        every = view.cfg.heat_every  # whole heat steps of the explicit phase, ~CHECK_S apart
        self.check_every = every * substeps_within(CHECK_S, dt * every)
        self.explicit = True
        self.stretch = 0  # explicit steps since the explicit phase began or the last check
        self.stretch_s = 0.0  # when that stretch began (s)
        self.at_s = math.nan  # when the implicit step first took over
        self.handbacks = 0  # times explicit steps took over again

    def steps_to_check(self) -> int:
        """Explicit steps to the next check."""
        return self.check_every - self.stretch

    def check(self, t: float, steps: int) -> None:
        """After ``steps`` explicit steps: at a check, hand over if the rule holds (the first
        time: every laser off and the motion died down; after a hand-back: the stretch since
        the last check, read as one step, proposes a step the implicit one may take)."""
        self.stretch += steps
        if self.stretch < self.check_every:
            return
        length = t - self.stretch_s
        ratio = self.adaptive.changes_ratio(length) if self.handbacks else math.nan
        self.restart_stretch(t)
        if t < self.lasers_off_s * (1 - 1e-12):
            return
        if self.handbacks == 0:
            if self.kinetic_ratio() >= self.fraction:
                return
        else:
            proposed = next_step(length, ratio, self.adaptive.controls)
            if proposed < self.adaptive.handback_below:
                return
            self.adaptive.dt = proposed
        self.hand_over(t)

    def hand_over(self, t: float) -> None:
        """The implicit step takes over at t (the rule's, or contact.settle_steps = "implicit"
        from the start)."""
        pt = self.adaptive.st.points
        struct_copy.from_numpy(pt, {"iso_strain_step": np.zeros(pt.shape)})
        self.explicit = False
        if self.handbacks == 0:
            self.at_s = t

    def hand_back(self, t: float) -> None:
        """Explicit steps take over again at t: the step counter raised to the next start of
        a heat (and curvature) step, the explicit dt, a stretch begun."""
        st = self.adaptive.st
        every = math.lcm(self.view.cfg.heat_every, self.view.cfg.geom_every)
        st.scalars.step[None] = -(-int(st.scalars.step[None]) // every) * every
        st.scalars.dt[None] = self.dt
        # the last implicit step's sum, already applied
        struct_copy.from_numpy(st.points, {"iso_strain_step": np.zeros(st.points.shape)})
        self.explicit = True
        self.handbacks += 1
        self.restart_stretch(t)

    def start_again(self, t: float) -> None:
        """The explicit phase begins again at t, as at the start of a run (contact.settle: the
        clock restarts at the settled state)."""
        if not self.explicit:
            self.hand_back(t)
        self.handbacks, self.at_s = 0, math.nan
        self.restart_stretch(t)

    def restart_stretch(self, t: float) -> None:
        """A stretch of explicit steps begins at t; after a hand-back its starting points are
        kept for its check (before the first hand-over the kinetic rule needs none)."""
        if self.handbacks:
            self.adaptive.save()
        self.stretch, self.stretch_s = 0, t


class HybridStepper:
    """Explicit steps on the explicit view, then adaptive implicit ones, as the hand-over says
    (module docstring; the stepper protocol, :mod:`taichi_sls.solver.stepper`)."""

    def __init__(self, handover: Handover) -> None:
        self.handover = handover
        self.adaptive = handover.adaptive
        self.explicit = ExplicitStepper(handover.view, handover.dt)

    @property
    def last_dt(self) -> float:
        h = self.handover
        return h.dt if h.explicit else self.adaptive.last_dt

    def compile(self) -> None:
        self.explicit.compile()
        self.adaptive.compile()

    def _t(self) -> float:
        return float(self.adaptive.st.scalars.t[None])

    def advance_to(self, t: float, hooks: StepHooks = NO_HOOKS) -> int:
        """Until the clock reaches t (s): adaptive steps that land on it, or, in an explicit
        phase, the whole explicit steps that reach it (after a hand-back the clock is off their
        grid; on it, the ones that land on it), a check of the hand-over every
        :meth:`Handover.steps_to_check` of them. Returns the steps taken."""
        h, taken = self.handover, 0
        while self._t() < t * (1.0 - 1e-12):
            if h.explicit:
                if (n := math.ceil((t - self._t()) / h.dt - 1e-6)) <= 0:
                    break
                k = min(n, h.steps_to_check())
                taken += whole_steps(self.explicit.take, k, hooks)
                h.check(self._t(), k)
            else:
                taken += self.adaptive.advance_to(t, hooks)
                if self._t() < t * (1.0 - 1e-12) and not hooks.stopping():
                    h.hand_back(self._t())  # stopped short: the explicit steps take over
            if hooks.stopping():
                break
        return taken
