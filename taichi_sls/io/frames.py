"""The frame images of a 2D run: the material coloured by temperature (melt outlined) and by
deformation (io/painter.py: the interface; io/frame_panels.py: what the 3D frames share).

The points are drawn as the material they stand for, rasterised at screen resolution: each
point spreads its area and its field over a tent a few point spacings wide, and the pixels whose
area fraction reaches 1/2 are material (for a regular lattice the level falls half a spacing
beyond the last row, on the body's true outline). Squares drawn at each point instead show the
empty strip, about one point spacing wide, that two coalescing bodies keep along their symmetry
line (no point crosses it) as a column of white dashes that reads as a crack.

Plotting is headless (Agg) and reuses one figure across frames so memory stays flat over
hundreds of frames; the axes box is fixed so that the raster is the same in every frame."""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")  # headless: the solver runs on machines without a display

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from scipy.ndimage import correlate1d

from .frame_panels import (
    blank_image,
    checked_domain,
    colour_limits,
    frame_time_label,
    melt_outline,
    remove_artist,
    save_png,
    section_axes,
    temperature_cmap,
)

MATERIAL_LEVEL = 0.5  # area fraction drawn as material: the outline of a regular lattice
# Half-width of the tent that spreads a point, in point spacings. At 3 the strip of a coalescing
# pair (its points 2 spacings apart across it) reads 2/3 and is filled, a gap of 3 spacings
# (0.44) stays open, and a flat free surface keeps its level 1/2 half a spacing out.
FOOTPRINT_SPACINGS = 3.0
MIN_MARKER_PT2 = 0.5  # a stray point's marker never shrinks below visibility
_MAX_RASTER_PIXELS = 1200  # per axis; bounds the raster at a high dpi
DEFORM_LABELS = {
    "displacement": ("|u| [um]", "displacement"),
    "plastic_strain": ("equivalent plastic strain", "plastic strain"),
}


def point_spacing(x: np.ndarray, fallback: float) -> float:
    """Typical particle spacing sqrt(area per point), from a sample of local point densities.

    Counting neighbours within a few nearest-neighbour distances (rather than using the
    nearest-neighbour distance itself) also covers anisotropic or jittered arrangements.
    """
    n = len(x)
    if n < 2:
        return fallback
    rng = np.random.default_rng(0)  # fixed seed: marker size must not flicker between frames
    sample = x if n <= 64 else x[rng.choice(n, 64, replace=False)]

    def dist2() -> Iterator[np.ndarray]:  # in chunks so memory stays O(16 N), not O(64 N)
        for i in range(0, len(sample), 16):
            yield ((sample[i : i + 16, None, :] - x[None]) ** 2).sum(axis=-1)

    # zero distance = self or an exact duplicate
    nn2 = np.concatenate([np.where(d2 > 0.0, d2, np.inf).min(axis=1) for d2 in dist2()])
    nn2 = nn2[np.isfinite(nn2)]
    if nn2.size == 0:
        return fallback
    r2 = 9.0 * float(np.median(nn2))
    counts = np.concatenate([(d2 <= r2).sum(axis=1) for d2 in dist2()])
    # Upper quantile of counts: points near a free surface see only half a neighbourhood.
    count = float(np.quantile(counts, 0.75))
    h = math.sqrt(math.pi * r2 / count)
    return h if h > 0.0 else fallback


def material_raster(
    x: np.ndarray,
    values: list[np.ndarray],
    spacing: float,
    lo: tuple[float, float],
    shape: tuple[int, int],
    pixel: float,
) -> tuple[np.ndarray, list[np.ndarray]]:
    """The points as material on a raster of ``shape`` (ny, nx) pixels of side ``pixel`` from
    corner ``lo``: the area fraction (points of area ``spacing``^2 spread over a tent of
    half-width FOOTPRINT_SPACINGS spacings) and each of ``values`` as the area-weighted mean of
    the points nearby (NaN where none has a finite value)."""
    ny, nx = shape
    on, ij = _pixels(x, lo, pixel, shape)
    flat = ij[on, 1] * nx + ij[on, 0]
    # a footprint beyond a tenth of the frame is the spacing of a blown-up state (points flung
    # apart): capped, the frame still draws in its usual time
    reach = FOOTPRINT_SPACINGS * spacing
    half = int(reach / pixel)
    if half > max(nx, ny) // 10:
        half = max(nx, ny) // 10
        reach = (half + 1) * pixel
    taps = 1.0 - np.abs(np.arange(-half, half + 1)) * pixel / reach
    taps /= taps.sum()  # discrete normalisation: a uniform lattice reads exactly 1

    def spread(weights: np.ndarray) -> np.ndarray:
        binned = np.bincount(flat, weights=weights, minlength=nx * ny).astype(float)  # int if empty
        binned = binned.reshape(ny, nx)
        return correlate1d(
            correlate1d(binned, taps, axis=0, mode="constant"), taps, axis=1, mode="constant"
        )

    area = spacing * spacing
    fraction = spread(np.full(flat.size, area)) / (pixel * pixel)
    out = []
    for v in values:
        v = np.asarray(v, dtype=float)[on]
        good = np.isfinite(v)
        num = spread(np.where(good, v * area, 0.0))
        den = spread(np.where(good, area, 0.0))
        out.append(np.divide(num, den, out=np.full_like(num, np.nan), where=den > 0.0))
    return fraction, out


def _on_material(
    x: np.ndarray, material: np.ndarray, lo: tuple[float, float], pixel: float
) -> np.ndarray:
    """Which points lie on a material pixel (non-finite points and those off the raster: no)."""
    on, ij = _pixels(x, lo, pixel, material.shape)
    out = np.zeros(len(x), dtype=bool)
    out[on] = material[ij[on, 1], ij[on, 0]]
    return out


def _pixels(
    x: np.ndarray, lo: tuple[float, float], pixel: float, shape: tuple[int, int]
) -> tuple[np.ndarray, np.ndarray]:
    """Each point's pixel (i, j) on a raster of ``shape`` (ny, nx) and whether it lies on it
    (a non-finite point, or one off the raster: no)."""
    ny, nx = shape
    with np.errstate(invalid="ignore", over="ignore"):
        cell = np.floor((x - np.asarray(lo)) / pixel)
    # compared as floats first: the cell of a point flung far by a blow-up fits no integer
    on = np.isfinite(cell).all(axis=1)
    on &= (cell[:, 0] >= 0) & (cell[:, 0] < nx) & (cell[:, 1] >= 0) & (cell[:, 1] < ny)
    ij = np.zeros((len(x), 2), dtype=np.int64)
    ij[on] = cell[on].astype(np.int64)
    return on, ij


# A scene wider than this (width / height: a powder layer) stacks its two panels, each across
# the whole frame, rather than squeezing them side by side into strips a few dozen pixels high.
STACK_ASPECT = 2.0
STACKED_WIDTH_IN = 13.0  # inches: 1040 px at the default dpi of 80
STACKED_PANEL_H_IN = (1.5, 5.0)  # a panel's axes height is clamped to this range (inches)


class Frame2DPainter:
    """Draws one 2D frame into a reused figure of two panels (temperature, deformation): side
    by side, or stacked for a scene wider than STACK_ASPECT (io/painter.FramePainter)."""

    dim = 2

    def __init__(
        self,
        domain_um: tuple[float, float, float, float],
        melt_C: float,
        deformation: str,
        dpi: int = 80,
        bed: bool = False,
    ) -> None:
        self.domain_um = checked_domain(domain_um)
        self.melt_C = float(melt_C)
        if deformation not in DEFORM_LABELS:
            raise ValueError(
                f"deformation={deformation!r}; allowed: {', '.join(sorted(DEFORM_LABELS))}"
            )
        self.deformation = deformation
        self.dpi = int(dpi)  # the raster's pixel is one pixel of the saved image
        self.bed = bed
        xmin, xmax, ymin, ymax = self.domain_um
        self.stacked = (xmax - xmin) > STACK_ASPECT * (ymax - ymin)
        self._fig: Figure | None = None

    def _layout(self) -> tuple[Figure, list[Axes], list[dict[str, Any]]]:
        """The figure, its two axes and each colour bar's placement (keywords of colorbar)."""
        xmin, xmax, ymin, ymax = self.domain_um
        if not self.stacked:
            panel_w = 4.2  # inches; 2 panels + colour bars stay ~800 px wide at dpi 80
            panel_h = min(max(panel_w * (ymax - ymin) / (xmax - xmin), 1.5), 6.0)
            fig = Figure(figsize=(2 * panel_w + 1.4, panel_h + 1.0))
            # Fixed layout (not constrained) so the axes box -- and so the raster -- is known
            # before drawing and identical across frames.
            fig.subplots_adjust(left=0.06, right=0.93, bottom=0.14, top=0.86, wspace=0.38)
            axes = list(fig.subplots(1, 2))
            return fig, axes, [{"ax": ax, "fraction": 0.046, "pad": 0.03} for ax in axes]
        # stacked: absolute placements in inches, the axes as wide as the frame allows
        left, right, cbar_w, cbar_gap = 0.75, 1.25, 0.15, 0.15
        top, title, ticks, xlabel = 0.45, 0.3, 0.35, 0.25
        w = STACKED_WIDTH_IN
        aw = w - left - right
        lo, hi = STACKED_PANEL_H_IN
        ah = min(max(aw * (ymax - ymin) / (xmax - xmin), lo), hi)
        h = top + 2 * (title + ah + ticks) + xlabel
        fig = Figure(figsize=(w, h))
        axes, cbars = [], []
        for i in range(2):
            y0 = h - top - title - ah - i * (title + ah + ticks)
            ax = fig.add_axes((left / w, y0 / h, aw / w, ah / h))
            cax = fig.add_axes(((left + aw + cbar_gap) / w, y0 / h, cbar_w / w, ah / h))
            axes.append(ax)
            cbars.append({"cax": cax})
        return fig, axes, cbars

    def _setup_figure(self) -> None:
        xmin, xmax, ymin, ymax = self.domain_um
        fig, axes, cbar_places = self._layout()
        FigureCanvasAgg(fig)
        # Image pixels per micrometre under equal aspect: the tighter of the two directions.
        pos = axes[0].get_position()
        w_in, h_in = fig.get_figwidth() * pos.width, fig.get_figheight() * pos.height
        px_per_um = self.dpi * min(w_in / (xmax - xmin), h_in / (ymax - ymin))
        self._pt_per_um = px_per_um * 72.0 / self.dpi  # marker sizes are in points
        self._pixel = max(1.0 / px_per_um, max(xmax - xmin, ymax - ymin) / _MAX_RASTER_PIXELS)
        nx = max(1, math.ceil((xmax - xmin) / self._pixel))
        ny = max(1, math.ceil((ymax - ymin) / self._pixel))
        self._shape = (ny, nx)
        self._pixel_centres = (
            xmin + (np.arange(nx) + 0.5) * self._pixel,
            ymin + (np.arange(ny) + 0.5) * self._pixel,
        )
        extent = (xmin, xmin + nx * self._pixel, ymin, ymin + ny * self._pixel)
        cb_label, name = DEFORM_LABELS[self.deformation]
        self._images, self._strays, self._cbars = [], [], []
        for i, (ax, place, cmap, label, title) in enumerate(
            zip(
                axes,
                cbar_places,
                (temperature_cmap(self.bed), matplotlib.colormaps["viridis"]),
                ("T [C]", cb_label),
                ("temperature (cyan: melt)", name),
                strict=True,
            )
        ):
            im = blank_image(ax, cmap, self._shape, extent)
            self._cbars.append(fig.colorbar(im, label=label, **place))
            self._images.append(im)
            # points too isolated to make material (a lone point, one thrown off) stay visible
            self._strays.append(
                ax.scatter(np.zeros(0), np.zeros(0), c=np.zeros(0), cmap=cmap, marker="s", lw=0)
            )
            # stacked: the lower panel's x label serves both
            section_axes(ax, self.domain_um, title, 10, xlabel=not (self.stacked and i == 0))
        self._axes, self._contour, self._fig = axes, None, fig

    def paint(
        self, t_s: float, x: np.ndarray, fields: Mapping[str, np.ndarray], png: Path | None
    ) -> None:
        """The frame at ``t_s`` into ``png`` (if given); a 2D frame has no surface for the VTU."""
        if png is not None:
            self.draw(t_s, x, fields)
            save_png(self._fig, png, self.dpi)

    def draw(self, t_s: float, x: np.ndarray, fields: Mapping[str, np.ndarray]) -> None:
        if self._fig is None:
            self._setup_figure()
        fallback = (
            self.domain_um[1] - self.domain_um[0]
        ) / 100  # lone or coincident points: a small visible patch
        h = point_spacing(x[np.isfinite(x).all(axis=1)], fallback)
        T, d = fields["T_C"], fields["deform"]
        lf = np.nan_to_num(np.asarray(fields["liquid_fraction"], dtype=float), nan=0.0)
        fraction, (T_px, d_px, lf_px) = material_raster(
            x, [T, d, lf], h, (self.domain_um[0], self.domain_um[2]), self._shape, self._pixel
        )
        material = fraction >= MATERIAL_LEVEL
        # T range always includes melt_C and |u| starts at 0, so colours keep their meaning.
        limits = (colour_limits(T, hi=self.melt_C), colour_limits(d, lo=0.0))
        stray = ~_on_material(x, material, (self.domain_um[0], self.domain_um[2]), self._pixel)
        size = max((h * self._pt_per_um) ** 2, MIN_MARKER_PT2)  # the point's own footprint
        for im, sc, v, p, clim in zip(
            self._images, self._strays, (T_px, d_px), (T, d), limits, strict=True
        ):
            im.set_data(np.ma.masked_where(~(material & np.isfinite(v)), v))
            im.set_clim(*clim)
            sc.set_offsets(x[stray])
            sc.set_array(np.asarray(p, dtype=float)[stray])
            sc.set_sizes(np.array([size]))
            sc.set_clim(*clim)
        remove_artist(self._contour)
        self._contour = melt_outline(self._axes[0], *self._pixel_centres, material, lf_px)
        self._fig.suptitle(frame_time_label(t_s))

    def close(self) -> None:
        self._fig = None  # drop the figure; a later draw rebuilds it
