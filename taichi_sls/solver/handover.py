"""Explicit steps, then implicit ones (``time.integrator = "hybrid"``).

The paper's melt collapses inertially while it melts: its answer needs steps of 1e-8-1e-7 s
there (docs/implicit.md), where an explicit step costs some 0.35 ms and an implicit one 15-20 ms.
Once every laser is off and the motion has died down (the kinetic energy, times the inertia
scale, below ``time.handover_kinetic_fraction`` of the surface energy) nothing is left that the
explicit limits need to resolve, and the adaptive implicit step (solver/adaptive.py) takes over
to run on to refreezing or through a long hold in steps of milliseconds.

Both integrators step the same fields: the explicit one through a second view of the state
with the explicit step's configuration (its heat clock, mass cut-off, FLIP share), compiled on
its own. The hand-over falls at the end of a heat step (a multiple of ``heat_every`` steps), so
that no heat is lost; the thermal strain increment that the last explicit heat step spread over
its mechanical steps has then been applied in full and is cleared for the implicit step, which
sums its own.
"""

import copy
import math
from collections.abc import Callable

from ..config import Case
from .adaptive import AdaptiveStepper
from .fields import State
from .scene import Scene
from .step_config import step_config
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
    """Which integrator steps now, and the moment to change (module docstring)."""

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
        self.lasers_off_s = case.lasers_off_s()
        self.fraction = case.time.handover_kinetic_fraction
        self.kinetic_ratio = kinetic_ratio
        every = view.cfg.heat_every  # whole heat steps of the explicit phase, ~CHECK_S apart
        self.check_every = every * substeps_within(CHECK_S, dt * every)
        self.explicit = True
        self.at_s = math.nan  # when the implicit step took over

    def steps_to_check(self, steps: int) -> int:
        """Explicit steps from ``steps`` to the next check."""
        return self.check_every - steps % self.check_every

    def check(self, t: float, steps: int) -> None:
        """Hand over if the rule holds (at a check, after the explicit steps up to it)."""
        if steps % self.check_every or t < self.lasers_off_s * (1 - 1e-12):
            return
        if self.kinetic_ratio() >= self.fraction:
            return
        st = self.adaptive.st
        st.points.iso_strain_step.fill(0.0)
        self.explicit = False
        self.at_s = t
