"""The time series: one row of monitors per frame (timeseries.csv), its plot at the end."""

from __future__ import annotations

from typing import Any

from ...io.writer import OutputWriter
from ..run_loop import Frame, Observer, RunEnd


class TimeSeries(Observer):
    """timeseries.csv, row by row; timeseries.png at the end (``events``: label -> time in s,
    marked on a bed's), not drawn after an interrupt."""

    key = "series"
    records_failed_frame = True

    def __init__(self, writer: OutputWriter, events: dict[str, float] | None = None) -> None:
        self.writer, self.events = writer, events

    def frame(self, frame: Frame) -> None:
        self.writer.row(frame.monitors)

    def finish(self, end: RunEnd) -> None:
        if not end.interrupted:
            self.writer.plot_series(self.events)

    def state(self) -> dict[str, Any]:
        return self.writer.series.saved()

    def restore(self, state: dict[str, Any]) -> None:
        self.writer.series.restore(state)
