"""The stop rule of ``time.stop = "solidified"`` (jobs/schedule.settled), frame by frame."""

from __future__ import annotations

from collections import deque
from typing import Any

from ...config import Case
from ..run_loop import Frame, Observer, RunEnd
from ..schedule import SETTLED_FRAMES, settled


class StopRule(Observer):
    """``stop`` once the case's run to solidification has settled; ``ended`` says how a run
    that went through its frames ended (complete, or max_time when it never settled)."""

    key = "stop_rule"

    def __init__(self, case: Case) -> None:
        self.case = case
        self.solidify = case.time.stop == "solidified"
        self.before: deque[dict[str, float]] = deque(maxlen=SETTLED_FRAMES)
        self.last: dict[str, float] | None = None
        self.stop = False

    def frame(self, frame: Frame) -> None:
        if self.last is not None:
            self.before.append(self.last)
        self.last = frame.monitors
        self.stop = self.solidify and settled(self.last, self.case, frame.sim.t, self.before)

    @property
    def ended(self) -> str:
        return "max_time" if self.solidify and not self.stop else "complete"

    def finish(self, end: RunEnd) -> None:
        if end.status == "max_time":
            end.warnings.append(
                f"time.max_s = {self.case.time.max_s:g} s reached before the pair solidified "
                "and settled: the outcome is not final"
            )

    def state(self) -> dict[str, Any]:
        return {"before": list(self.before), "last": self.last}

    def restore(self, state: dict[str, Any]) -> None:
        self.before.extend(state.get("before", []))
        self.last = state.get("last")
