"""The neck of a contact: the section of the material normal to the line of its two bodies'
centres, in 2D a line and in 3D a plane. The dimension is the centres' (``ca``, ``cb``).

The two measures (``SECTIONS``) are the one thing that differs. 2D reads the width of a line
across the centres: the field (bilinear between nodes, as the outline's marching squares are
linear along cell edges) sampled every ``SECTION_STEP`` cells out to ``reach`` on either side,
the distance between the outermost crossings of the interface (so that the empty strip of points
along a symmetry line, a hole inside the neck, does not shorten it). 3D reads the area A of a
plane region and gives the diameter 2 sqrt(A / pi), so that a circular neck reads its diameter,
the counterpart of the 2D width (the fillet's neck 2 (t - rho) is the same in both:
solver/contacts.py), and a ratio of necks (the verdict's growth) is a ratio of diameters: each
plane sampled on a square lattice of spacing ``PLANE_STEP`` cells (the field trilinear between
nodes), its area the marching triangles' (each lattice square split into two triangles, on each
of which the field is linear, so the part >= 0 is cut exactly), a hole inside counted as
material as 2D counts the span between the outermost crossings.

Shared: sections every ``SECTION_STEP`` cells span the middle half of the centre distance; the
neck is the narrowest, or the widest once the pair has turned convex (no waist: the narrowest
would be the range's end); 0 where a section holds no material (a torn neck), NaN for a
blown-up state. So are the reach (the radius of the disc or sphere holding both bodies), the
interpolation of a node field and the force's colour filter, each written over ``dim``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from scipy import ndimage

SECTION_STEP = 0.125  # sampling of a neck section, in cells (sub-cell: the crossings are linear)
FAR_APART = 16.0  # centres farther apart than this many body radii: no neck to read
SECTION_RANGE = 0.25  # sections across the middle half of the centre distance (each side)
PLANE_STEP = 0.25  # lattice spacing in each 3D section plane, in cells


def neck_section(
    material: np.ndarray,
    h: float,
    off: int,
    ca: np.ndarray,
    cb: np.ndarray,
    reach: float,
    cell: float | None = None,
) -> tuple[float, np.ndarray]:
    """The neck of one contact (m) and where it lies, on a node field that is >= 0 in the
    material (c - 1/2 of the colour, or -phi of eq. 21): the narrowest section normal to
    ca -> cb (the widest once convex), its width in 2D, 2 sqrt(A / pi) in 3D, sampled out to
    ``reach`` from the line of centres. ``cell``: the length the sampling steps are counted in
    (default h; the grid's cell where the field lies on a finer raster of spacing h, so that
    the raster refines the field, not the number of samples)."""
    cell = h if cell is None else cell
    d = float(np.linalg.norm(cb - ca))
    # a blown-up state (the guard reports it): centres NaN, or flung far beyond the bodies' size
    if not (math.isfinite(d) and math.isfinite(reach) and 0.0 < d <= FAR_APART * reach):
        return math.nan, np.full(len(ca), math.nan)
    e = (cb - ca) / d
    step = SECTION_STEP * cell
    s = np.arange((0.5 - SECTION_RANGE) * d, (0.5 + SECTION_RANGE) * d + 0.5 * step, step)
    sizes = SECTIONS[len(ca)](material, h, off, ca, e, s, reach, cell)
    k = int(np.argmin(sizes))
    # a pair coalesced past its waist is convex: its sections narrow away from the middle, and
    # the narrowest is the range's end, not the neck; read it where it is widest (Hopper's r_n
    # is the middle section). A pair with a waist (every cold or part-fused contact) keeps
    # the narrowest section.
    mid = len(s) // 2
    if k in (0, len(s) - 1) and sizes[mid] > max(sizes[0], sizes[-1]):
        k = int(np.argmax(sizes))
    neck = float(sizes[k]) if len(ca) == 2 else 2.0 * math.sqrt(sizes[k] / math.pi)
    return neck, ca + s[k] * e


def line_widths(
    material: np.ndarray,
    h: float,
    off: int,
    ca: np.ndarray,
    e: np.ndarray,
    s,
    reach: float,
    cell: float,
) -> np.ndarray:
    """2D: the width of each section line at ca + s e across e (m), sampled every
    SECTION_STEP ``cell``."""
    n = np.array([-e[1], e[0]])
    step = SECTION_STEP * cell
    # whole steps either side of the line of centres: the same samples whatever the reach, so a
    # longer reach reads a section inside the shorter one's span as that one did
    n_t = math.ceil(reach / step - 1e-9)
    t = step * np.arange(-n_t, n_t + 1)
    xy = ca[None, None, :] + s[:, None, None] * e + t[None, :, None] * n  # (S, T, 2)
    c = bilinear(material, h, off, xy[..., 0], xy[..., 1], outside=-1.0)
    return np.array([_outer_span(row, t) for row in c])


def plane_areas(
    material: np.ndarray,
    h: float,
    off: int,
    ca: np.ndarray,
    e: np.ndarray,
    s,
    reach: float,
    cell: float,
) -> np.ndarray:
    """3D: the area of each section plane through ca + s e normal to e (m^2), on a lattice of
    PLANE_STEP ``cell``."""
    u, w = plane_basis(e)
    lat = PLANE_STEP * cell
    n_t = math.ceil(reach / lat - 1e-9)
    t = lat * np.arange(-n_t, n_t + 1)
    plane = t[:, None, None] * u + t[None, :, None] * w  # (T, T, 3)
    points = ca + np.asarray(s)[:, None, None, None] * e + plane  # (S, T, T, 3)
    return section_areas(trilinear(material, h, off, points, -1.0), lat)


SECTIONS: dict[int, Callable[..., np.ndarray]] = {2: line_widths, 3: plane_areas}


def pair_reach(ra: float, rb: float, dim: int = 2) -> float:
    """How far either side of the line of centres a section of one pair is sampled (m): the
    radius of the disc (sphere) holding both bodies' area (volume), sqrt(ra^2 + rb^2) in 2D and
    (ra^3 + rb^3)^(1/3) in 3D: the end state of a coalescence, so the section of a pair fused
    to the end still lies within it (the smaller radius, the earlier reach, capped the width at
    the initial diameter)."""
    if dim == 2:
        return math.sqrt(ra * ra + rb * rb)
    return (ra**3 + rb**3) ** (1.0 / 3.0)


def equivalent_radii(body: np.ndarray, vol: np.ndarray, dim: int) -> np.ndarray:
    """Each body's equivalent radius as seeded (m): sqrt(A / pi) in 2D, (3 V / 4 pi)^(1/3) in
    3D (its reach for a neck)."""
    size = np.bincount(body, weights=vol)
    return np.sqrt(size / np.pi) if dim == 2 else np.cbrt(3.0 * size / (4.0 * np.pi))


def interpolate(
    field: np.ndarray, h: float, off: int, p: np.ndarray, outside: float = 0.0
) -> np.ndarray:
    """A node field (array index i at x = (i - off) h) interpolated multilinearly at the points
    p (..., dim) (m); ``outside`` beyond the arrays."""
    if p.shape[-1] == 2:
        return bilinear(field, h, off, p[..., 0], p[..., 1], outside)
    return trilinear(field, h, off, p, outside)


def bilinear(
    field: np.ndarray, h: float, off: int, x: np.ndarray, y: np.ndarray, outside: float = 0.0
) -> np.ndarray:
    """A node field (array index i at x = (i - off) h) interpolated bilinearly at (x, y) (m);
    ``outside`` beyond the arrays."""
    u, v = x / h + off, y / h + off
    i, j = np.floor(u).astype(int), np.floor(v).astype(int)
    fu, fv = u - i, v - j
    nx, ny = field.shape
    ok = (i >= 0) & (j >= 0) & (i < nx - 1) & (j < ny - 1)
    i, j = np.where(ok, i, 0), np.where(ok, j, 0)
    out = (
        field[i, j] * (1 - fu) * (1 - fv)
        + field[i + 1, j] * fu * (1 - fv)
        + field[i, j + 1] * (1 - fu) * fv
        + field[i + 1, j + 1] * fu * fv
    )
    return np.where(ok, out, outside)


def trilinear(field: np.ndarray, h: float, off: int, p: np.ndarray, outside: float) -> np.ndarray:
    """A node field (array index i at x = (i - off) h) interpolated trilinearly at the points
    p (..., 3) (m); ``outside`` beyond the arrays."""
    u = p / h + off
    i = np.floor(u).astype(np.intp)
    f = u - i
    g = 1.0 - f
    ok = np.all((i >= 0) & (i < np.array(field.shape) - 1), axis=-1)
    stride = np.array(field.strides) // field.itemsize
    base = np.where(ok, i @ stride, 0)  # flat index of each corner (0, 0, 0)
    flat = field.ravel()
    out = np.zeros(p.shape[:-1])
    for a in (0, 1):
        wa = f[..., 0] if a else g[..., 0]
        for b in (0, 1):
            wab = wa * (f[..., 1] if b else g[..., 1])
            for c in (0, 1):
                wc = f[..., 2] if c else g[..., 2]
                out += wab * wc * flat[base + (a * stride[0] + b * stride[1] + c * stride[2])]
    return np.where(ok, out, outside)


def _outer_span(c: np.ndarray, t: np.ndarray) -> float:
    """Distance between the outermost crossings of c = 0 (c > 0: material) along t."""
    inside = np.nonzero(c >= 0.0)[0]
    if len(inside) == 0:
        return 0.0
    lo, hi = inside[0], inside[-1]
    t0 = t[lo] if lo == 0 else t[lo - 1] + (t[lo] - t[lo - 1]) * c[lo - 1] / (c[lo - 1] - c[lo])
    t1 = t[hi]
    if hi < len(t) - 1:
        t1 = t[hi] + (t[hi + 1] - t[hi]) * c[hi] / (c[hi] - c[hi + 1])
    return float(t1 - t0)


def _triangle_fraction(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """The fraction of a triangle where the linear field with corner values a, b, c is >= 0."""
    pos = (a >= 0).astype(int) + (b >= 0) + (c >= 0)
    # the lone corner (the positive one of 1, the negative one of 2) and the other two
    lone_pos = np.where(a >= 0, 0, np.where(b >= 0, 1, 2))
    lone_neg = np.where(a < 0, 0, np.where(b < 0, 1, 2))
    lone = np.where(pos == 1, lone_pos, lone_neg)
    v = np.stack([a, b, c])
    p = np.take_along_axis(v, lone[None], 0)[0]
    q = np.take_along_axis(v, ((lone + 1) % 3)[None], 0)[0]
    r = np.take_along_axis(v, ((lone + 2) % 3)[None], 0)[0]
    with np.errstate(divide="ignore", invalid="ignore"):
        corner = (p / (p - q)) * (p / (p - r))  # the lone corner's similar triangle
    return np.select([pos == 3, pos == 1, pos == 2], [1.0, corner, 1.0 - corner], 0.0)


def section_area(c: np.ndarray, step: float) -> float:
    """Area (m^2) where a field sampled on a square lattice of spacing ``step`` is >= 0, holes
    filled (marching triangles; the lattice's edge is outside)."""
    return float(section_areas(c[None], step)[0])


# binary_fill_holes within each plane of a stack, never across planes
IN_PLANE = np.stack(
    [np.zeros((3, 3), bool), ndimage.generate_binary_structure(2, 1), np.zeros((3, 3), bool)]
)


def section_areas(c: np.ndarray, step: float) -> np.ndarray:
    """:func:`section_area` of each plane c[k] of a stack (S, T, T), in one pass."""
    solid = ndimage.binary_fill_holes(c >= 0.0, structure=IN_PLANE)
    c = np.where(solid & (c < 0.0), 0.0, c)  # a hole's nodes count as material
    sw, se, nw, ne = c[:, :-1, :-1], c[:, 1:, :-1], c[:, :-1, 1:], c[:, 1:, 1:]
    frac = _cut_fraction(sw, se, ne) + _cut_fraction(sw, ne, nw)
    return 0.5 * step * step * frac.sum(axis=(1, 2))


def _cut_fraction(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """:func:`_triangle_fraction` of each triangle, the cut computed only on the triangles the
    interface crosses (few of a section's lattice): 1 inside, 0 outside."""
    full = (a >= 0) & (b >= 0) & (c >= 0)
    cut = (a >= 0) | (b >= 0) | (c >= 0)
    cut &= ~full
    out = full.astype(float)
    out[cut] = _triangle_fraction(a[cut], b[cut], c[cut])
    return out


def plane_basis(e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors normal to e and to each other."""
    k = int(np.argmin(np.abs(e)))
    u = np.cross(e, np.eye(3)[k])
    u /= np.linalg.norm(u)
    return u, np.cross(e, u)


def filtered_colour(c: np.ndarray) -> np.ndarray:
    """The force's colour filter (physics/surface_energy.py, colour_field) in numpy: one
    [1 2 1] / 4 pass along each axis on the interior nodes, 0 on the arrays' edge. It closes
    the one-cell notch that the points of two bodies leave along a node-line mid-plane."""
    out = c
    for axis in range(c.ndim):
        lo = np.take(out, range(0, c.shape[axis] - 2), axis=axis)
        mid = np.take(out, range(1, c.shape[axis] - 1), axis=axis)
        hi = np.take(out, range(2, c.shape[axis]), axis=axis)
        pad = [(0, 0)] * c.ndim
        pad[axis] = (1, 1)
        out = np.pad(0.25 * (lo + 2.0 * mid + hi), pad)
    inner = np.zeros_like(c)
    core = (slice(1, -1),) * c.ndim
    inner[core] = out[core]
    return inner
