"""What a laser did to a powder layer as a whole: its relative density before and after, and the
depth and width of the melt track (docs/record/beds.md).

Relative density: the area where the raw colour c >= 1/2 (the material as the capillary force
and the necks see it) over the area of the layer's envelope, the region under its top profile
between the side walls (the bed's x range). The top profile is the highest crossing of c = 1/2
in each column, recomputed from the material on every call: a layer that shrinks as its pores
close has a lower envelope and so a higher density, which is what sintering does (a fixed
envelope would read the same density before and after, the material's area being conserved).
At the start it is the generator's envelope packing fraction (config/packing.py) read on the
grid, the fillet bridges included.

Melt extent: from the points that were ever fully molten (``time_molten`` > 0), by their start
positions, so that it says which powder melted whatever the melt did afterwards: the depth is
the layer top (the highest body top as seeded: the laser's default y_l) less the lowest such
point's lower edge, the width the x-extent of those points, each point counted with its square
of one point spacing. The lowest molten material's height above the plate is given beside the
depth: on a rough layer the highest top lies well above the mean one.
"""

from __future__ import annotations

import numpy as np

from ..solver.contacts import bilinear
from ..solver.section3d import trilinear

SAMPLES_PER_CELL = 4  # sampling of the colour for the areas: a quarter cell each way


def relative_density(
    colour: np.ndarray, h: float, off: int, x_range_m: tuple[float, float], height_m: float
) -> dict[str, float]:
    """The relative density of the layer between x_range_m on the raw colour ``colour``
    (nodes, index i at x = (i - off) h; m), with the envelope's area and mean top height (m).
    Midpoint sampling every h / SAMPLES_PER_CELL from the plate up to ``height_m``."""
    d = h / SAMPLES_PER_CELL
    x0, x1 = x_range_m
    nx = max(1, round((x1 - x0) / d))
    xs = x0 + (np.arange(nx) + 0.5) * (x1 - x0) / nx
    ys = (np.arange(max(1, round(height_m / d))) + 0.5) * d
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    solid = bilinear(colour, h, off, X, Y, outside=0.0) >= 0.5
    # per column the index of the highest material sample, -1 where none: the top profile
    rows = np.arange(len(ys))[None, :]
    top_idx = np.max(np.where(solid, rows, -1), axis=1)
    dx = (x1 - x0) / nx
    envelope = float(np.sum(top_idx + 1) * d * dx)
    material = float(np.count_nonzero(solid) * d * dx)
    return {
        "relative_density": material / envelope if envelope > 0 else float("nan"),
        "envelope_area_m2": envelope,
        "material_area_m2": material,
        "mean_top_m": envelope / (x1 - x0),
    }


def relative_density_3d(
    colour: np.ndarray,
    h: float,
    off: int,
    x_range_m: tuple[float, float],
    z_range_m: tuple[float, float],
    height_m: float,
) -> dict[str, float]:
    """:func:`relative_density` of a 3D layer over x_range_m x z_range_m (m): the material's
    volume over the volume under the top surface, and the surface's mean height (m)."""
    d = h / SAMPLES_PER_CELL
    (x0, x1), (z0, z1) = x_range_m, z_range_m
    nx, nz = max(1, round((x1 - x0) / d)), max(1, round((z1 - z0) / d))
    xs = x0 + (np.arange(nx) + 0.5) * (x1 - x0) / nx
    zs = z0 + (np.arange(nz) + 0.5) * (z1 - z0) / nz
    ys = (np.arange(max(1, round(height_m / d))) + 0.5) * d
    Y, Z = np.meshgrid(ys, zs, indexing="ij")
    rows = np.arange(len(ys))[:, None]
    columns, material = 0, 0
    for x in xs:  # one x-slice at a time: (y, z) samples
        p = np.stack([np.full_like(Y, x), Y, Z], axis=-1)
        solid = trilinear(colour, h, off, p, outside=0.0) >= 0.5
        columns += int(np.sum(np.max(np.where(solid, rows, -1), axis=0) + 1))
        material += int(np.count_nonzero(solid))
    cell = d * ((x1 - x0) / nx) * ((z1 - z0) / nz)
    envelope = columns * cell
    return {
        "relative_density": material * cell / envelope if envelope > 0 else float("nan"),
        "envelope_volume_m3": envelope,
        "material_volume_m3": material * cell,
        "mean_top_m": envelope / ((x1 - x0) * (z1 - z0)),
    }


def melt_extent(
    x0: np.ndarray,
    time_molten: np.ndarray,
    top_m: float,
    spacing_m: float,
    across_axis: int = 0,
) -> dict[str, float]:
    """Depth below ``top_m``, lowest height and width (m) of the points ever fully molten, by
    their start positions x0 (m), each with its square (cube) of side ``spacing_m``; the width
    is their extent along ``across_axis`` (x in 2D; 3D: the bed axis across the scan); depth
    and width 0 (bottom NaN) when none melted."""
    molten = time_molten > 0.0
    if not molten.any():
        return {
            "melt_depth_m": 0.0,
            "melt_bottom_m": float("nan"),
            "track_width_m": 0.0,
            "molten_points": 0,
        }
    x = x0[molten]
    bottom = float(x[:, 1].min() - 0.5 * spacing_m)
    return {
        "melt_depth_m": float(top_m - bottom),
        "melt_bottom_m": bottom,
        "track_width_m": float(x[:, across_axis].max() - x[:, across_axis].min() + spacing_m),
        "molten_points": int(molten.sum()),
    }
