"""The packing fraction of a bed, two ways (docs/record/beds.md), of discs (2D) or spheres (3D): the
dimension is the centres' (``c``, (n, dim)).

envelope: the particles' area (volume) over the area (volume) under the bed's top profile (at
each x, or (x, z), the highest particle top, 0 where none lies) between the side walls: the
fraction of the layer as a laser sees it, its rough top and wall layers included. bulk: the
particles' area (volume) inside a window that stays BULK_MARGIN mean diameters away from the
side walls (a periodic 3D bed has none: the window spans the whole period in x and z), the
plate and the mean top height, over the window's: the interior, free of the ordering that a
wall or the plate imposes and of the open top, which is what published random-packing values
describe. The top and the content of the window are the two things that differ with the
dimension (a profile and a surface; chords of discs and slices of spheres).
"""

from __future__ import annotations

import math

import numpy as np

BULK_MARGIN = 2.0  # mean diameters kept clear of the walls, the plate and the mean top
_SAMPLES = 256  # quadrature points per disc (midpoint rule in the chord angle: smooth)
_SLICES = 64  # y slices per sphere cut by a side of the window (midpoint rule in the angle)
_CHORDS = 128  # chords per slice (midpoint rule in the chord angle)
_TOP_SAMPLES = 200  # top-surface samples per side of the x-z range, at least


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


def packing_fractions(
    c: np.ndarray,
    r: np.ndarray,
    ranges: list[tuple[float, float]],
    periodic: bool = False,
) -> dict[str, float]:
    """envelope and bulk packing fractions of the particles (centres c, (n, dim); radii r)
    between side walls at the ends of ``ranges`` (x in 2D; x and z in 3D; periodic: 3D only,
    no walls), with the mean top height; in 3D also the core window's y extent ``core_y``.
    bulk is NaN where the bed is too small for its window."""
    c, r = np.asarray(c, float), np.asarray(r, float)
    dim = c.shape[1]
    if periodic and dim == 2:
        raise ValueError("a periodic packing is 3D only")
    if dim == 2:
        ((lo, hi),) = ranges
        xs = np.linspace(lo, hi, max(4001, int(200 * (hi - lo) / r.min())))
        under = np.trapezoid(top_profile(c[:, 0], c[:, 1], r, xs), xs)
        content = float(np.sum(np.pi * r**2))
    else:
        top, cell = top_surface(c, r, ranges[0], ranges[1], periodic)
        under = top.sum() * cell
        content = float(np.sum(4.0 / 3.0 * np.pi * r**3))
    mean_top = float(under / math.prod(hi - lo for lo, hi in ranges))
    m = BULK_MARGIN * 2.0 * float(np.mean(r))
    yw = (m, mean_top - m)
    side = 0.0 if periodic else m
    lateral = [(lo + side, hi - side) for lo, hi in ranges]
    windows = [lateral[0], yw, *lateral[1:]]  # x, y (, z)
    bulk = np.nan
    if all(w[1] > w[0] for w in windows):
        box = math.prod(w[1] - w[0] for w in windows)
        bulk = _content_in_window(c, r, windows, periodic) / box
    out = {"envelope": content / float(under), "bulk": float(bulk), "mean_top": mean_top}
    return out if dim == 2 else {**out, "core_y": list(yw)}


def _content_in_window(c: np.ndarray, r: np.ndarray, windows: list, periodic: bool) -> float:
    """The particles' area (volume) inside the window (one (lo, hi) per axis)."""
    if len(windows) == 2:
        return area_in_window(c[:, 0], c[:, 1], r, *windows)
    if periodic:  # the window spans whole periods: every sphere counts by its slab
        return float(np.sum(slab_volume(c[:, 1], r, *windows[1])))
    return volume_in_box(c, r, *windows)
