"""Contacts between bodies: which bodies touch, the initial neck that joins two touching discs,
and the colour of one pair's points alone. The neck of a contact is read across the line of its
bodies' centres by solver/neck_section.py.

In a bed a section across one contact also crosses the neighbouring particles, and the outermost
crossings then span them: ``point_colour`` gives the colour of one pair's points alone, on which
the bed's per-contact necks are read (``Simulation.pair_necks_m``).

Contacts are a thing, not a column: the list is built once from the seeded points (two bodies
touch where points of both lie within ``TOUCH_SPACINGS`` point spacings), and one function
measures every contact, whatever its direction and wherever it lies.

The initial neck (``[contact] initial = "fillet"``). Two discs that touch at a point start with
a neck, a cusp curvature and a cusp stress that the grid sets (the colour reads 18.4 um at
h = 4 um and 13.6 um at h = 2 um at t = 0), so no refinement can converge. A finite neck with a
smooth outline fixes the start independently of h: the discs are joined by the region between
them that two fillet circles of radius rho, tangent to both discs, cut off. The fillet centres
lie at distance r_a + rho from centre a and r_b + rho from centre b; the neck is the narrowest
section of the bridge, the gap between the two fillet circles across the line of centres. For
two touching discs of radius R, a neck of half-width a needs rho = a^2 / (2 (R - a)): the
paper's 8 um neck between 20 um discs is a fillet of 0.5 um, below any grid used here, so the
fillet radius is a stated modelling choice (``fillet_radius_um``) and the neck follows from it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

TOUCH_SPACINGS = 1.5  # two bodies touch where their points lie this many point spacings apart


@dataclass(frozen=True)
class Fillet:
    """The bridge between discs a and b (m): the fillet circles' centres and radius, and the
    neck: its width and the point on the line of centres where it is narrowest."""

    centre_plus: np.ndarray
    centre_minus: np.ndarray
    radius: float
    neck_width: float
    neck_point: np.ndarray


def fillet(ca, ra: float, cb, rb: float, rho: float) -> Fillet | None:
    """The fillet of radius rho joining disc (ca, ra) to disc (cb, rb), or None where the discs
    are too far apart for it (gap >= 2 rho) or one holds the other."""
    ca, cb = np.asarray(ca, float), np.asarray(cb, float)
    d = float(np.linalg.norm(cb - ca))
    ka, kb = ra + rho, rb + rho
    if d <= abs(ra - rb) or d >= ka + kb:
        return None
    e = (cb - ca) / d
    n = np.array([-e[1], e[0]])
    s = (d * d + ka * ka - kb * kb) / (2.0 * d)  # fillet centres' distance from a along e
    t = math.sqrt(max(ka * ka - s * s, 0.0))  # ... and from the line of centres
    if t <= rho:  # the fillets overlap: the discs overlap by more than the fillet can bridge
        return None
    return Fillet(ca + s * e + t * n, ca + s * e - t * n, rho, 2.0 * (t - rho), ca + s * e)


def in_bridge(f: Fillet, ca, cb, px: np.ndarray, py: np.ndarray) -> np.ndarray:
    """Which points lie in the bridge: inside the kite ca, f+, cb, f- and outside both fillet
    circles (the discs themselves are the bodies' own; the caller excludes their points)."""
    kite = np.array([ca, f.centre_plus, cb, f.centre_minus], dtype=float)
    inside = np.ones(px.shape, dtype=bool)
    for k in range(4):  # a convex quadrilateral, counter-clockwise or clockwise: same side
        x0, y0 = kite[k]
        x1, y1 = kite[(k + 1) % 4]
        cross = (x1 - x0) * (py - y0) - (y1 - y0) * (px - x0)
        inside &= cross * _orientation(kite) >= 0.0
    for c in (f.centre_plus, f.centre_minus):
        inside &= (px - c[0]) ** 2 + (py - c[1]) ** 2 > f.radius**2
    return inside


def _orientation(poly: np.ndarray) -> float:
    x, y = poly[:, 0], poly[:, 1]
    return math.copysign(1.0, float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)))


def touching(points: np.ndarray, body: np.ndarray, spacing: float) -> list[tuple[int, int]]:
    """Pairs of bodies (a < b) with points of both within TOUCH_SPACINGS point spacings."""
    tree = cKDTree(points)
    pairs = tree.query_pairs(TOUCH_SPACINGS * spacing, output_type="ndarray")
    if len(pairs) == 0:
        return []
    ba, bb = body[pairs[:, 0]], body[pairs[:, 1]]
    cross = ba != bb
    lo, hi = np.minimum(ba[cross], bb[cross]), np.maximum(ba[cross], bb[cross])
    return sorted({(int(a), int(b)) for a, b in zip(lo, hi, strict=True)})


def gimp_1d(xi: np.ndarray, h: float, lp: float) -> np.ndarray:
    """The uGIMP weight of physics/shape.py (gimp_1d), in numpy."""
    a = np.abs(xi)
    r = h + lp - a
    return np.where(
        a < lp,
        1.0 - (xi * xi + lp * lp) / (2.0 * h * lp),
        np.where(a < h - lp, 1.0 - a / h, np.where(a < h + lp, r * r / (4.0 * h * lp), 0.0)),
    )


def point_colour(
    x: np.ndarray, weight: np.ndarray, h: float, lp: float, off: int, shape: tuple[int, ...]
) -> np.ndarray:
    """sum_p weight_p N_i(x_p) on the nodes (array index i at x = (i - off) h): the P2G of the
    step (3x3 uGIMP stencil, 3x3x3 in 3D, clamped as solver/step.py clamps it) for a subset of
    the points. With weight = m_p / (rho V_cell) it is the raw mass colour of those points
    alone."""
    f = x / h
    base = np.floor(f + 0.5).astype(int) - 1
    w = [gimp_1d((f - (base + a)) * h, h, lp) for a in range(3)]  # each (N, 2)
    idx = np.clip(base + off, 1, np.array(shape) - 4)
    flat = np.ravel_multi_index(tuple(idx.T), shape)  # each stencil's corner node
    stride = np.ravel_multi_index(tuple(np.eye(len(shape), dtype=int)), shape)  # per axis
    nodes, weights = [], []
    for a in range(3):
        for b in range(3):
            wab = weight * w[a][:, 0] * w[b][:, 1]
            if len(shape) == 2:
                nodes.append(flat + a * stride[0] + b * stride[1])
                weights.append(wab)
                continue
            for c in range(3):  # 3D: the third axis of the stencil
                nodes.append(flat + a * stride[0] + b * stride[1] + c * stride[2])
                weights.append(wab * w[c][:, 2])
    # one scatter, each node's sum in the stencil's order and then the points' (as a loop of
    # np.add.at over the stencil would add them)
    size = int(np.prod(shape))
    out = np.bincount(np.concatenate(nodes), np.concatenate(weights), minlength=size)
    return out.reshape(shape)
