"""The time series: one row of monitors per output frame in a CSV rewritten atomically (so it
is always valid), and its plot."""

from __future__ import annotations

import contextlib
import csv
import io
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .atomic import atomic_write_text
from .frames import save_png

SERIES_LABELS = {
    "contact_line_um": "contact line [um]",
    "T_max_C": "peak temperature [C]",
}
MONITORED = ("contact_line_um", "T_max_C")


def fmt_cell(v: Any) -> str:
    """CSV cell: ints exact, floats round-trip exact (repr), NaN/inf as nan/inf, None empty."""
    if v is None:
        return ""
    if isinstance(v, (bool, np.bool_)):
        return str(int(v))
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    return str(v)


class SeriesWriter:
    """Rows of monitors -> ``path`` (CSV). The first row fixes the column order; keys first seen
    later become new columns at the end (earlier rows left empty there) rather than being
    dropped."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.header: list[str] = []
        self._lines: list[list[str]] = []  # formatted cells; padded when the header grows

    def row(self, values: dict[str, float]) -> None:
        """Append a row and rewrite the file atomically."""
        for k in values:
            if k not in self.header:
                self.header.append(k)
        self._lines.append([fmt_cell(values.get(k)) for k in self.header])
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(self.header)
        n = len(self.header)
        for cells in self._lines:
            w.writerow(cells + [""] * (n - len(cells)))
        atomic_write_text(self.path, buf.getvalue())

    def rows(self) -> list[dict[str, float]]:
        """The rows so far, as numbers (empty cells as NaN)."""
        out = []
        for cells in self._lines:
            row = {}
            for k, v in zip(self.header, cells, strict=False):
                try:
                    row[k] = float(v)
                except ValueError:
                    row[k] = float("nan")
            out.append(row)
        return out

    def resume(self) -> None:
        """Keep the rows an earlier run wrote."""
        if self.path.is_file():
            rows = list(csv.reader(self.path.open()))
            if rows:
                self.header = rows[0]
                self._lines = rows[1:]


LOG_AXIS_DECADES = 2  # times spanning more decades than this are plotted on a log axis


def plot_series(csv_path: Path, png_path: Path, columns: list[str]) -> bool:
    """Plot each of ``columns`` (those present) against ``t_s`` in microseconds, one panel each,
    on a log axis when the times span more than LOG_AXIS_DECADES decades.

    Returns False (and writes nothing) when there is nothing to plot: fewer than two rows, no
    ``t_s`` column or none of ``columns`` present. Unparseable cells plot as gaps.
    """
    csv_path, png_path = Path(csv_path), Path(png_path)
    if not csv_path.is_file():
        return False
    with csv_path.open(newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    present = [c for c in columns if rows and c in rows[0]]
    if len(rows) < 2 or "t_s" not in rows[0] or not present:
        return False

    def col(name: str) -> np.ndarray:
        out = np.full(len(rows), np.nan)
        for i, r in enumerate(rows):
            with contextlib.suppress(TypeError, ValueError):
                out[i] = float(r[name])
        return out

    t_us = col("t_s") * 1e6
    pos = t_us[np.isfinite(t_us) & (t_us > 0)]
    # log-spaced rows (a laser case) span decades: a linear axis would squeeze the transient
    log_axis = pos.size > 1 and pos.max() / pos.min() > 10.0**LOG_AXIS_DECADES
    fig = Figure(figsize=(4.2 * len(present), 3.2), layout="constrained")
    FigureCanvasAgg(fig)
    for ax, name in zip(fig.subplots(1, len(present), squeeze=False)[0], present, strict=True):
        if log_axis:
            keep = t_us > 0  # t = 0 has no place on a log axis
            ax.semilogx(t_us[keep], col(name)[keep], lw=1.2, marker=".", ms=3)
        else:
            ax.plot(t_us, col(name), lw=1.2)
        ax.set_xlabel("t [us]")
        ax.set_ylabel(SERIES_LABELS.get(name, name))
        ax.grid(True, alpha=0.3)
    save_png(fig, png_path, dpi=100)
    return True


def read_series(path: str | Path) -> dict[str, np.ndarray]:
    """A ``timeseries.csv`` as one float array per column (empty cells as NaN)."""
    with Path(path).open(newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        return {}
    out = {}
    for k in rows[0]:
        vals = []
        for r in rows:
            try:
                vals.append(float(r[k]))
            except (TypeError, ValueError):
                vals.append(np.nan)
        out[k] = np.array(vals)
    return out
