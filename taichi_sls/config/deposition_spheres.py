"""Random sequential deposition of spheres with rolling (Visscher & Bolsterli 1972; Jullien &
Meakin 1987): the 3D algorithm behind config/deposition.py, the counterpart of
deposition_discs.py (docs/record/beds.md, "3D beds").

Each sphere, in turn, falls vertically at a random (x, z) onto the plate (y = 0) or onto the
spheres already there, then moves under gravity along the steepest descent its contacts allow:
over one sphere (a great circle of the sphere of centres about it), in the groove of two (the
circle of centres touching both), or along a side wall and a sphere, until it rests on the
plate or on three supports (spheres or walls) whose contact normals hold it up; a sphere whose
support gives way falls again. The motion at each contact set is the projection of gravity on
the cone the contacts allow (frictionless unilateral contacts), so every contact force stays
compressive; every path is a circle and every event (a new contact, the plate, a wall, a support
giving way) a root of A cos(phi) + B sin(phi) = C, found in closed form. Nothing moves once
placed; every contact is a tangency exact to round-off.

Lateral boundaries: ``"walls"`` (planes at the ends of the x and z ranges, as a case's domain
has) or ``"periodic"`` (in x and z: no wall layers, the bulk packing a wide bed has inside).
Lengths in any one unit. Pure numpy (no kernel to compile).
"""

from __future__ import annotations

import itertools
import math
from typing import Literal

import numpy as np

Lateral = Literal["walls", "periodic"]
PLATE, X_LO, X_HI, Z_LO, Z_HI = -1, -2, -3, -4, -5  # plane supports (sphere supports: >= 0)
_PLANE_NORMAL = {
    PLATE: (0.0, 1.0, 0.0),
    X_LO: (1.0, 0.0, 0.0),
    X_HI: (-1.0, 0.0, 0.0),
    Z_LO: (0.0, 0.0, 1.0),
    Z_HI: (0.0, 0.0, -1.0),
}
_G = np.array([0.0, -1.0, 0.0])  # the direction of gravity
_TOUCH = 1e-9  # a gap below this fraction of the radius is a contact (round-off of the paths)
_TOL = 1e-10  # round-off of unit vectors: contact forces, approach rates
_MAX_MOVES = 2_000  # paths of one sphere before it is deemed stuck (never seen)


def deposit_spheres(
    radii: np.ndarray,
    x_range: tuple[float, float],
    z_range: tuple[float, float],
    rng: np.random.Generator,
    lateral: Lateral = "walls",
    existing: np.ndarray | None = None,
) -> np.ndarray:
    """Drop spheres of the given radii, in order, over x_range x z_range onto the plate (y = 0)
    and onto ``existing`` spheres (rows x, y, z, r). Returns the new centres, (n, 3)."""
    old = np.empty((0, 4)) if existing is None else np.asarray(existing, float).reshape(-1, 4)
    r_max = float(np.max(np.concatenate([radii, old[:, 3]])))
    bed = _Bed(x_range, z_range, lateral == "periodic", r_max, len(old) + len(radii))
    for row in old:
        bed.add(row[:3], row[3])
    (x0, x1), (z0, z1) = x_range, z_range
    out = np.empty((len(radii), 3))
    for i, r in enumerate(np.asarray(radii, float)):
        if not bed.periodic and min(x1 - x0, z1 - z0) < 2 * r:
            raise ValueError(f"a sphere of diameter {2 * r:g} does not fit the range")
        lo = 0.0 if bed.periodic else r
        x = rng.uniform(x0 + lo, x1 - lo)
        z = rng.uniform(z0 + lo, z1 - lo)
        out[i] = _settle(bed, np.array([x, math.inf, z]), r, rng)
        bed.add(out[i], r)
    return out


class _Bed:
    """The spheres placed so far, binned in (x, z) columns for the neighbour searches."""

    def __init__(self, x_range, z_range, periodic: bool, r_max: float, capacity: int) -> None:
        self.lo = np.array([x_range[0], z_range[0]], float)
        self.size = np.array([x_range[1] - x_range[0], z_range[1] - z_range[0]], float)
        if periodic and np.min(self.size) < 8.0 * r_max:
            # a path's circle and a sphere it meets lie within 4 r_max: one image in reach
            raise ValueError("a periodic range must be at least four of the largest diameters")
        self.periodic, self.r_max = periodic, r_max
        self.bins = np.maximum((self.size // (2.0 * r_max)).astype(int), 1)
        self.cell = self.size / self.bins
        self.members: dict[tuple[int, int], list[int]] = {}
        self._c = np.empty((capacity, 3))
        self._r = np.empty(capacity)
        self.n = 0

    @property
    def c(self) -> np.ndarray:
        return self._c[: self.n]

    @property
    def r(self) -> np.ndarray:
        return self._r[: self.n]

    def add(self, centre: np.ndarray, r: float) -> None:
        centre = self.wrap(np.asarray(centre, float))
        self._c[self.n], self._r[self.n] = centre, r
        self.members.setdefault(self._bin(centre), []).append(self.n)
        self.n += 1

    def wrap(self, p: np.ndarray) -> np.ndarray:
        if self.periodic:
            p = p.copy()
            p[[0, 2]] = self.lo + np.mod(p[[0, 2]] - self.lo, self.size)
        return p

    def _bin(self, p: np.ndarray) -> tuple[int, int]:
        k = np.floor((p[[0, 2]] - self.lo) / self.cell).astype(int)
        k = np.mod(k, self.bins) if self.periodic else np.clip(k, 0, self.bins - 1)
        return int(k[0]), int(k[1])

    def near(self, p: np.ndarray, reach: float) -> np.ndarray:
        """Indices of the spheres whose centres may lie within ``reach`` of p in (x, z)."""
        k0 = np.floor((p[[0, 2]] - reach - self.lo) / self.cell).astype(int)
        k1 = np.floor((p[[0, 2]] + reach - self.lo) / self.cell).astype(int)
        axes = []
        for a in range(2):
            if self.periodic:
                span = range(k0[a], k1[a] + 1)
                axes.append(sorted({k % self.bins[a] for k in span}))
            else:
                axes.append(range(max(k0[a], 0), min(k1[a], self.bins[a] - 1) + 1))
        found = [self.members.get((i, j), ()) for i in axes[0] for j in axes[1]]
        return np.fromiter(itertools.chain.from_iterable(found), dtype=int)

    def delta(self, p: np.ndarray, idx: np.ndarray) -> np.ndarray:
        """p minus the centres idx, each the periodic image nearest p: (len(idx), 3)."""
        d = p - self.c[idx]
        if self.periodic:
            d[:, [0, 2]] -= self.size * np.round(d[:, [0, 2]] / self.size)
        return d


def _touching(bed: _Bed, p: np.ndarray, r: float) -> tuple[list[int], np.ndarray]:
    """The supports p touches (sphere indices and plane ids) and their unit normals."""
    ids, normals = [], []
    idx = bed.near(p, r + bed.r_max)
    if len(idx):
        d = bed.delta(p, idx)
        dist = np.linalg.norm(d, axis=1)
        hit = np.abs(dist - (r + bed.r[idx])) <= _TOUCH * r
        ids += [int(k) for k in idx[hit]]
        normals += list(d[hit] / dist[hit, None])
    gaps = {PLATE: p[1] - r}
    if not bed.periodic:
        (x0, z0), (w, d_) = bed.lo, bed.size
        gaps.update({X_LO: p[0] - x0 - r, X_HI: x0 + w - r - p[0]})
        gaps.update({Z_LO: p[2] - z0 - r, Z_HI: z0 + d_ - r - p[2]})
    for k, gap in gaps.items():
        if gap <= _TOUCH * r:
            ids.append(k)
            normals.append(np.array(_PLANE_NORMAL[k]))
    return ids, np.array(normals).reshape(-1, 3)


def _motion(normals: np.ndarray) -> tuple[tuple[int, ...], np.ndarray]:
    """The active contacts and the direction gravity moves the sphere: its projection on the
    cone {t: t . n_i >= 0} of the touching normals (Moreau's rule for frictionless contacts).
    The subsets are tried from the smallest, so a support whose force has just vanished is let
    go; the projection is unique, so the first subset that meets the conditions is it."""
    n = len(normals)
    for k in range(min(n, 3) + 1):
        for subset in itertools.combinations(range(n), k):
            N = normals[list(subset)]
            lam = np.zeros(0)
            if k:
                gram = N @ N.T
                if abs(np.linalg.det(gram)) < 1e-12:
                    continue
                lam = np.linalg.solve(gram, N @ _G)
            t = _G - lam @ N
            # the forces -lam push out of each support; no touching support is entered
            if np.all(lam <= _TOL) and np.all(normals @ t >= -_TOL):
                return subset, t
    raise RuntimeError("no admissible motion")  # cannot happen: the cone is never empty


def _settle(bed: _Bed, p: np.ndarray, r: float, rng: np.random.Generator) -> np.ndarray:
    """The resting centre of a sphere of radius r dropped from p (y = inf: from above)."""
    p = _drop(bed, p, r, [])
    for _ in range(_MAX_MOVES):
        ids, normals = _touching(bed, p, r)
        subset, t = _motion(normals)
        active = [ids[i] for i in subset]
        if PLATE in active or np.linalg.norm(t) < _TOL:
            if PLATE in active or len(active) >= 3:
                return p
            # balanced on the top of a sphere or a groove (measure zero): a random nudge along it
            n0 = normals[subset[0]]
            t = np.cross(n0, normals[subset[1]]) if len(active) == 2 else np.cross(n0, _G)
            t *= rng.choice([-1.0, 1.0])
            if np.linalg.norm(t) < _TOL:  # on a sphere's very top: any horizontal way
                t = np.array([1.0, 0.0, 0.0])
        if np.linalg.norm(np.cross(t, _G)) <= _TOL * np.linalg.norm(t) or not any(
            k >= 0 for k in active
        ):
            p = _drop(bed, p, r, [k for k in ids if k >= 0])  # free fall, or down a wall
            continue
        p = bed.wrap(_roll(bed, p, r, active, t / np.linalg.norm(t)))
    raise RuntimeError(f"a sphere dropped at (x, z) = ({p[0]:g}, {p[2]:g}) did not come to rest")


def _drop(bed: _Bed, p: np.ndarray, r: float, leaving: list[int]) -> np.ndarray:
    """Fall vertically from p to the first sphere below or the plate."""
    idx = bed.near(p, r + bed.r_max)
    if leaving:
        idx = idx[~np.isin(idx, leaving)]
    y = r
    if len(idx):
        d = bed.delta(p, idx)
        reach = (r + bed.r[idx]) ** 2 - d[:, 0] ** 2 - d[:, 2] ** 2
        ok = reach > 0
        y_hit = bed.c[idx[ok], 1] + np.sqrt(reach[ok])
        y_hit = y_hit[y_hit <= p[1] + _TOUCH * r]  # spheres above the start are not in the way
        if len(y_hit):
            y = max(y, float(np.max(y_hit)))
    return np.array([p[0], y, p[2]])


def _circle(bed: _Bed, p: np.ndarray, active: list[int], t: np.ndarray):
    """The path of the centre under the active supports (one sphere, two spheres, or a sphere
    and a wall): centre m, radius rho, p(phi) = m + rho (cos phi u + sin phi v), and each
    support's normal as a e + b r_hat(phi) (e the circle's axis; e = 0 for one support)."""
    spheres = [k for k in active if k >= 0]
    c0 = p - bed.delta(p, np.array(spheres))  # their images nearest p
    if len(active) == 1:
        m, e = c0[0], np.zeros(3)
    elif len(spheres) == 2:
        e = c0[1] - c0[0]
        e /= np.linalg.norm(e)
        m = c0[0] + np.dot(p - c0[0], e) * e
    else:
        e = np.array(_PLANE_NORMAL[next(k for k in active if k < 0)])
        m = c0[0] + np.dot(p - c0[0], e) * e
    rho = float(np.linalg.norm(p - m))
    ab = []
    for k in active:
        if k >= 0:
            ci = c0[spheres.index(k)]
            R = float(np.linalg.norm(p - ci))
            ab.append((np.dot(m - ci, e) / R, rho / R))
        else:
            ab.append((np.dot(_PLANE_NORMAL[k], e), 0.0))
    return m, rho, (p - m) / rho, t, e, ab


def _first_entry(A, B, C, scale) -> np.ndarray:
    """For f(phi) = A cos phi + B sin phi - C, non-negative at phi = 0 up to round-off: the first
    phi >= 0 at which f turns negative (inf if it never does). An f that varies by less than
    round-off of ``scale`` along the path (a wall parallel to it) never does."""
    A, B, C = (np.atleast_1d(np.asarray(a, float)) for a in (A, B, C))
    K = np.hypot(A, B)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = C / K
    phi = np.full(len(K), np.inf)
    ok = (K > _TOUCH * scale) & (np.abs(c) < 1.0)
    # the root where f decreases: phi - delta = +acos(C/K), modulo 2 pi
    phi[ok] = np.mod(np.arctan2(B[ok], A[ok]) + np.arccos(c[ok]), 2 * math.pi)
    phi[ok & (phi > 2 * math.pi - 1e-9)] = 0.0  # just past the root: entering now
    return phi


def _roll(bed: _Bed, p: np.ndarray, r: float, active: list[int], t: np.ndarray) -> np.ndarray:
    """Move along the active supports' circle to the first event: a new sphere, the plate, a
    wall, a support whose force vanishes, or the circle's lowest point."""
    m, rho, u, v, e, ab = _circle(bed, p, active, t)
    events = []
    idx = bed.near(m, rho + r + bed.r_max)
    idx = idx[~np.isin(idx, active)]
    if len(idx):
        D = bed.delta(m, idx)
        Rk = r + bed.r[idx]
        events.append(
            _first_entry(
                2 * rho * D @ u, 2 * rho * D @ v, Rk**2 - rho**2 - (D * D).sum(1), rho * Rk
            )
        )
    planes = [(PLATE, 1, 1.0, r)]
    if not bed.periodic:
        (x0, z0), (w, d) = bed.lo, bed.size
        planes += [(X_LO, 0, 1.0, x0 + r), (X_HI, 0, -1.0, -(x0 + w - r))]
        planes += [(Z_LO, 2, 1.0, z0 + r), (Z_HI, 2, -1.0, -(z0 + d - r))]
    for k, axis, s, level in planes:  # s (m + rho r_hat)[axis] >= level
        if k not in active:
            events.append(
                _first_entry(s * rho * u[axis], s * rho * v[axis], level - s * m[axis], rho)
            )
    gu, gv, ge = _G @ u, _G @ v, _G @ e
    if len(active) == 1:  # the force is -g . r_hat: it vanishes at the support's equator
        events.append(_first_entry(-gu, -gv, 0.0, 1.0))
    else:  # a1 l1 + a2 l2 = g . e, b1 l1 + b2 l2 = g . r_hat (the forces -l in the plane)
        (a1, b1), (a2, b2) = ab
        det = a1 * b2 - a2 * b1
        events.append(_first_entry(a2 / det * gu, a2 / det * gv, ge * b2 / det, 1.0))
        events.append(_first_entry(-a1 / det * gu, -a1 / det * gv, -b1 * ge / det, 1.0))
    lowest = np.mod(math.atan2(-gv, -gu) + math.pi, 2 * math.pi)  # where y is least
    phi = min(lowest, float(np.min(np.concatenate(events))))
    return m + rho * (math.cos(phi) * u + math.sin(phi) * v)
