"""The packing fraction of a bed of discs, two ways (docs/record/beds.md).

envelope: the discs' area over the area under the bed's top profile (at each x the highest disc
top, 0 where no disc lies) between the side walls: the fraction of the layer as a laser sees it,
its rough top and wall layers included. bulk: the discs' area inside a window that stays
BULK_MARGIN mean diameters away from the side walls and the plate and below the mean top
height, over the window's area: the interior, free of the ordering that a wall or the plate
imposes and of the open top, which is what published random-packing values describe.
"""

from __future__ import annotations

import numpy as np

BULK_MARGIN = 2.0  # mean diameters kept clear of the walls, the plate and the mean top
_SAMPLES = 256  # quadrature points per disc (midpoint rule in the chord angle: smooth)


def top_profile(x: np.ndarray, y: np.ndarray, r: np.ndarray, xs: np.ndarray) -> np.ndarray:
    """At each of the sorted abscissae xs, the highest disc top (0 where no disc lies)."""
    top = np.zeros(len(xs))
    for cx, cy, cr in zip(x, y, r, strict=True):
        i0, i1 = np.searchsorted(xs, [cx - cr, cx + cr])
        u = xs[i0:i1] - cx
        top[i0:i1] = np.maximum(top[i0:i1], cy + np.sqrt(np.maximum(cr * cr - u * u, 0.0)))
    return top


def area_in_window(
    x: np.ndarray, y: np.ndarray, r: np.ndarray, xw: tuple[float, float], yw: tuple[float, float]
) -> float:
    """Total area of the discs inside the rectangle xw x yw: for each disc the chord length
    inside the window integrated over x = cx + r sin t (midpoint rule in t)."""
    x, y, r = (np.asarray(a, float)[:, None] for a in (x, y, r))
    ta = np.arcsin(np.clip((xw[0] - x) / r, -1.0, 1.0))
    tb = np.arcsin(np.clip((xw[1] - x) / r, -1.0, 1.0))
    u = (np.arange(_SAMPLES) + 0.5) / _SAMPLES
    t = ta + (tb - ta) * u
    half = r * np.cos(t)
    chord = np.clip(np.minimum(y + half, yw[1]) - np.maximum(y - half, yw[0]), 0.0, None)
    return float(np.sum(chord * r * np.cos(t) * (tb - ta) / _SAMPLES))


def packing_fractions(
    x: np.ndarray, y: np.ndarray, r: np.ndarray, x_range: tuple[float, float]
) -> dict[str, float]:
    """envelope and bulk packing fractions of the discs between side walls at x_range (bulk is
    NaN where the bed is too small for its window), with the mean top height."""
    x, y, r = (np.asarray(a, float) for a in (x, y, r))
    lo, hi = x_range
    xs = np.linspace(lo, hi, max(4001, int(200 * (hi - lo) / r.min())))
    top = top_profile(x, y, r, xs)
    mean_top = float(np.trapezoid(top, xs) / (hi - lo))
    envelope = float(np.sum(np.pi * r**2) / np.trapezoid(top, xs))
    m = BULK_MARGIN * 2.0 * float(np.mean(r))
    xw, yw = (lo + m, hi - m), (m, mean_top - m)
    bulk = np.nan
    if xw[1] > xw[0] and yw[1] > yw[0]:
        bulk = area_in_window(x, y, r, xw, yw) / ((xw[1] - xw[0]) * (yw[1] - yw[0]))
    return {"envelope": envelope, "bulk": float(bulk), "mean_top": mean_top}
