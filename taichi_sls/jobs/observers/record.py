"""The summary's record of the run as a whole: the first and last frame's monitors, the
settling before it, and the integrator's counts (refused adaptive steps, extrapolation's kept
points) over the whole run, a resumed one included."""

from __future__ import annotations

from typing import Any

from ...solver.simulation import Simulation
from ..run_loop import Frame, Observer, RunEnd


def _counts(sim: Simulation) -> dict[str, int]:
    return {
        "refused_steps": sim.adaptive.refused if sim.adaptive is not None else 0,
        "extrapolation_kept_points": getattr(sim.implicit, "kept", 0),
    }


def linear_solves(sim: Simulation) -> dict[str, Any]:
    """The implicit steps' solves since the run (or its resume) started: the linear solver of
    the last step (time.linear_solver) and its direct factorization's library
    (time.direct_solver, where it factorizes), Newton iterations, linear solves, factorizations (or
    multigrid set-ups), those of a new pattern (``analyses``: a new elimination order and
    symbolic factor), conjugate-gradient iterations and the last step's relative residual."""
    imp = sim.implicit
    stats = getattr(imp.linear, "stats", None)
    return {
        "solver": imp.last.solver or None,
        "direct_solver": imp.linear.backend if imp.last.solver == "direct" else None,
        "newton_iterations": int(imp.newton_total),
        "solves": stats.solves if stats is not None else 0,
        "factorizations": stats.factorizations if stats is not None else 0,
        "analyses": stats.analyses if stats is not None else 0,
        "cg_iterations": stats.cg_iterations if stats is not None else 0,
        "last_residual": float(imp.last.residual),
    }


class Record(Observer):
    """``initial``, ``final``, ``settle``, the step counts and the integrator's counts."""

    key = "record"
    records_failed_frame = True

    def __init__(self) -> None:
        self.initial: dict[str, float] | None = None
        self.last: dict[str, float] = {}
        self.settle: dict[str, float] | None = None
        self.counts_before = {"refused_steps": 0, "extrapolation_kept_points": 0}
        self._sim: Simulation | None = None

    def start(self, sim: Simulation) -> None:
        self._sim = sim

    def frame(self, frame: Frame) -> None:
        if self.initial is None:
            self.initial = frame.monitors
        self.last = frame.monitors

    def counts(self, sim: Simulation) -> dict[str, int]:
        """The integrator's counts over the whole run (before a resume and since)."""
        return {k: v + self.counts_before[k] for k, v in _counts(sim).items()}

    def finish(self, end: RunEnd) -> None:
        sim, s = end.sim, end.summary
        if self.settle is not None:
            s["settle"] = self.settle
        if self.initial is not None:  # else stopped before its first frame
            s.update(initial=self.initial, final=self.last)
        s.update(steps=sim.steps, simulated_s=sim.t)
        s.update(self.counts(sim))
        if sim.implicit is not None:
            s["linear_solves"] = linear_solves(sim)
        s.update(
            handover_s=sim.handover.at_s if sim.handover is not None else None,
            handbacks=sim.handover.handbacks if sim.handover is not None else 0,
            T_peak_C=self.last.get("T_peak_C"),
        )

    def state(self) -> dict[str, Any]:
        counts = self.counts(self._sim) if self._sim is not None else self.counts_before
        return {"initial": self.initial, "last": self.last, "settle": self.settle, **counts}

    def restore(self, state: dict[str, Any]) -> None:
        self.initial, self.last = state.get("initial"), state.get("last", {})
        self.settle = state.get("settle")
        self.counts_before = {k: int(state.get(k, 0)) for k in self.counts_before}
