"""The pair's verdict (jobs/outcome.py): the neck followed frame by frame, the outcome record
and outcome.png at the end."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from ...config import Case
from ...io.frames3d import section_layer
from ...io.outcome_plot import plot_outcome
from ..outcome import NeckHistory, neck_region, outcome
from ..run_loop import Frame, Observer, RunEnd


class PairVerdict(Observer):
    """The summary's ``outcome`` of a pair (bodies 0 and 1), judged by the rule of every contact
    (jobs/fusion_rule.py) against ``baseline_um``, the unheated neck when one was made
    (jobs/unheated.py, or the settled neck)."""

    key = "verdict"
    records_failed_frame = True

    def __init__(self, case: Case, out_dir: Path, baseline_um: float | None = None) -> None:
        self.case, self.out_dir, self.baseline_um = case, out_dir, baseline_um
        self.history = NeckHistory()
        self.last: dict[str, float] = {}

    def frame(self, frame: Frame) -> None:
        self.history.add(frame.monitors)
        self.last = frame.monitors

    def finish(self, end: RunEnd) -> None:
        if not self.last:  # stopped before its first frame: nothing to judge
            return
        sim = end.sim
        arrays = sim.point_arrays()
        in_neck = neck_region(self.case, arrays["x0"], sim.scene.body, arrays["mass"])
        solid = end.status == "complete" and self.last["molten_fraction"] == 0.0
        end.summary["outcome"] = outcome(
            self.case,
            self.history,
            self.last,
            arrays["time_molten"],
            in_neck,
            solidified=solid,
            baseline_um=self.baseline_um,
        )
        if end.interrupted:
            return
        try:  # a 3D pair's outcome.png is drawn from one layer of points
            plot_outcome(
                self.out_dir, *section_layer(self.case, sim.scene.x, arrays["x"], sim.scene.body)
            )
        except Exception as e:  # noqa: BLE001 -- a plot must never cost the run's outputs
            print(f"warning: outcome.png not drawn ({type(e).__name__}: {e})", file=sys.stderr)

    def state(self) -> dict[str, Any]:
        return {"history": vars(self.history), "last": self.last, "baseline_um": self.baseline_um}

    def restore(self, state: dict[str, Any]) -> None:
        vars(self.history).update(state.get("history", {}))
        self.last = state.get("last", {})
        self.baseline_um = state.get("baseline_um", self.baseline_um)
