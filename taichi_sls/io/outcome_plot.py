"""``outcome.png``: the neck and the molten fraction against time on a log axis over the whole
run, and the final shape over the initial one, whole and zoomed on the neck.

The final shape is the material the points stand for (filled, io/frames.material_raster), the
initial one the outline of each body drawn as a line in a contrasting colour: dots of both, as
before, could not be told apart."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from .frame_panels import save_png
from .frames import MATERIAL_LEVEL, material_raster, point_spacing
from .series import read_series

FINAL_COLOUR = "#4a7fb5"  # filled final material
INITIAL_COLOUR = "#d62728"  # initial outline, a red line over the blue fill
FOOTPRINT_PAD = 4  # raster margin around the points, in spacings: more than the tent's reach
PIXELS_PER_SPACING = 4  # raster resolution of the shapes: smooth outlines at the point scale
ZOOM_HALF_WIDTH = 0.25  # the neck zoom spans this fraction of the centroid distance each side
ZOOM_PAD_SPACINGS = 3  # margin of the zoom above and below the material, in point spacings


def plot_outcome(
    out_dir: Path, x_initial: np.ndarray, x_final: np.ndarray, body: np.ndarray
) -> Path | None:
    """Draw OUT/outcome.png from OUT/timeseries.csv and the point positions (m); None when the
    series has fewer than two rows."""
    out_dir = Path(out_dir)
    path = out_dir / "timeseries.csv"
    if not path.is_file():
        return None
    s = read_series(path)
    if len(s.get("t_s", [])) < 2:
        return None
    fig = Figure(figsize=(14, 3.6), layout="constrained")
    FigureCanvasAgg(fig)
    ax_neck, ax_shape, ax_zoom = fig.subplots(1, 3, width_ratios=[1.2, 1, 0.5])
    t = s["t_s"]
    keep = t > 0
    ax_neck.semilogx(t[keep], s["contact_line_um"][keep], "C0o-", ms=3, label="contact line")
    ax_neck.set_xlabel("t [s]")
    ax_neck.set_ylabel("contact line [um]", color="C0")
    ax_neck.grid(True, which="both", alpha=0.3)
    ax_m = ax_neck.twinx()
    ax_m.semilogx(t[keep], s["molten_fraction"][keep], "C3s--", ms=3, label="molten fraction")
    ax_m.set_ylabel("molten fraction", color="C3")
    ax_m.set_ylim(-0.02, 1.02)
    if np.isfinite(s["contact_line_um"][0]):
        ax_neck.axhline(s["contact_line_um"][0], color="C0", lw=0.8, ls=":")
    ax_neck.set_title("neck and melt over the run (dotted: the start)", fontsize=10)
    _draw_shapes(
        fig,
        ax_shape,
        ax_zoom,
        np.asarray(x_initial) * 1e6,
        np.asarray(x_final) * 1e6,
        np.asarray(body),
    )
    out = out_dir / "outcome.png"
    save_png(fig, out, dpi=90)
    return out


def _outline(
    x: np.ndarray, spacing: float, lo: np.ndarray, shape: tuple[int, int], pixel: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pixel centres and the area fraction of the points ``x`` (um) on the shapes' raster."""
    frac, _ = material_raster(x, [], spacing, (float(lo[0]), float(lo[1])), shape, pixel)
    ny, nx = shape
    return lo[0] + (np.arange(nx) + 0.5) * pixel, lo[1] + (np.arange(ny) + 0.5) * pixel, frac


def _draw_shapes(
    fig: Figure, ax: object, ax_zoom: object, xi: np.ndarray, xf: np.ndarray, body: np.ndarray
) -> None:
    """Final material filled, each body's initial outline as a line; the same zoomed on the neck
    (the mid-plane between the centroids of bodies 0 and 1)."""
    lo, hi = xi.min(axis=0), xi.max(axis=0)
    span = hi - lo
    # points that flew off (a failed run) would stretch the axes beyond drawing
    ok = np.isfinite(xf).all(axis=1) & np.all(np.abs(xf - 0.5 * (lo + hi)) < 2 * span, axis=1)
    spacing = point_spacing(xi, float(span.max()) / 100)
    pixel = spacing / PIXELS_PER_SPACING
    both = np.vstack([xi, xf[ok]])
    corner = both.min(axis=0) - FOOTPRINT_PAD * spacing
    nx, ny = np.ceil((both.max(axis=0) + FOOTPRINT_PAD * spacing - corner) / pixel).astype(int)
    shape = (int(ny), int(nx))
    final = _outline(xf[ok], spacing, corner, shape, pixel)
    initial = [_outline(xi[body == b], spacing, corner, shape, pixel) for b in np.unique(body)]
    for a in (ax, ax_zoom):
        a.contourf(*final, levels=[MATERIAL_LEVEL, np.inf], colors=[FINAL_COLOUR])
        for xc, yc, frac in initial:
            a.contour(
                xc,
                yc,
                frac,
                levels=[MATERIAL_LEVEL],
                colors=[INITIAL_COLOUR],
                linewidths=1.2,
                linestyles="--",
            )
        a.set_aspect("equal")
        a.set_xlabel("x [um]")
    ax.set_ylabel("y [um]")
    ax.set_title("final shape over the initial one", fontsize=10)
    ax.legend(
        handles=[
            Patch(facecolor=FINAL_COLOUR, label="final"),
            Line2D([], [], color=INITIAL_COLOUR, ls="--", lw=1.2, label="initial"),
        ],
        loc="upper center",
        ncols=2,
        fontsize=8,
        framealpha=0.9,
    )
    ax.set_ylim(corner[1], corner[1] + ny * pixel + 0.25 * span[1])  # room for the legend
    if len(np.unique(body)) < 2:
        ax_zoom.set_visible(False)
        return
    cx = [float(xi[body == b, 0].mean()) for b in (0, 1)]
    mid, half = 0.5 * (cx[0] + cx[1]), ZOOM_HALF_WIDTH * abs(cx[1] - cx[0])
    near = np.abs(xf[ok, 0] - mid) <= half
    ys = xf[ok][near, 1] if near.any() else xi[:, 1]
    pad = ZOOM_PAD_SPACINGS * spacing
    ax_zoom.set_xlim(mid - half, mid + half)
    ax_zoom.set_ylim(float(ys.min()) - pad, float(ys.max()) + pad)
    ax_zoom.set_title("the neck", fontsize=10)
    ax.indicate_inset_zoom(ax_zoom, edgecolor="0.3")
