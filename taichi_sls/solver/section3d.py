"""The neck of a contact in 3D (``domain.dim = 3``): the c = 1/2 cross-section of the node
colour in planes normal to the line of the two bodies' centres.

2D reads a neck as the width of a section across the line of centres (solver/contacts.py,
``neck_width``). In 3D the section is a plane region; its size is read as the area-equivalent
radius sqrt(A / pi), and the neck as the diameter 2 sqrt(A / pi), so that a circular neck reads
its diameter, the 3D counterpart of the 2D width (the fillet's neck 2 (t - rho) is the same in
both: solver/contacts.py), and a ratio of necks (the verdict's growth) is a ratio of diameters.

Each plane is sampled on a square lattice of spacing ``PLANE_STEP`` cells out to the pair's
reach (the colour trilinear between nodes), and its area is the marching triangles' one: each
lattice square split into two triangles, on each of which the sampled field is linear, so the
part >= 0 is cut exactly (sub-cell). A hole inside the section (the empty strip of points along
a node plane, with the raw colour) is counted as material, as 2D counts the span between the
outermost crossings. Planes every ``SECTION_STEP`` cells span the middle half of the centre
distance; the neck is the narrowest, or the widest once the pair has turned convex (no waist),
as in 2D.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from .contacts import FAR_APART, SECTION_RANGE, SECTION_STEP

PLANE_STEP = 0.25  # lattice spacing in each section plane, in cells


def pair_reach_3d(ra: float, rb: float) -> float:
    """How far from the line of centres a section of one pair is sampled (m): (ra^3 + rb^3)^(1/3),
    the radius of the sphere holding both bodies' volume (the coalesced end state)."""
    return (ra**3 + rb**3) ** (1.0 / 3.0)


def equivalent_radii(body: np.ndarray, vol: np.ndarray, dim: int) -> np.ndarray:
    """Each body's equivalent radius as seeded (m): sqrt(A / pi) in 2D, (3 V / 4 pi)^(1/3) in
    3D (its reach for a neck)."""
    size = np.bincount(body, weights=vol)
    return np.sqrt(size / np.pi) if dim == 2 else np.cbrt(3.0 * size / (4.0 * np.pi))


def trilinear(field: np.ndarray, h: float, off: int, p: np.ndarray, outside: float) -> np.ndarray:
    """A node field (array index i at x = (i - off) h) interpolated trilinearly at the points
    p (..., 3) (m); ``outside`` beyond the arrays."""
    u = p / h + off
    i = np.floor(u).astype(int)
    f = u - i
    ok = np.all((i >= 0) & (i < np.array(field.shape) - 1), axis=-1)
    i = np.where(ok[..., None], i, 0)
    out = np.zeros(p.shape[:-1])
    for a in (0, 1):
        wa = f[..., 0] if a else 1.0 - f[..., 0]
        for b in (0, 1):
            wb = f[..., 1] if b else 1.0 - f[..., 1]
            for c in (0, 1):
                wc = f[..., 2] if c else 1.0 - f[..., 2]
                out += wa * wb * wc * field[i[..., 0] + a, i[..., 1] + b, i[..., 2] + c]
    return np.where(ok, out, outside)


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
    solid = ndimage.binary_fill_holes(c >= 0.0)
    c = np.where(solid & (c < 0.0), 0.0, c)  # a hole's nodes count as material
    sw, se, nw, ne = c[:-1, :-1], c[1:, :-1], c[:-1, 1:], c[1:, 1:]
    frac = _triangle_fraction(sw, se, ne) + _triangle_fraction(sw, ne, nw)
    return float(0.5 * step * step * frac.sum())


def plane_basis(e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors normal to e and to each other."""
    k = int(np.argmin(np.abs(e)))
    u = np.cross(e, np.eye(3)[k])
    u /= np.linalg.norm(u)
    return u, np.cross(e, u)


def neck_diameter(
    material: np.ndarray, h: float, off: int, ca: np.ndarray, cb: np.ndarray, reach: float
) -> tuple[float, np.ndarray]:
    """The neck of one contact in 3D (m): 2 sqrt(A / pi) of the narrowest section (the widest
    once convex) normal to ca -> cb, and where it lies, on a node field >= 0 in the material;
    0 where a section holds no material, NaN for a blown-up state."""
    d = float(np.linalg.norm(cb - ca))
    if not (math.isfinite(d) and math.isfinite(reach) and 0.0 < d <= FAR_APART * reach):
        return math.nan, np.full(3, math.nan)
    e = (cb - ca) / d
    u, w = plane_basis(e)
    step = SECTION_STEP * h
    s = np.arange((0.5 - SECTION_RANGE) * d, (0.5 + SECTION_RANGE) * d + 0.5 * step, step)
    lat = PLANE_STEP * h
    n_t = math.ceil(reach / lat - 1e-9)
    t = lat * np.arange(-n_t, n_t + 1)
    plane = t[:, None, None] * u + t[None, :, None] * w  # (T, T, 3)
    areas = np.array(
        [section_area(trilinear(material, h, off, ca + sk * e + plane, -1.0), lat) for sk in s]
    )
    k = int(np.argmin(areas))
    mid = len(s) // 2
    if k in (0, len(s) - 1) and areas[mid] > max(areas[0], areas[-1]):
        k = int(np.argmax(areas))
    return 2.0 * math.sqrt(areas[k] / math.pi), ca + s[k] * e


def filtered_colour_3d(c: np.ndarray) -> np.ndarray:
    """The force's colour filter in 3D (physics/surface_energy.py, colour_field) in numpy: one
    [1 2 1] / 4 pass along x, y and z on the interior nodes, 0 on the arrays' edge."""
    out = c
    for axis in range(3):
        lo = np.take(out, range(0, c.shape[axis] - 2), axis=axis)
        mid = np.take(out, range(1, c.shape[axis] - 1), axis=axis)
        hi = np.take(out, range(2, c.shape[axis]), axis=axis)
        pad = [(0, 0)] * 3
        pad[axis] = (1, 1)
        out = np.pad(0.25 * (lo + 2.0 * mid + hi), pad)
    inner = np.zeros_like(c)
    inner[1:-1, 1:-1, 1:-1] = out[1:-1, 1:-1, 1:-1]
    return inner
