"""What a laser did to a powder layer as a whole: its relative density before and after, and the
depth and width of the melt track (docs/record/beds.md).

Relative density: the area where the raw colour c >= 1/2 (the material as the capillary force
and the necks see it) over the area of the layer's envelope, the region under its top profile
between the side walls (the bed's x range). The top profile is the highest crossing of c = 1/2
in each column, recomputed from the material on every call: a layer that shrinks as its pores
close has a lower envelope and so a higher density, which is what sintering does (a fixed
envelope would read the same density before and after, the material's area being conserved).
At the start it is the generator's envelope packing fraction (config/packing.py) read on the
grid, the fillet bridges included. In 3D the same in volumes: the material under the layer's
top surface over the bed's x and z ranges; one function reads both, the dimension the colour's.

Melt extent: from the points that were ever fully molten (``time_molten`` > 0), by their start
positions, so that it says which powder melted whatever the melt did afterwards: the depth is
the layer top (the highest body top as seeded: the laser's default y_l) less the lowest such
point's lower edge, the width the x-extent of those points, each point counted with its square
of one point spacing. The lowest molten material's height above the plate is given beside the
depth: on a rough layer the highest top lies well above the mean one.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..solver.neck_section import interpolate

if TYPE_CHECKING:
    from ..solver.simulation import Simulation

SAMPLES_PER_CELL = 4  # sampling of the colour for the areas: a quarter cell each way
_BLOCK = 2**20  # samples interpolated at once (a 3D layer is read a block of x at a time)


def relative_density(
    colour: np.ndarray,
    h: float,
    off: int,
    ranges_m: list[tuple[float, float]],
    height_m: float,
) -> dict[str, float]:
    """The relative density of the layer over the lateral ranges ``ranges_m`` (x in 2D; x and z
    in 3D; m) on the raw colour ``colour`` (nodes, index i at x = (i - off) h; its dimension is
    the layer's): the material's area (volume) over the area (volume) under the top profile
    (surface), with both and the mean top height (m). Midpoint sampling every
    h / SAMPLES_PER_CELL from the plate up to ``height_m``."""
    d = h / SAMPLES_PER_CELL
    counts = [max(1, round((hi - lo) / d)) for lo, hi in ranges_m]
    xs, *across = (
        lo + (np.arange(n) + 0.5) * (hi - lo) / n
        for (lo, hi), n in zip(ranges_m, counts, strict=True)
    )
    ys = (np.arange(max(1, round(height_m / d))) + 0.5) * d
    rows = np.arange(len(ys)).reshape(1, -1, *(1,) * len(across))
    block = max(1, _BLOCK // (len(ys) * math.prod(len(a) for a in across)))
    columns, material = 0, 0
    for i in range(0, len(xs), block):  # (x, y[, z]) samples, a block of x at a time
        grid = np.meshgrid(xs[i : i + block], ys, *across, indexing="ij")
        p = np.stack([grid[0], grid[1], *grid[2:]], axis=-1)
        solid = interpolate(colour, h, off, p, outside=0.0) >= 0.5
        # per column the index of the highest material sample, -1 where none: the top
        columns += int(np.sum(np.max(np.where(solid, rows, -1), axis=1) + 1))
        material += int(np.count_nonzero(solid))
    widths = [(hi - lo) / n for (lo, hi), n in zip(ranges_m, counts, strict=True)]
    envelope, solid_measure = _measure(columns, d, widths), _measure(material, d, widths)
    unit = "area_m2" if len(ranges_m) == 1 else "volume_m3"
    return {
        "relative_density": solid_measure / envelope if envelope > 0 else float("nan"),
        f"envelope_{unit}": envelope,
        f"material_{unit}": solid_measure,
        "mean_top_m": envelope / math.prod(hi - lo for lo, hi in ranges_m),
    }


def _measure(samples: int, d: float, widths: list[float]) -> float:
    """The area (volume) of ``samples`` sample cells of height d and these widths, multiplied
    in the order each dimension always has (the records hold the last bit)."""
    if len(widths) == 1:
        return float(samples * d * widths[0])
    return float(samples * (d * widths[0] * widths[1]))


def layer_density(sim: Simulation) -> dict[str, float]:
    """The layer's relative density now between the bed's side walls (the points' extents as
    seeded without a generated bed): over x, and z in 3D."""
    cfg = sim.state.cfg
    rep = sim.case.bed_report
    axes = (0,) if cfg.dim == 2 else (0, 2)
    if rep is not None:
        ranges = [tuple(v * 1e-6 for v in rep[f"{'xyz'[k]}_range_um"]) for k in axes]
    else:  # bodies listed one by one: the extent of the points as seeded
        x0 = sim.scene.x
        half = 0.5 * cfg.h / sim.case.grid.points_per_cell
        ranges = [(float(x0[:, k].min()) - half, float(x0[:, k].max()) + half) for k in axes]
    return relative_density(
        sim.necks.raw_colour(), cfg.h, cfg.off, ranges, sim.case.domain.height_um * 1e-6
    )


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
