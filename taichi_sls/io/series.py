"""The time series: one row of monitors per output frame in a CSV rewritten atomically (so it
is always valid), and its plot."""

from __future__ import annotations

import contextlib
import csv
import io
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .atomic import atomic_write_text
from .frame_panels import save_png

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
        self._write()

    def _write(self) -> None:
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

    def saved(self) -> dict[str, list]:
        """The header and rows so far (as written), for a checkpoint."""
        return {"header": list(self.header), "lines": [list(c) for c in self._lines]}

    def restore(self, saved: dict[str, list]) -> None:
        """Continue from :meth:`saved`: the rows up to a checkpoint, the file rewritten so."""
        self.header = list(saved["header"])
        self._lines = [list(c) for c in saved["lines"]]
        self._write()

    def resume(self) -> None:
        """Keep the rows an earlier run wrote."""
        if self.path.is_file():
            rows = list(csv.reader(self.path.open()))
            if rows:
                self.header = rows[0]
                self._lines = rows[1:]


LOG_AXIS_DECADES = 2  # times spanning more decades than this are plotted on a log axis

# A panel of the plot: one column (its label from SERIES_LABELS), or (y label, columns) drawn
# together with a legend.
Panel = str | tuple[str, tuple[str, ...]]
# a bed's panels (jobs/bed_outcome.bed_monitors and the point monitors), three to a row
BED_PANELS: tuple[Panel, ...] = (
    "relative_density",
    "molten_fraction",
    "T_max_C",
    "neck_median_um",
    (
        "contacts",
        ("contacts", "contacts_melted_through", "contacts_molten", "contacts_fused"),
    ),
    "mean_top_um",
)
BED_PANELS_PER_ROW = 3
SERIES_LABELS.update(
    {
        "relative_density": "relative density",
        "molten_fraction": "molten fraction (of the mass)",
        "neck_median_um": "median neck [um]",
        "mean_top_um": "mean layer top [um]",
        "contacts": "all",
        "contacts_melted_through": "melted through",
        "contacts_molten": "holding melt",
        "contacts_fused": "fused",
    }
)
START_LABEL = "value at t = 0"
GROUP_STYLES = {"contacts": {"color": "0.6", "ls": "--"}}  # the total: a reference line


def plot_series(
    csv_path: Path,
    png_path: Path,
    columns: Sequence[Panel],
    per_row: int | None = None,
    events: dict[str, float] | None = None,
    start_lines: bool = False,
) -> bool:
    """Write :func:`series_figure` to ``png_path``; False (and nothing written) when it has
    nothing to plot."""
    fig = series_figure(csv_path, columns, per_row, events, start_lines)
    if fig is None:
        return False
    save_png(fig, Path(png_path), dpi=100)
    return True


def series_figure(
    csv_path: Path,
    columns: Sequence[Panel],
    per_row: int | None = None,
    events: dict[str, float] | None = None,
    start_lines: bool = False,
) -> Figure | None:
    """Each of ``columns`` (those present; see Panel) against ``t_s`` in microseconds, one
    panel each, ``per_row`` panels to a row (default: all in one), on a log axis when the times
    span more than LOG_AXIS_DECADES decades; ``events`` (label: time in s) as dotted verticals;
    with ``start_lines``, a one-column panel on a log axis shows its value at t = 0 (which the
    axis cannot) as a dashed line. The figure's title says what the lines mark.

    None when there is nothing to plot: fewer than two rows, no ``t_s`` column or none of
    ``columns`` present. Unparseable cells plot as gaps.
    """
    csv_path = Path(csv_path)
    if not csv_path.is_file():
        return None
    with csv_path.open(newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    panels = [(SERIES_LABELS.get(c, c), (c,)) if isinstance(c, str) else c for c in columns]
    present = [(label, [c for c in cols if rows and c in rows[0]]) for label, cols in panels]
    present = [(label, cols) for label, cols in present if cols]
    if len(rows) < 2 or "t_s" not in rows[0] or not present:
        return None

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
    ncols = min(per_row or len(present), len(present))
    nrows = math.ceil(len(present) / ncols)
    fig = Figure(figsize=(4.2 * ncols, 3.2 * nrows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
    for ax in axes[len(present) :]:
        ax.set_visible(False)
    keep = t_us > 0 if log_axis else np.isfinite(t_us)  # t = 0 has no place on a log axis
    for ax, (label, cols) in zip(axes, present, strict=False):
        for name in cols:
            style = GROUP_STYLES.get(name, {}) if len(cols) > 1 else {}
            line_label = SERIES_LABELS.get(name, name)
            if log_axis:
                ax.semilogx(t_us[keep], col(name)[keep], lw=1.2, marker=".", ms=3, **style)
            else:
                ax.plot(t_us[keep], col(name)[keep], lw=1.2, **style)
            ax.lines[-1].set_label(line_label)
        if start_lines and log_axis and len(cols) == 1 and t_us[0] == 0.0:
            ax.axhline(col(cols[0])[0], color="0.6", lw=0.8, ls="--", label=START_LABEL)
        for event, t_s in (events or {}).items():
            ax.axvline(t_s * 1e6, color="0.4", lw=0.8, ls=":", label=event)
        if len(cols) > 1:
            ax.legend(fontsize=7)
        ax.set_xlabel("t [us]")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    notes = [f"dotted: {e} at {t_s * 1e6:.4g} us" for e, t_s in (events or {}).items()]
    if start_lines and log_axis:
        notes.append(f"dashed: the {START_LABEL}")
    if notes:
        fig.suptitle("; ".join(notes), fontsize=9)
    return fig


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
