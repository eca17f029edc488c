"""A bed run's ``outcome.png``: the layer at the end with every contact marked by its outcome
(the contacts map, the melted powder tinted), and the contacts' necks at the start, as their
melting ended and at the end (histogram) beside each contact's neck growth along the track.

The pair's outcome (io/outcome_plot.py) reads bodies 0 and 1 only: in a bed its neck is an
arbitrary contact and its contact line spans the layer, so a bed gets this figure instead. The
quantities are those of the contacts table (jobs/bed_outcome.py); the map's material is the
raster of the frames (io/frames.material_raster)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from .contacts_plot import KINDS, contact_kind
from .frame_panels import save_png
from .frames import MATERIAL_LEVEL, material_raster, point_spacing

SOLID_COLOUR = "#c9ced6"  # powder never fully molten: light grey
MELTED_COLOUR = "#f3c58f"  # powder that was fully molten at some time: light orange
PIXELS_PER_SPACING = 2  # raster resolution of the map, per point spacing
NECK_HISTS = (  # (column, label, colour) of the histogram
    ("neck_initial_um", "start", "0.45"),
    ("neck_melt_um", "as melting ended", "#ff7f0e"),
    ("neck_final_um", "end", "#1f77b4"),
)


def plot_bed_outcome(
    out_dir: Path,
    rows: list[dict[str, Any]],
    x_um: np.ndarray,
    *,
    time_molten: np.ndarray | None = None,
    density: tuple[float, float] | None = None,
    neck_growth: float | None = None,
    spacing_um: float | None = None,
    dpi: int = 90,
) -> Path | None:
    """Draw :func:`bed_outcome_figure` to OUT/outcome.png; None without contacts."""
    fig = bed_outcome_figure(
        rows,
        x_um,
        time_molten=time_molten,
        density=density,
        neck_growth=neck_growth,
        spacing_um=spacing_um,
    )
    if fig is None:
        return None
    out = Path(out_dir) / "outcome.png"
    save_png(fig, out, dpi=dpi)
    return out


def bed_outcome_figure(
    rows: list[dict[str, Any]],
    x_um: np.ndarray,
    *,
    time_molten: np.ndarray | None = None,
    density: tuple[float, float] | None = None,
    neck_growth: float | None = None,
    spacing_um: float | None = None,
) -> Figure | None:
    """The bed's outcome from the contacts table's rows, the points' final positions (um) and,
    when given, their time above T_m (s; the melted powder tinted), the layer's relative
    density (start, end) and the fusion rule's neck growth (its line on the growth panel).
    ``spacing_um``: the points' spacing for the map's raster (default: read from the points;
    a 3D run's projection onto x-y gives it, since its points lie on each other to round-off
    until they move). None without contacts."""
    if not rows:
        return None
    fig = Figure(figsize=(13, 6.8), layout="constrained")
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(2, 2, height_ratios=[1.0, 1.0])
    ax_map = fig.add_subplot(grid[0, :])
    ax_hist, ax_growth = fig.add_subplot(grid[1, 0]), fig.add_subplot(grid[1, 1])
    kinds = [contact_kind(r) for r in rows]
    _draw_map(ax_map, rows, kinds, np.asarray(x_um, dtype=float), time_molten, spacing_um)
    n, fused = len(rows), kinds.count("fused")
    title = f"the layer at the end: {n} contacts, {fused} fused ({fused / n:.0%})"
    if density is not None and all(np.isfinite(density)):
        title += f"; relative density {density[0]:.3f} -> {density[1]:.3f}"
    ax_map.set_title(title, fontsize=10)
    _draw_histogram(ax_hist, rows)
    _draw_growth(ax_growth, rows, kinds, neck_growth)
    return fig


def _draw_map(
    ax: Axes,
    rows: list[dict[str, Any]],
    kinds: list[str],
    x: np.ndarray,
    time_molten: np.ndarray | None,
    spacing_um: float | None = None,
) -> None:
    """The final material filled (melted powder tinted) and each contact where it started,
    coloured by its outcome."""
    ok = np.isfinite(x).all(axis=1)
    x = x[ok]
    if len(x):
        lo, hi = x.min(axis=0), x.max(axis=0)
        spacing = spacing_um or point_spacing(x, float((hi - lo).max()) / 100)
        pixel = spacing / PIXELS_PER_SPACING
        corner = lo - 4 * spacing
        nx, ny = (np.ceil((hi + 4 * spacing - corner) / pixel)).astype(int)
        melted = np.zeros(len(x)) if time_molten is None else (time_molten[ok] > 0.0) * 1.0
        frac, (m,) = material_raster(
            x, [melted], spacing, (float(corner[0]), float(corner[1])), (int(ny), int(nx)), pixel
        )
        # 0: never molten, 1: molten at some time (the tent's mean split at 1/2)
        shade = np.where(np.nan_to_num(m, nan=0.0) >= 0.5, 1.0, 0.0)
        ax.imshow(
            np.ma.masked_where(frac < MATERIAL_LEVEL, shade),
            cmap=ListedColormap([SOLID_COLOUR, MELTED_COLOUR]),
            vmin=0.0,
            vmax=1.0,
            origin="lower",
            extent=(corner[0], corner[0] + nx * pixel, corner[1], corner[1] + ny * pixel),
            interpolation="nearest",
        )
        ax.set_xlim(corner[0], corner[0] + nx * pixel)
        top = corner[1] + ny * pixel
        ax.set_ylim(corner[1], top + 0.3 * (top - corner[1]))  # room for the legend
    handles = [Patch(facecolor=SOLID_COLOUR, label="never fully molten")]
    if time_molten is not None:
        handles.append(Patch(facecolor=MELTED_COLOUR, label="fully molten at some time"))
    for kind, colour in KINDS.items():
        sel = [k == kind for k in kinds]
        if any(sel):
            xs = [r["x_um"] for r, s in zip(rows, sel, strict=True) if s]
            ys = [r["y_um"] for r, s in zip(rows, sel, strict=True) if s]
            (line,) = ax.plot(
                xs, ys, "o", ms=5, color=colour, mec="k", mew=0.4, label=f"{kind} ({sum(sel)})"
            )
            handles.append(line)
    ax.set_aspect("equal")
    ax.set_xlabel("x [um]")
    ax.set_ylabel("y [um]")
    ax.legend(handles=handles, fontsize=8, loc="upper center", ncols=6, framealpha=0.9)


def _draw_histogram(ax: Axes, rows: list[dict[str, Any]]) -> None:
    """The contacts' necks at the start, as their melting ended and at the end."""
    cols = {k: np.array([r[k] for r in rows], dtype=float) for k, _, _ in NECK_HISTS}
    every = np.concatenate([v[np.isfinite(v)] for v in cols.values()])
    bins = np.linspace(every.min(), every.max(), 25) if np.ptp(every) > 0 else 10
    for k, label, colour in NECK_HISTS:
        v = cols[k][np.isfinite(cols[k])]
        if len(v):
            ax.hist(
                v, bins=bins, histtype="step", lw=1.5, color=colour, label=f"{label} ({len(v)})"
            )
    ax.set_xlabel("neck [um]")
    ax.set_ylabel("contacts")
    ax.set_title("the necks (as melting ended: the contacts that melted)", fontsize=10)
    ax.legend(fontsize=8)


def _draw_growth(
    ax: Axes, rows: list[dict[str, Any]], kinds: list[str], neck_growth: float | None
) -> None:
    """Each contact's neck growth (final over initial) against its x, coloured by outcome; a
    contact whose initial section held no point (a 3D neck below the grid's reach) has no growth
    to draw and is left out."""
    x = np.array([r["x_um"] for r in rows], dtype=float)
    initial = np.array([r["neck_initial_um"] for r in rows], dtype=float)
    final = np.array([r["neck_final_um"] for r in rows], dtype=float)
    growth = np.full_like(initial, np.nan)
    seen = initial > 0.0
    growth[seen] = 100.0 * (final[seen] / initial[seen] - 1.0)
    for kind, colour in KINDS.items():
        sel = np.array([k == kind for k in kinds])
        if sel.any():
            ax.plot(x[sel], growth[sel], "o", ms=4, color=colour, mec="k", mew=0.3, label=kind)
    ax.axhline(0.0, color="0.5", lw=0.8)
    if neck_growth is not None:
        ax.axhline(100.0 * neck_growth, color="#2ca02c", lw=0.8, ls="--", label="fusion rule")
    ax.set_xlabel("x of the contact [um]")
    ax.set_ylabel("neck growth, end over start [%]")
    ax.set_title("neck growth along the track", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
