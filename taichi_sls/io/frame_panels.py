"""The pieces both frame painters (io/frames.py in 2D, io/frames3d.py in 3D) draw with: the
title, the temperature's colour scale and limits, the image panels of a section, the melt
outline, the checked x-y range and the PNG file."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")  # headless: the solver runs on machines without a display

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import Colormap, ListedColormap
from matplotlib.contour import QuadContourSet
from matplotlib.figure import Figure
from matplotlib.image import AxesImage

from .atomic import atomic_write_bytes

MELT_LEVEL = 0.5  # liquid fraction drawn as the melt outline
# The bed's temperature scale: inferno from a quarter up, so that the powder at the bed
# temperature (the scale's foot) is a clear purple, not the black of inferno's foot, which reads
# as shadow or void against the white background.
BED_T_CMAP_FROM = 0.25


def temperature_cmap(bed: bool) -> Colormap:
    """inferno for a pair (today's frames); for a bed inferno from BED_T_CMAP_FROM up."""
    base = matplotlib.colormaps["inferno"]
    if not bed:
        return base
    return ListedColormap(base(np.linspace(BED_T_CMAP_FROM, 1.0, 256)), name="inferno_bed")


def colour_limits(
    v: np.ndarray, lo: float | None = None, hi: float | None = None
) -> tuple[float, float]:
    """Colour limits spanning the finite values and the anchors; never degenerate."""
    f = v[np.isfinite(v)]
    vals = [float(f.min()), float(f.max())] if f.size else []
    vals += [a for a in (lo, hi) if a is not None]
    if not vals:
        return 0.0, 1.0
    vmin, vmax = min(vals), max(vals)
    if not vmax > vmin:  # uniform field: Normalize would divide by zero
        vmin, vmax = vmin - (0.0 if lo is not None else 1.0), vmax + 1.0
    return vmin, vmax


def frame_time_label(t_s: float) -> str:
    """A frame's title: the time in us below 1 ms (the paper's pulses), then ms, then s (a
    layer time of seconds reads "t = 10 s", not in millions of us)."""
    if t_s < 1e-3:
        return f"t = {t_s * 1e6:.1f} us"
    if t_s < 1.0:
        return f"t = {t_s * 1e3:.4g} ms"
    return f"t = {t_s:.4g} s"


def save_png(fig: Figure, path: Path, dpi: int) -> None:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    atomic_write_bytes(path, buf.getvalue())


def checked_domain(domain_um: tuple[float, ...]) -> tuple[float, float, float, float]:
    """The frames' (xmin, xmax, ymin, ymax) in um as floats; an empty range is an error."""
    xmin, xmax, ymin, ymax = (float(v) for v in domain_um)
    if not (xmax > xmin and ymax > ymin):
        raise ValueError(f"domain_um={domain_um!r} must be (xmin, xmax, ymin, ymax), min<max")
    return xmin, xmax, ymin, ymax


def remove_artist(artist: Any) -> None:
    """Take last frame's artist (an outline, a mesh) off its axes, if there is one."""
    if artist is not None:
        with contextlib.suppress(Exception):
            artist.remove()


def blank_image(
    ax: Axes, cmap: Colormap, shape: tuple[int, int], extent: tuple[float, ...]
) -> AxesImage:
    """An image panel's artist, empty until the first frame sets its data."""
    return ax.imshow(
        np.ma.masked_all(shape),
        cmap=cmap,
        origin="lower",
        extent=extent,
        interpolation="nearest",  # one raster pixel per image pixel already
    )


def section_axes(
    ax: Axes, domain_um: tuple[float, ...], title: str, fontsize: float, xlabel: bool = True
) -> None:
    """An image panel's axes: the frames' x-y range at equal aspect, in um, and its title."""
    xmin, xmax, ymin, ymax = domain_um
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal", adjustable="box")
    if xlabel:
        ax.set_xlabel("x [um]")
    ax.set_ylabel("y [um]")
    ax.set_title(title, fontsize=fontsize)


def melt_outline(
    ax: Axes, xs: np.ndarray, ys: np.ndarray, material: np.ndarray, liquid: np.ndarray
) -> QuadContourSet | None:
    """The melt outline (liquid fraction MELT_LEVEL, cyan) on an image of pixel centres ``xs``,
    ``ys``, the void counting as solid: the outline closes along the free surface and, like the
    material, has no gap along a mid-plane strip. None where nothing is molten."""
    melt = np.where(material, np.nan_to_num(liquid, nan=0.0), 0.0)
    if not (melt > MELT_LEVEL).any():
        return None
    try:
        return ax.contour(xs, ys, melt, levels=[MELT_LEVEL], colors="cyan", linewidths=1.0)
    except Exception:  # noqa: BLE001 -- the outline is decoration; never lose a frame
        return None
