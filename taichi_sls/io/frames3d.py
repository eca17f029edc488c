"""Frame images of a 3D run, drawn on the CPU with matplotlib alone (no GPU, no PyVista):

1. the temperature on a section through the material (the x-y plane at ``section_z_um``: the
   laser's track if it scans along x, else the mid-depth, across the tracks of a scan along z;
   y up as in the 2D frames), the melt outlined (liquid fraction 1/2, cyan);
2. the liquid fraction on the same section;
3. the material's surface (colour c = 1/2, io/surface3d.py) in an orthographic view over the
   box's edges (io/surface_image.py), coloured by the temperature and lit by one distant light
   (Lambert: the colour times 0.3 + 0.7 cos of the angle between the surface's normal and the
   light), with a scale bar.

The section and the surface are read off one colour grid of the point spacing
(io/surface3d.colour_grid), so the section's material and the surface agree. One figure is
reused across frames (headless Agg); only the artists change. outcome.png of a 3D run draws
the points seeded in the lattice layer at that section (:func:`section_layer`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from scipy.ndimage import zoom

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
from .surface3d import SURFACE_LEVEL, ColourGrid, Surface, colour_grid, surface
from .surface_image import OrthographicView, Projection, box_edges, draw_surface, fit_box

# the light: from above (y), in front (-z: the viewer's side) and to the left (-x)
LIGHT = np.array([-0.4, 1.0, -0.6]) / np.linalg.norm([-0.4, 1.0, -0.6])
AMBIENT = 0.3  # the light a face turned away from the light still gets
# the camera of the surface panel, over the plot's axes (x, z, y): the solver's y up
VIEW = OrthographicView(elev_deg=25.0, azim_deg=-60.0)
PLOT_AXES = [0, 2, 1]  # the solver's (x, y, z) shown as the plot's (x, z, y)
SECTION_REFINE = 4  # section pixels per colour-grid node spacing
PANEL_W_IN = 3.6  # inches per panel: three panels and colour bars ~ 950 px at dpi 80


@dataclass(frozen=True)
class View3D:
    """What a 3D frame needs beyond the 2D one: the box's z range (um), the seeding's point
    spacing (um; the colour grid's spacing) and the section's z (um)."""

    z_range_um: tuple[float, float]
    point_spacing_um: float
    section_z_um: float


def view_3d(case: Any) -> View3D:
    """The 3D frame of ``case``: the box with its ghost layer in z as in x, the seeding's point
    spacing, the section at the first laser's track if it scans along x, else at mid-depth."""
    g = case.grid
    ghost = g.ghost_cells * g.spacing_um
    depth = case.domain.depth()
    along_x = [las for las in case.lasers if las.direction == "x"]
    z = along_x[0].z_start_um if along_x else 0.5 * depth
    return View3D((-ghost, depth + ghost), g.spacing_um / g.points_per_cell, float(z))


def section_layer(
    case: Any, x_initial: np.ndarray, x_final: np.ndarray, body: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """outcome.png of a 3D run (io/outcome_plot.py draws points in a plane): the points seeded
    in the lattice layer nearest the frames' section (z of :func:`view_3d`), their x and y at
    the start and the end, and their bodies. A 2D run's points as they are."""
    if case.domain.dim == 2:
        return x_initial, x_final, body
    v = view_3d(case)
    a = v.point_spacing_um * 1e-6
    z = (np.round(v.section_z_um * 1e-6 / a - 0.5) + 0.5) * a  # the layer's seeded z
    layer = np.abs(x_initial[:, 2] - z) < 0.25 * a
    return x_initial[layer, :2], x_final[layer, :2], body[layer]


def section(
    grid: ColourGrid, z_um: float
) -> tuple[np.ndarray, list[np.ndarray], np.ndarray, np.ndarray]:
    """The colour and the sums of T_C and liquid_fraction on the grid's node plane nearest
    ``z_um``, as images (rows y), refined SECTION_REFINE times by linear interpolation (the
    material's outline then follows the colour's level, not the nodes' squares); with the
    pixel centres' x and y (um)."""
    k = int(round((z_um - grid.lo[2]) / grid.spacing))
    k = min(max(k, 0), grid.c.shape[2] - 1)
    planes = [grid.c[:, :, k].T] + [grid.sums[n][:, :, k].T for n in ("T_C", "liquid_fraction")]
    fine = [zoom(p, SECTION_REFINE, order=1, grid_mode=False) for p in planes]
    ny, nx = planes[0].shape
    xs = np.linspace(grid.lo[0], grid.lo[0] + (nx - 1) * grid.spacing, fine[0].shape[1])
    ys = np.linspace(grid.lo[1], grid.lo[1] + (ny - 1) * grid.spacing, fine[0].shape[0])
    return fine[0], fine[1:], xs, ys


def shade(normals: np.ndarray) -> np.ndarray:
    """Lambert's factor of unit normals (T, 3) in the solver's axes: AMBIENT .. 1."""
    return AMBIENT + (1.0 - AMBIENT) * np.clip(normals @ LIGHT, 0.0, None)


class Frame3DPainter:
    """Draws one 3D frame (section of T, section of the liquid fraction, lit surface) into a
    reused figure (io/painter.FramePainter)."""

    dim = 3

    def __init__(
        self,
        domain_um: tuple[float, float, float, float],
        view: View3D,
        melt_C: float,
        bed: bool = False,
        dpi: int = 80,
    ) -> None:
        self.domain_um = checked_domain(domain_um)
        self.view = view
        self.melt_C = float(melt_C)
        self.cmap = temperature_cmap(bed)
        self.dpi = int(dpi)
        self._fig: Figure | None = None

    def paint(
        self, t_s: float, x: np.ndarray, fields: Mapping[str, np.ndarray], png: Path | None
    ) -> Surface:
        """The frame at ``t_s`` into ``png`` (if given); the colour grid and its surface are
        computed once, for the picture and for the VTU (the surface returned)."""
        xmin, xmax, ymin, ymax = self.domain_um
        read = {k: fields[k] for k in ("T_C", "liquid_fraction")}
        box = ((xmin, xmax), (ymin, ymax), self.view.z_range_um)
        grid = colour_grid(x, read, self.view.point_spacing_um, box)
        surf = surface(grid)
        if png is not None:
            self.draw(t_s, grid, surf, fields["T_C"])
            save_png(self._fig, png, self.dpi)
        return surf

    def _setup(self) -> None:
        xmin, xmax, ymin, ymax = self.domain_um
        zmin, zmax = self.view.z_range_um
        h_in = min(max(PANEL_W_IN * (ymax - ymin) / (xmax - xmin), 1.5), 5.0) + 1.2
        fig = Figure(figsize=(3.4 * PANEL_W_IN + 1.6, h_in))
        FigureCanvasAgg(fig)
        fig.subplots_adjust(left=0.05, right=0.98, bottom=0.12, top=0.84, wspace=0.4)
        gs = fig.add_gridspec(1, 3, width_ratios=(1.0, 1.0, 1.4))
        ax_t = fig.add_subplot(gs[0])
        ax_l = fig.add_subplot(gs[1])
        ax_s = fig.add_subplot(gs[2])
        z = self.view.section_z_um
        self._images = []
        for ax, cmap, label, title in (
            (ax_t, self.cmap, "T [C]", f"temperature at z = {z:.0f} um (cyan: melt)"),
            (ax_l, matplotlib.colormaps["Blues"], "liquid fraction", "liquid fraction"),
        ):
            im = blank_image(ax, cmap, (2, 2), self.domain_um)
            fig.colorbar(im, ax=ax, label=label, fraction=0.046, pad=0.03)
            section_axes(ax, self.domain_um, title, 9)
            self._images.append(im)
        self._images[1].set_clim(0.0, 1.0)
        box = np.array([(xmin, xmax), (zmin, zmax), (ymin, ymax)])  # the plot's axes
        width_px = int(fig.get_figwidth() * ax_s.get_position().width * self.dpi)
        self._projection = fit_box(VIEW, box, max(width_px, 16))
        self._box_edges = box_edges(box)
        ax_s.set_axis_off()
        ax_s.set_title("surface, lit, by temperature", fontsize=9)
        self._surface_image = ax_s.imshow(
            np.zeros((*self._projection.size[::-1], 4)), interpolation="nearest"
        )
        scale_bar(ax_s, self._projection, xmax - xmin)
        self._ax_t, self._ax_s = ax_t, ax_s
        self._contour = None
        self._fig = fig

    def draw(self, t_s: float, grid: ColourGrid, surf: Surface, T_points: np.ndarray) -> None:
        """Frame at ``t_s`` from the colour ``grid`` (sums of T_C and liquid_fraction), its
        surface ``surf`` and the points' temperatures (the colour limits)."""
        if self._fig is None:
            self._setup()
        c, sums, xs, ys = section(grid, self.view.section_z_um)
        material = c >= SURFACE_LEVEL
        T, lf = (np.divide(v, c, out=np.full_like(c, np.nan), where=c > 0.0) for v in sums)
        dx, dy = xs[1] - xs[0], ys[1] - ys[0]
        extent = (xs[0] - dx / 2, xs[-1] + dx / 2, ys[0] - dy / 2, ys[-1] + dy / 2)
        clim = colour_limits(np.asarray(T_points, dtype=float), hi=self.melt_C)
        for im, v in zip(self._images, (T, lf), strict=True):
            im.set_data(np.ma.masked_where(~(material & np.isfinite(v)), v))
            im.set_extent(extent)
        self._images[0].set_clim(*clim)
        remove_artist(self._contour)
        self._contour = melt_outline(self._ax_t, xs, ys, material, lf)
        colour = self.cmap(Normalize(*clim)(surf.values["T_C"][surf.tris].mean(axis=1)))
        normals = surf.normals()
        colour[:, :3] *= shade(normals)[:, None]
        image = draw_surface(
            self._projection,
            surf.verts[:, PLOT_AXES],
            surf.tris,
            normals[:, PLOT_AXES],
            colour,
            self._box_edges,
        )
        self._surface_image.set_data(image)
        self._fig.suptitle(frame_time_label(t_s))

    def close(self) -> None:
        self._fig = None


def scale_bar(ax: Any, proj: Projection, width_um: float) -> None:
    """A bar of a round length (1, 2 or 5 times a power of ten, about a fifth of the box's
    width) in the image's lower left, labelled in um."""
    target = 0.2 * width_um
    power = 10.0 ** np.floor(np.log10(target))
    length = max(m * power for m in (1.0, 2.0, 5.0) if m * power <= target)
    w, h = proj.size
    x0, y0 = 0.05 * w, 0.95 * h
    ax.plot([x0, x0 + length * proj.scale], [y0, y0], color="black", linewidth=2)
    ax.text(x0, y0 - 0.03 * h, f"{length:g} um", fontsize=7, va="bottom")
