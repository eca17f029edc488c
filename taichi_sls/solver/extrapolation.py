"""A second-order implicit step (``time.implicit_scheme = "extrapolated"``): Richardson's
extrapolation of the backward-Euler step.

The backward-Euler step (solver/implicit.py) is first order: its error after a step dt is
c dt^2 + O(dt^3) with the same c for any dt. Taken once whole and once as two halves from the same
state, the combination 2 y_halves - y_whole cancels c and is second order. Its stability function
on y' = lambda y, 2 / (1 - z/2)^2 - 1 / (1 - z) with z = lambda dt, vanishes as z -> -inf: the
extrapolated step damps stiff modes (a Maxwell melt relaxing within a step, the elastic waves) as
backward Euler does (L-stable), where the implicit midpoint rule would let them ring. Three
Newton solves a step instead of one.

The extrapolation holds for any first-order step, so it needs nothing of the step's inside: the
points' mechanical state (position, velocity, affine velocity, deformation gradient, strains,
stresses, J) is extrapolated; the heat, the phase and everything else are those of the two
halves (the heat step is first order, or explicit substeps whose error the halves only shrink);
the equivalent plastic strain never falls below the step's start. Where the two solutions of a
point disagree so much that its extrapolated J would fall below half the halves' J, that point
keeps the halves' state (first order there; counted in ``kept``, the main job's summary
``extrapolation_kept_points``).
"""

from taichi_sls.backend import ti

from . import checkpoint
from .adaptive import copy_points
from .fields import POINT_MEMBERS, struct_type
from .implicit import ImplicitStepper, StepReport
from .step import init_box
from .stepper import NO_HOOKS, StepHooks, fixed_steps_to, whole_steps

# the points' members the extrapolation combines: the mechanics a step integrates
EXTRAPOLATED = (
    "x",
    "v",
    "C",
    "F",
    "strain",
    "plastic_strain",
    "stress",
    "elastic_stretch",
    "viscous_stress",
    "J",
)


@ti.kernel
def extrapolate(now: ti.template(), whole: ti.template(), start: ti.template()) -> ti.i32:
    """now = 2 now - whole on the mechanical members (the equivalent plastic strain kept at or
    above ``start``'s). A point whose extrapolated J would fall below half its J after the
    halves (the two solutions disagree by more than a step can be trusted to extrapolate)
    keeps the halves' state; returns how many did."""
    kept = 0
    for p in now:
        if 2.0 * now[p].J - whole[p].J < 0.5 * now[p].J:
            kept += 1
        else:
            for name in ti.static(EXTRAPOLATED):
                field, other = ti.static(getattr(now, name), getattr(whole, name))
                field[p] = 2.0 * field[p] - other[p]
            e = 2.0 * now[p].equivalent_plastic_strain - whole[p].equivalent_plastic_strain
            now[p].equivalent_plastic_strain = ti.max(e, start[p].equivalent_plastic_strain)
    return kept


class ExtrapolatedStepper:
    """Backward-Euler steps of one State, each taken whole and as two halves and extrapolated
    (module docstring). Offers the :class:`ImplicitStepper` interface that the adaptive step
    uses, and the stepper protocol (:mod:`taichi_sls.solver.stepper`)."""

    def __init__(self, inner: ImplicitStepper) -> None:
        self.inner = inner
        self.st = inner.st
        self.heat = inner.heat
        kind = struct_type(POINT_MEMBERS, self.st.cfg.dim)
        n = self.st.n_points
        self.start = kind.field(shape=n, layout=ti.Layout.SOA)
        self.whole = kind.field(shape=n, layout=ti.Layout.SOA)
        self.kept = 0  # points that kept the halves' state, over the run

    @property
    def last(self) -> StepReport:
        return self.inner.last

    @property
    def newton_total(self) -> int:
        return self.inner.newton_total

    @property
    def dt(self) -> float:
        """The fixed step of :meth:`advance_to` (s), the inner stepper's."""
        return self.inner.dt

    @dt.setter
    def dt(self, dt: float) -> None:
        self.inner.dt = dt

    @property
    def last_dt(self) -> float:
        return self.inner.dt

    def advance_to(self, t: float, hooks: StepHooks = NO_HOOKS) -> int:
        """The whole steps of dt nearest to t (s) (:mod:`taichi_sls.solver.stepper`)."""
        n = fixed_steps_to(float(self.st.scalars.t[None]), t, self.dt)
        return whole_steps(self.advance, n, hooks)

    def compile(self) -> None:
        self.inner.compile(self)
        self.kept = 0

    def advance(self, n: int) -> None:
        for _ in range(n):
            self.step()

    def step(self) -> None:
        st, sc = self.st, self.st.scalars
        dt, dt_heat = float(sc.dt[None]), float(sc.dt_heat[None])
        before = checkpoint.capture(st, points=False)
        copy_points(st.points, self.start, True)
        try:
            self.inner.step()
            copy_points(st.points, self.whole, True)
            copy_points(st.points, self.start, False)
            checkpoint.restore(st, before)
            init_box(st)
            sc.dt[None], sc.dt_heat[None] = 0.5 * dt, 0.5 * dt_heat
            self.inner.step()
            self.inner.step()
        finally:
            sc.dt[None], sc.dt_heat[None] = dt, dt_heat
        self.kept += extrapolate(st.points, self.whole, self.start)
        sc.step[None] = int(before["steps"]) + 1
        init_box(st)
