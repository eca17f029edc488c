"""Random sequential deposition of discs with rolling (Visscher & Bolsterli 1972, in 2D): the 2D
algorithm behind config/deposition.py (its 3D counterpart: deposition_spheres.py).

Each disc, in turn, falls vertically at a random x onto the plate (y = 0) or onto the discs
already there, then rolls under gravity over the disc it landed on until it rests: on the
plate, between two discs whose centres lie on either side of its own, or against a side wall
and one disc. No disc moves once placed, so the bed is built in one pass; every contact is exact
to round-off (tangent discs), which is what the fillet initial neck needs (solver/contacts.py).

Lengths in any one unit (the case reads um). Pure numpy; a few thousand discs take about a second.
"""

from __future__ import annotations

import math

import numpy as np

_MAX_MOVES = 10_000  # pivots of one disc before the roll is deemed stuck (never seen)
_EPS_ANGLE = 1e-9  # a contact this little ahead along the roll is the one just left (rad)


def deposit_discs(
    radii: np.ndarray,
    x_range: tuple[float, float],
    rng: np.random.Generator,
    existing: np.ndarray,
) -> np.ndarray:
    """Drop discs of the given radii, in order, over x_range (side walls at its ends) onto the
    plate and onto ``existing`` discs (rows x, y, r: a previous layer). Returns the new
    centres, (n, 2)."""
    x_lo, x_hi = x_range
    ex = np.asarray(existing, float).reshape(-1, 3).T
    m = len(ex[0])
    cx = np.concatenate([ex[0], np.zeros(len(radii))]).astype(float)
    cy = np.concatenate([ex[1], np.zeros(len(radii))]).astype(float)
    cr = np.concatenate([ex[2], radii]).astype(float)
    for i, r in enumerate(radii):
        n = m + i
        if x_hi - x_lo < 2 * r:
            raise ValueError(f"a disc of diameter {2 * r:g} does not fit the width {x_hi - x_lo:g}")
        x = rng.uniform(x_lo + r, x_hi - r)
        cx[n], cy[n] = _settle(x, r, cx[:n], cy[:n], cr[:n], x_lo + r, x_hi - r, rng)
    return np.stack([cx[m:], cy[m:]], axis=1)


def _drop(x, y_from, r, cx, cy, cr, skip) -> tuple[float, int]:
    """Fall from (x, y_from) to the first disc below (its index) or the plate (-1)."""
    dx = x - cx
    reach = (r + cr) ** 2 - dx**2
    ok = reach > 0
    if skip >= 0:
        ok[skip] = False
    y_hit = np.where(ok, cy + np.sqrt(np.where(ok, reach, 0.0)), -np.inf)
    y_hit[y_hit > y_from + 1e-9 * r] = -np.inf  # discs above the start are not in the way
    j = int(np.argmax(y_hit)) if len(y_hit) else -1
    if j < 0 or y_hit[j] <= r:
        return r, -1
    return float(y_hit[j]), j


def _settle(x, r, cx, cy, cr, wall_lo, wall_hi, rng) -> tuple[float, float]:
    """The resting centre of a disc of radius r dropped at x (walls bound its centre)."""
    y, j = _drop(x, math.inf, r, cx, cy, cr, -1)
    if j < 0:
        return x, y
    side = math.copysign(1.0, x - cx[j]) if x != cx[j] else rng.choice([-1.0, 1.0])
    for _ in range(_MAX_MOVES):
        x, y, k, event = _roll(x, y, r, j, side, cx, cy, cr, wall_lo, wall_hi)
        if event in ("plate", "wall"):
            return x, y
        if event == "disc":
            if min(cx[j], cx[k]) < x < max(cx[j], cx[k]):
                return x, y  # cradled between two supports
            j = k  # both supports on one side: roll on over the new one
            continue
        y, k = _drop(x, y, r, cx, cy, cr, j)  # rolled past the equator: fall
        if k < 0:
            return x, y
        j = k
        side = math.copysign(1.0, x - cx[j]) if x != cx[j] else rng.choice([-1.0, 1.0])
    raise RuntimeError(f"a disc dropped at x = {x:g} did not come to rest")


def _roll(x, y, r, j, side, cx, cy, cr, wall_lo, wall_hi):
    """Roll the disc at (x, y) over disc j towards ``side`` until the first event: another disc
    (its index), the plate, a wall, or the equator of j (then it falls). Angles theta about
    j's centre; the roll runs theta0 -> 0 (side +1) or -> pi (side -1), by phi >= 0."""
    R = r + cr[j]
    theta0 = math.atan2(max(y - cy[j], 0.0), x - cx[j])
    span = theta0 if side > 0 else math.pi - theta0
    events = [(span, 3, -1, "equator")]  # (phi, priority at a tie, disc, event)
    if r > cy[j]:  # a disc larger than the support's height meets the plate on the way
        t = math.asin(min((r - cy[j]) / R, 1.0))
        events.append((side * (theta0 - (t if side > 0 else math.pi - t)), 1, -1, "plate"))
    wall = wall_hi if side > 0 else wall_lo
    c = (wall - cx[j]) / R
    if abs(c) <= 1.0:
        events.append((side * (theta0 - math.acos(c)), 2, -1, "wall"))
    # other discs: where the centre's circle about j meets the circle of contact about k
    dxk, dyk = cx - cx[j], cy - cy[j]
    d = np.hypot(dxk, dyk)
    Rk = r + cr
    ok = (d < R + Rk) & (d > np.abs(R - Rk))
    ok[j] = False
    if ok.any():
        a = (R**2 - Rk[ok] ** 2 + d[ok] ** 2) / (2 * d[ok])
        beta = np.arccos(np.clip(a / R, -1.0, 1.0))
        alpha = np.arctan2(dyk[ok], dxk[ok])
        idx = np.nonzero(ok)[0]
        # a disc touched now blocks the roll if the motion heads into it (the one just left
        # lies behind); the tangent of the motion is side (sin theta0, -cos theta0)
        ahead = side * (math.sin(theta0) * dxk[ok] - math.cos(theta0) * dyk[ok]) > 0.0
        for th in (alpha + beta, alpha - beta):
            th = (th + math.pi) % (2 * math.pi) - math.pi
            phi = side * (theta0 - th)
            good = (phi > _EPS_ANGLE) | ((np.abs(phi) <= _EPS_ANGLE) & ahead)
            events += [
                (max(float(p), 0.0), 0, int(k), "disc")
                for p, k in zip(phi[good], idx[good], strict=True)
            ]
    # plate and wall: round-off may put them a hair behind the start
    events = [(max(e[0], 0.0), *e[1:]) if e[0] > -_EPS_ANGLE else e for e in events]
    phi, _, k, event = min(e for e in events if e[0] >= 0.0)
    phi = min(phi, span)
    theta = theta0 - side * phi
    nx, ny = cx[j] + R * math.cos(theta), cy[j] + R * math.sin(theta)
    if event == "plate":
        ny = r
    elif event == "wall":
        nx = wall
    return nx, ny, k, event
