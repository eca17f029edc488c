"""The progress bar of a run (jobs/progress.py), moved on after every chunk of steps."""

from __future__ import annotations

import math

from ...config import Case
from ...solver.simulation import Simulation
from ..outcome import laser_acted
from ..progress import Progress
from ..run_loop import Frame, Observer, RunEnd


class ProgressBar(Observer):
    """A bar from the loop's start to ``horizon_s`` (end_s, or max_s for a run to
    solidification); ``tick`` after each chunk of steps."""

    def __init__(self, case: Case, horizon_s: float, enabled: bool = True) -> None:
        self.case, self.horizon_s, self.enabled = case, horizon_s, enabled
        self.bar: Progress | None = None

    def start(self, sim: Simulation) -> None:
        c = self.case
        walls = [w.temperature_C for w in c.boundary.walls(c.domain.dim) if w.thermal == "fixed"]
        self.bar = Progress(
            self.horizon_s,
            sim.t,
            enabled=self.enabled,
            solidify=c.time.stop == "solidified",
            T_c=min(m.solid_below_C() for m in c.materials.values()),
            T_wall=min(walls) if walls else math.nan,
            adaptive=sim.adaptive is not None,
            lasers_off_s=c.lasers_off_s() if laser_acted(c) else math.nan,
        )

    def tick(self, sim: Simulation, steps_per_s: float) -> None:
        if self.bar is not None:
            self.bar.update(sim.t, steps_per_s if math.isfinite(steps_per_s) else 0.0, sim.step_dt)

    def frame(self, frame: Frame) -> None:
        if self.bar is not None:
            self.bar.note(frame.monitors)

    def finish(self, end: RunEnd) -> None:
        if self.bar is not None:
            self.bar.close()
