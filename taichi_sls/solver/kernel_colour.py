"""The points' own colour on a raster finer than the grid, closed by a disc of one cell: the field
the sections across the centres read with ``contact.neck_colour = "kernel"`` (the default).

c(x) = sum_p V_p N(x - x_p) / h^dim: each point's current volume V_p = V0_p J_p spread with its
uGIMP shape function N (the weight the step's P2G gives a node at x), taken at any x rather
than at the nodes alone. Its samples at the nodes are the raw colour (with the volume for
m / rho); here it is evaluated where the sections read it:

- Bilinear interpolation between the nodes of a field whose interface is about two cells wide
  moves its c = 1/2 crossing with the interface's place in the cell (up to ~0.07 h each side on
  a straight outline: a first-order error in h that the raw colour carries). The kernel sum
  crosses 1/2 on a straight outline exactly (the kernel is symmetric; the points' squares tile
  the body), and within kappa sigma^2 / 2 of a curved one (sigma^2 = h^2 / 6 + lp^2 / 3, the
  kernel's variance along an axis): second order. The force's filtered colour adds h^2 / 2 of
  variance, kappa h^2 / 4 of widening at a concave neck (+3.2 % between h = 2 and 1 um on the
  resolved pair's fillet; the kernel colour +0.3 %).
- The closing (:func:`closed`): the points of two coalescing bodies never cross their
  mid-plane, and along it, behind the neck's tip, they leave a slot about a cell wide
  (Hopper's pair at R0/h = 20, tau = 0.5: the innermost points 0.58 h either side) that the
  kernel sum reads as a notch (-11.9 % from Hopper; the raw colour -13.4 %). A disc of one
  cell cannot enter it, so the closing fills it, while every outline whose concave radius
  of curvature exceeds a cell is left as it is: as h falls, every smooth outline is.
- A point's volume, not its mass: a region whose points spread (J > 1) keeps c = 1, where the
  mass colour of fixed kernels falls below it.

Sampled on a raster of spacing h / ``REFINE`` (the sections interpolate it bilinearly, or
trilinearly; at h / 4 that moves a straight outline's crossing by at most 0.004 h) over the box
a contact's sections span, from the points within the kernel's reach of it: about 10 ms per
contact in 2D, 0.1 s in 3D (docs/running.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from .contacts import gimp_1d
from .neck_section import FAR_APART, SECTION_RANGE, neck_section

# raster spacing h / REFINE[dim]: in 3D a coarser raster, as the closing's ball costs 1.5 s per
# contact at h / 4 (0.12 s at h / 2); pair3d_25W's seeded 4 um fillet (exact 18.53 um) reads
# 18.87 um at h / 2, 19.04 um at h / 4
REFINE = {2: 4, 3: 2}
# radius of the closing disc (ball), in cells: at 1/2 and 3/4 cell the slot still reads -7.5 /
# -4.3 % on Hopper's pair at tau = 0.5 (-2.6 % at 1); beyond one cell the disc fills resolved
# geometry (the settled pair at h = 2 um moves; docs/record/verification.md)
CLOSING_CELLS = 1.0
CHUNK = 4096  # points spread at a time (each to 11^2 raster nodes in 2D, 7^3 in 3D)


@dataclass(frozen=True)
class Raster:
    """A field on a raster: ``values[i, j(, k)]`` at ``origin + (i, j(, k)) spacing`` (m)."""

    values: np.ndarray
    spacing: float
    origin: np.ndarray


def kernel_colour(
    x: np.ndarray,
    volume: np.ndarray,
    h: float,
    lp: float,
    lo: np.ndarray,
    hi: np.ndarray,
    refine: int | None = None,
) -> Raster:
    """sum_p volume_p N(r - x_p) / h^dim at the raster nodes r of spacing h / ``refine`` that
    cover the box [lo, hi] (m), from the points x (N, dim) and their volumes (m^dim); ``refine``
    defaults to REFINE of the dimension."""
    spacing = h / (refine or REFINE[x.shape[1]])
    first = np.floor(lo / spacing).astype(int)
    shape = tuple(int(n) for n in np.ceil(hi / spacing).astype(int) - first + 1)
    start, end = first * spacing, (first + np.array(shape) - 1) * spacing  # the raster's box
    reach = h + lp  # the kernel's support, each side
    near = np.nonzero(np.all((x > start - reach) & (x < end + reach), axis=1))[0]
    values = np.zeros(math.prod(shape))
    for k in range(0, len(near), CHUNK):
        part = near[k : k + CHUNK]
        values += _spread(x[part], volume[part], h, lp, spacing, first, shape)
    return Raster(values.reshape(shape), spacing, start)


def _spread(
    x: np.ndarray,
    volume: np.ndarray,
    h: float,
    lp: float,
    spacing: float,
    first: np.ndarray,
    shape: tuple[int, ...],
) -> np.ndarray:
    """The kernel sum of the points x on the raster (flattened): each point's weights on the
    raster nodes about its nearest one, a product of its 1D weights along the axes."""
    dim = x.shape[1]
    half = math.ceil((h + lp) / spacing + 0.5)  # the support about the nearest node
    steps = np.arange(-half, half + 1)
    flat = np.zeros((len(x),) + (1,) * dim, dtype=np.int64)
    weight = (volume / h**dim).reshape((-1,) + (1,) * dim)
    for axis in range(dim):
        index = np.rint(x[:, axis] / spacing).astype(int)[:, None] + steps[None, :]
        w = gimp_1d(index * spacing - x[:, axis][:, None], h, lp)
        index -= first[axis]
        inside = (index >= 0) & (index < shape[axis])
        expand = [len(x)] + [1] * dim
        expand[axis + 1] = len(steps)
        weight = weight * np.where(inside, w, 0.0).reshape(expand)
        flat = flat * shape[axis] + np.clip(index, 0, shape[axis] - 1).reshape(expand)
    return np.bincount(flat.ravel(), weights=weight.ravel(), minlength=math.prod(shape))


def section_box(
    ca: np.ndarray, cb: np.ndarray, reach: float, span: float, pad: float
) -> tuple[np.ndarray, np.ndarray]:
    """The axis-aligned box (lo, hi) (m) holding every section of one contact: the line
    ca -> cb from (1/2 - span) to (1/2 + span) of the centre distance, each section a disc (2D:
    a segment) of radius ``reach`` normal to it, widened by ``pad``."""
    d = cb - ca
    e = d / np.linalg.norm(d)
    ends = np.stack([ca + (0.5 - span) * d, ca + (0.5 + span) * d])
    # a disc of radius r normal to e spans r sqrt(1 - e_k^2) along axis k
    across = reach * np.sqrt(np.clip(1.0 - e * e, 0.0, 1.0))
    return ends.min(axis=0) - across - pad, ends.max(axis=0) + across + pad


def closed(raster: Raster, radius: float) -> Raster:
    """The raster's field closed by a flat disc (3D: ball) of ``radius`` (m): the max over the
    disc, then the min over it. Flat closing commutes with thresholding, so its c = 1/2 outline
    is the closing of the outline: what the disc cannot enter (a slot narrower than 2 radius)
    is filled, and an outline whose concave radius of curvature exceeds ``radius`` is left as
    it is (a locally straight one exactly, on the raster too: the max and the min over a
    symmetric footprint cancel)."""
    n = radius / raster.spacing
    steps = np.arange(-math.floor(n), math.floor(n) + 1)
    axes = np.meshgrid(*([steps] * raster.values.ndim), indexing="ij")
    disc = sum(a * a for a in axes) <= n * n + 1e-9
    values = ndimage.grey_closing(raster.values, footprint=disc, mode="constant", cval=0.0)
    return Raster(values, raster.spacing, raster.origin)


def kernel_neck(
    x: np.ndarray,
    volume: np.ndarray,
    h: float,
    lp: float,
    ca: np.ndarray,
    cb: np.ndarray,
    reach: float,
) -> float:
    """The neck (m) of the contact between the bodies centred at ca and cb, read by
    :func:`~taichi_sls.solver.neck_section.neck_section` on the kernel colour of the points x
    (with their volumes) rastered over the box its sections span; NaN for a blown-up state
    (as neck_section reads it)."""
    d = float(np.linalg.norm(cb - ca))
    if not (math.isfinite(d) and math.isfinite(reach) and 0.0 < d <= FAR_APART * reach):
        return math.nan
    radius = CLOSING_CELLS * h
    lo, hi = section_box(ca, cb, reach, SECTION_RANGE, h + radius)
    raster = closed(kernel_colour(x, volume, h, lp, lo, hi), radius)
    shifted = (ca - raster.origin, cb - raster.origin)
    return neck_section(raster.values - 0.5, raster.spacing, 0, *shifted, reach, cell=h)[0]
