"""The packing fraction of a bed of spheres, two ways, as packing.py gives it for discs.

envelope: the spheres' volume over the volume under the bed's top surface (at each (x, z) the
highest sphere top) over the x-z range: the layer as a laser sees it, rough top and wall layers
included. bulk: the spheres' volume inside a core window BULK_MARGIN mean diameters clear of
the plate, of the mean top height and of the side walls (a periodic bed has none: the window
spans the whole period in x and z), over the window's volume: the interior, which published
random-packing values describe.
"""

from __future__ import annotations

import numpy as np

from .packing import BULK_MARGIN

_SLICES = 64  # y slices per sphere cut by a side of the window (midpoint rule in the angle)
_CHORDS = 128  # chords per slice (midpoint rule in the chord angle)
_TOP_SAMPLES = 200  # top-surface samples per side of the x-z range, at least


def slab_volume(y: np.ndarray, r: np.ndarray, y0: float, y1: float) -> np.ndarray:
    """Volume of each sphere (centre height y, radius r) between the planes y0 < y1: exact."""

    def below(s: np.ndarray) -> np.ndarray:  # volume of the sphere under y = its centre + s
        s = np.clip(s, -r, r)
        return np.pi * (r * r * s - s**3 / 3.0 + 2.0 * r**3 / 3.0)

    return below(y1 - y) - below(y0 - y)


def volume_in_box(
    c: np.ndarray, r: np.ndarray, xw: tuple[float, float], yw: tuple[float, float], zw
) -> float:
    """Volume of the spheres (centres c, (n, 3)) inside the box xw x yw x zw: exact (slab) for
    a sphere inside the window's sides, slices of discs in the x-z rectangle for one cut by
    them (the chord rule of packing.area_in_window)."""
    c, r = np.asarray(c, float), np.asarray(r, float)
    x, y, z = c.T
    inside = (x - r >= xw[0]) & (x + r <= xw[1]) & (z - r >= zw[0]) & (z + r <= zw[1])
    apart = (x + r <= xw[0]) | (x - r >= xw[1]) | (z + r <= zw[0]) | (z - r >= zw[1])
    total = float(np.sum(slab_volume(y[inside], r[inside], *yw)))
    cut = ~inside & ~apart
    u = (np.arange(_SLICES) + 0.5) / _SLICES  # y = y_c + r sin t, t over [ta, tb]
    for xc, yc, zc, rc in zip(x[cut], y[cut], z[cut], r[cut], strict=True):
        ta, tb = np.arcsin(np.clip((np.array(yw) - yc) / rc, -1.0, 1.0))
        t = ta + (tb - ta) * u
        rs = rc * np.cos(t)  # the slices' radii
        total += float(np.sum(_disc_areas(xc, zc, rs, xw, zw) * rs * (tb - ta) / _SLICES))
    return total


def _disc_areas(x: float, z: float, rs: np.ndarray, xw, zw) -> np.ndarray:
    """Area of each disc (centre x, z; radii rs) inside the rectangle xw x zw: its chord
    inside integrated over x = x_c + r sin s (midpoint rule, as packing.area_in_window)."""
    rs = rs[:, None]
    sa = np.arcsin(np.clip((xw[0] - x) / rs, -1.0, 1.0))
    sb = np.arcsin(np.clip((xw[1] - x) / rs, -1.0, 1.0))
    s = sa + (sb - sa) * (np.arange(_CHORDS) + 0.5) / _CHORDS
    half = rs * np.cos(s)
    chord = np.clip(np.minimum(z + half, zw[1]) - np.maximum(z - half, zw[0]), 0.0, None)
    return np.sum(chord * rs * np.cos(s) * (sb - sa) / _CHORDS, axis=1)


def top_surface(
    c: np.ndarray, r: np.ndarray, x_range, z_range, periodic: bool
) -> tuple[np.ndarray, float]:
    """The highest sphere top on a grid of cell centres over the x-z range (0 where none lies),
    and the grid's cell area."""
    (x0, x1), (z0, z1) = x_range, z_range
    n = max(_TOP_SAMPLES, int(8 * max(x1 - x0, z1 - z0) / float(np.min(r))))
    hx, hz = (x1 - x0) / n, (z1 - z0) / n
    top = np.zeros((n, n))
    for (x, y, z), rr in zip(c, r, strict=True):
        i = np.arange(int(np.floor((x - rr - x0) / hx)), int(np.ceil((x + rr - x0) / hx)) + 1)
        k = np.arange(int(np.floor((z - rr - z0) / hz)), int(np.ceil((z + rr - z0) / hz)) + 1)
        if periodic:
            i, k = np.unique(i % n), np.unique(k % n)
        else:
            i, k = i[(i >= 0) & (i < n)], k[(k >= 0) & (k < n)]
        dx = x0 + (i + 0.5) * hx - x
        dz = z0 + (k + 0.5) * hz - z
        if periodic:
            dx -= (x1 - x0) * np.round(dx / (x1 - x0))
            dz -= (z1 - z0) * np.round(dz / (z1 - z0))
        h2 = rr * rr - dx[:, None] ** 2 - dz[None, :] ** 2
        cap = np.where(h2 > 0, y + np.sqrt(np.maximum(h2, 0.0)), 0.0)
        top[np.ix_(i, k)] = np.maximum(top[np.ix_(i, k)], cap)
    return top, hx * hz


def packing_fractions_3d(
    c: np.ndarray, r: np.ndarray, x_range, z_range, periodic: bool = False
) -> dict[str, float]:
    """envelope and bulk packing fractions of the spheres over x_range x z_range (side walls
    at its ends, or periodic), the mean top height, and the core window's y extent."""
    c, r = np.asarray(c, float).reshape(-1, 3), np.asarray(r, float)
    top, cell = top_surface(c, r, x_range, z_range, periodic)
    area = (x_range[1] - x_range[0]) * (z_range[1] - z_range[0])
    mean_top = float(top.sum() * cell / area)
    volume = float(np.sum(4.0 / 3.0 * np.pi * r**3))
    envelope = volume / float(top.sum() * cell)
    m = BULK_MARGIN * 2.0 * float(np.mean(r))
    yw = (m, mean_top - m)
    side = 0.0 if periodic else m
    xw = (x_range[0] + side, x_range[1] - side)
    zw = (z_range[0] + side, z_range[1] - side)
    bulk = np.nan
    if yw[1] > yw[0] and xw[1] > xw[0] and zw[1] > zw[0]:
        box = (xw[1] - xw[0]) * (yw[1] - yw[0]) * (zw[1] - zw[0])
        if periodic:  # the window spans whole periods: every sphere counts by its slab
            inside = float(np.sum(slab_volume(c[:, 1], r, *yw)))
        else:
            inside = volume_in_box(c, r, xw, yw, zw)
        bulk = inside / box
    return {"envelope": envelope, "bulk": float(bulk), "mean_top": mean_top, "core_y": list(yw)}
