"""The step chosen by the physics (``time.adaptive``; the implicit integrator only).

Each step is taken with the current dt and then measured: the largest temperature change of any
point, dT, the largest strain increment, de = |f - I| (Frobenius; f = F^{n+1} (F^n)^-1, the
step's deformation gradient; or, with ``time.strain_control = "plastic"``, the largest increment
of the equivalent plastic strain: the elastic part reaches its quasi-static state at any step),
and the farthest motion of a point, dx (or its velocity times dt, which the guard limits).
Against the case's
controls, r = max(dT / dT_max, de / de_max, dx / (cells h)), and the next step follows as for a
first-order method, whose error per step grows with dt: dt_next = SAFETY dt / r, at most GROWTH
and at least SHRINK times the last, within [dt_min, dt_max]. So the step grows while nothing
changes fast (laser off, the melt settled) and shrinks through the pulse and the melting and
freezing fronts. A step with r > REDO (twice over its controls) or whose Newton failed is redone
from the state before it at a smaller step.

A step never crosses a laser's switch-on or switch-off time, so the pulse starts and stops on
time, nor a time the caller asks to land on (a frame). A step cut short to land there does not
shrink the next one.
"""

import enum
import math
from dataclasses import dataclass

import numpy as np

from taichi_sls.backend import ti

from ..config import Case
from ..physics.small_matrix import IDENTITY
from . import checkpoint
from .fields import POINT_MEMBERS, State, struct_type
from .guard import SimulationError
from .implicit import ImplicitStepper, NewtonError
from .step import init_box
from .stepper import NO_HOOKS, StepHooks

SAFETY = 0.9  # aim a little below the controls, so that steady growth is rarely refused
GROWTH = 2.0  # the most a step may grow over the last one
SHRINK = 0.2  # the most a step may shrink below the last one, measured or redone
REDO = 2.0  # a step over its controls by more than this factor is redone smaller


@dataclass(frozen=True)
class StepControls:
    """The adaptive step's bounds (s) and accuracy controls per step (K, strain)."""

    dt_min: float
    dt_max: float
    temperature_K: float
    strain: float
    cells: float
    plastic: bool = False  # the strain control reads the plastic increment, not the total
    strain_error: float = 0.0  # > 0: the plastic strain's local error replaces its increment

    @classmethod
    def from_case(cls, case: Case, dt0: float, floor: float | None = None) -> "StepControls":
        """``floor``: the smallest step under dt_min_s = "auto" (default dt0 / 1000)."""
        t = case.time
        auto = dt0 / 1000.0 if floor is None else floor
        dt_min = auto if t.dt_min_s == "auto" else float(t.dt_min_s)
        dt_max = math.inf if t.dt_max_s == "auto" else float(t.dt_max_s)
        return cls(
            dt_min,
            max(dt_max, dt_min),
            t.max_temperature_change_K,
            t.max_strain_increment,
            t.max_motion_cells,
            t.strain_control == "plastic",
            t.max_strain_error if t.strain_control == "error" else 0.0,
        )


def next_step(dt: float, ratio: float, controls: StepControls) -> float:
    """The step after one of ``dt`` whose changes were ``ratio`` times the controls."""
    factor = min(GROWTH, max(SHRINK, SAFETY / max(ratio, 1e-12)))
    return min(controls.dt_max, max(controls.dt_min, dt * factor))


def laser_switch_times(case: Case) -> list[float]:
    """Every time a laser with power switches on or stops heating (s), sorted."""
    edges = set()
    for las in case.lasers:
        if las.power_W > 0:
            edges.add(las.on_s)
            if las.scan == "across":  # each pass starts and ends on time
                edges.update(e for window in las.track_windows_s() for e in window)
            elif case.domain.dim == 3:  # each track in the bed starts and ends on time
                edges.update(e for window in las.track_windows_along_s() for e in window)
    edges.add(case.lasers_off_s())
    return sorted(e for e in edges if e > 0.0)


@ti.kernel
def copy_points(a: ti.template(), b: ti.template(), into_b: ti.i32):
    """b = a (``into_b``) or a = b: one kernel both ways (a template each way would be two)."""
    for p in a:
        if into_b:
            b[p] = a[p]
        else:
            a[p] = b[p]


class PointsPass(enum.IntEnum):
    """What :func:`points_pass` does with the points and their copy from before the step."""

    SAVE = 0  # before = now
    RESTORE = 1  # now = before
    CHANGES = 2  # the step's changes, :func:`points_pass`
    ACCEPT = 3  # the step's plastic rates become the last step's


@ti.kernel
def points_pass(
    now: ti.template(),
    before: ti.template(),
    rates: ti.template(),
    out: ti.template(),
    dt: float,
    what: ti.i32,
):
    """As ``what`` (:class:`PointsPass`) says: save the points, put them back, or out = (dT,
    de, dx, dp, ep): the largest temperature change (K), strain increment |F F_before^-1 - I|
    (Frobenius), motion (m), equivalent plastic strain increment and its local error
    dt |r - r_last| / 2 (backward Euler's against a step at the plastic rate the last step
    took, r_last = ``rates[p, 0]``; the step's rate r goes to ``rates[p, 1]``) of any point
    over the step dt since ``before``; the motion also as the point's own velocity times dt,
    which the guard limits (with FLIP it is not the grid velocity that moved the point). One
    kernel for the three (a kernel's compilation costs tens of ms whatever its size)."""
    if what == PointsPass.CHANGES:
        out[None] = ti.Vector([0.0, 0.0, 0.0, 0.0, 0.0])
    for p in now:
        if what == PointsPass.SAVE:
            before[p] = now[p]
        elif what == PointsPass.RESTORE:
            now[p] = before[p]
        elif what == PointsPass.ACCEPT:
            rates[p][0] = rates[p][1]
        else:
            f = now[p].F @ before[p].F.inverse()
            f -= ti.Matrix(IDENTITY[f.n])
            ti.atomic_max(out[None][0], ti.abs(now[p].T - before[p].T))
            ti.atomic_max(out[None][1], ti.sqrt((f * f).sum()))
            dx = ti.max((now[p].x - before[p].x).norm(), now[p].v.norm() * dt)
            ti.atomic_max(out[None][2], dx)
            dp = now[p].equivalent_plastic_strain - before[p].equivalent_plastic_strain
            ti.atomic_max(out[None][3], dp)
            rates[p][1] = dp / dt
            ti.atomic_max(out[None][4], 0.5 * ti.abs(dp - dt * rates[p][0]))


class AdaptiveStepper:
    """Implicit steps of a size chosen by :class:`StepControls` (module docstring).
    ``heat_step_max``: the longest heat substep (s), which sets the substeps of each step;
    ``floor``: the smallest step under dt_min_s = "auto" (the hybrid's explicit step)."""

    def __init__(
        self,
        case: Case,
        st: State,
        implicit: ImplicitStepper,
        dt0: float,
        heat_step_max: float,
        floor: float | None = None,
    ) -> None:
        self.st = st
        self.implicit = implicit
        self.controls = StepControls.from_case(case, dt0, floor)
        self.dt = min(self.controls.dt_max, max(self.controls.dt_min, dt0))  # the next to try
        self.first_dt = self.dt  # the first, tried again when the clock restarts
        self.heat_step_max = heat_step_max
        self.edges = laser_switch_times(case)
        self.last_dt = self.dt  # the last step taken
        self.handback_below = 0.0  # hybrid: no step shorter than this (solver/handover.py)
        self.refused = 0  # steps redone smaller, over the run
        # the points before the step, kept on the device (a host copy costs much of a step)
        self.before = struct_type(POINT_MEMBERS, st.cfg.dim).field(
            shape=st.n_points, layout=ti.Layout.SOA
        )
        self.changes = ti.Vector.field(5, float, ())
        # each point's plastic strain rate over the last accepted step and over the one being
        # judged (1/s): the strain error's estimate (points_pass)
        self.rates = ti.Vector.field(2, float, st.n_points)

    def compile(self) -> None:
        """Compile the implicit step's kernels, those that judge a step (they change nothing
        the run reads before the next step writes it) and the copy back that a refused step
        makes, so that the first step does not pay for them."""
        self.implicit.compile()
        self.save()
        self.points_pass(PointsPass.RESTORE)
        self.changes_ratio(self.dt)

    def points_pass(self, what: PointsPass, dt: float = 0.0) -> None:
        points_pass(self.st.points, self.before, self.rates, self.changes, dt, what)

    def save(self) -> None:
        """Keep the points as they are (:attr:`before`)."""
        self.points_pass(PointsPass.SAVE)

    def set_step(self, dt: float) -> None:
        """Make the next step ``dt`` long, its heat substeps at most heat_step_max."""
        self.st.scalars.dt[None] = dt
        self.implicit.heat.set_step(dt, self.heat_step_max)

    def _limit(self, t: float, t_end: float) -> float:
        """The next step from t: the controller's, cut to land on t_end or a laser switch."""
        stop = min([t_end, *(e for e in self.edges if e > t * (1 + 1e-12))])
        return min(self.dt, stop - t)

    def changes_ratio(self, dt: float) -> float:
        """The changes of the points since :attr:`before` (over dt), as a multiple of the
        controls: the largest of dT / dT_max, de / de_max (or the strain error's ratio) and
        dx / (cells h). The strain error grows as dt^2: its square root, so that the next step
        follows from it as from the others."""
        self.points_pass(PointsPass.CHANGES, dt)
        dT, de, dx, dp, ep = (float(x) for x in self.changes[None])
        c, h = self.controls, self.st.cfg.h
        if c.strain_error > 0.0:
            strain = math.sqrt(ep / c.strain_error)
        else:
            strain = (dp if c.plastic else de) / c.strain
        return max(dT / c.temperature_K, strain, dx / (c.cells * h))

    def step(self, t_end: float = math.inf) -> bool:
        """One accepted step (redoing refused ones), at most up to ``t_end``; none, and False,
        where the step would be shorter than ``handback_below`` (the hybrid's explicit steps
        take it)."""
        st = self.st
        while True:
            if self.hands_back():
                return False
            t = float(st.scalars.t[None])
            dt = self._limit(t, t_end)
            cut = dt < self.dt
            before = checkpoint.capture(st, points=False)
            self.save()
            self.set_step(dt)
            try:
                self.implicit.step()
            except NewtonError as e:
                self._redo(before, dt, SHRINK**0.5 * dt, str(e))
                continue
            ratio = self.changes_ratio(dt)
            if ratio > REDO and dt > self.controls.dt_min:
                dT, de, dx, dp, ep = (float(x) for x in self.changes[None])
                why = (
                    f"changes {ratio:.2g} x the controls (dT {dT:.3g} K, strain {de:.3g}, "
                    f"plastic strain {dp:.3g} (error {ep:.3g}), motion {dx / st.cfg.h:.3g} "
                    "cells)"
                )
                self._redo(before, dt, next_step(dt, ratio, self.controls), why)
                continue
            self.last_dt = dt
            if self.controls.strain_error > 0.0:
                self.points_pass(PointsPass.ACCEPT)
            if not (cut and ratio <= 1.0):
                self.dt = next_step(dt, ratio, self.controls)
            return True

    def hands_back(self) -> bool:
        """Whether the next step would be shorter than ``handback_below`` (the hybrid's
        explicit steps take it)."""
        return self.dt < self.handback_below

    def _redo(self, before: dict[str, np.ndarray], dt: float, smaller: float, why: str) -> None:
        """Put the state back and make the next try ``smaller``; below dt_min, give up."""
        self.points_pass(PointsPass.RESTORE)
        checkpoint.restore(self.st, before)
        init_box(self.st)
        self.refused += 1
        if dt <= self.controls.dt_min:
            raise SimulationError(
                f"adaptive step at t = {self.st.scalars.t[None]:.4g} s: refused at the smallest "
                f"step time.dt_min_s = {self.controls.dt_min:.3g} s ({why}); try a smaller "
                "time.dt_min_s or looser time.max_temperature_change_K / max_strain_increment"
            )
        self.dt = max(self.controls.dt_min, min(smaller, dt))

    def advance_to(self, t_end: float, hooks: StepHooks = NO_HOOKS) -> int:
        """Steps that land on ``t_end`` (s), or until a hand-back (the hybrid's explicit steps
        take it; :meth:`hands_back`); returns how many were taken."""
        n = 0
        while float(self.st.scalars.t[None]) < t_end * (1.0 - 1e-12):
            if self.hands_back():  # before a study's load, not after it
                break
            if hooks.before is not None:
                hooks.before()
            if not self.step(t_end):
                break
            n += 1
            if hooks.after is not None:
                hooks.after()
            if hooks.stopping():
                break
        return n
