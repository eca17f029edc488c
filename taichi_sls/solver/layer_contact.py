"""A previous layer in the scene: where its points lie, and the fillet that joins a new disc
resting on it (``contact.initial = "fillet"``).

The layer's points (``points`` bodies, read from a layer file) are placed as they are; each
stands for the square (3D: the cube) of its volume around it, and no new body is seeded inside
those.

The fillet of two touching discs (solver/contacts.py) is the region that a circle of radius rho
rolling outside both cannot reach: the morphological closing of their union by a disc of radius
rho, less the union. The same closing joins a disc to a layer of any shape, where no fillet
circle has a closed form: on a raster of the disc's neighbourhood, the union of the disc and the
layer's squares is dilated by rho and eroded by rho (Euclidean distance transforms), and the
closed cells outside the union within 2 rho of both outlines are the bridge. For two discs it
gives the analytic fillet to within the raster spacing (tests/solver/test_layer_contact.py). In
3D the same closing joins a sphere to the layer's cubes, on a voxel raster.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import distance_transform_edt
from scipy.spatial import cKDTree

RASTER_PER_RHO = 8  # raster cells per fillet radius (and per point spacing, the smaller rules)
RASTER_PER_RHO_3D = 4  # in 3D: voxels, (2 R / step)^3 of them around each sphere


class LayerPoints:
    """The points of every ``points`` body of a case (um, (N, dim)), with the body each
    belongs to and the half side of its square (cube)."""

    def __init__(self, x: np.ndarray, half: np.ndarray, body: np.ndarray) -> None:
        self.x, self.half, self.body = x, half, body
        self._tree = cKDTree(x) if len(x) else None

    @classmethod
    def of_case(cls, case) -> LayerPoints:
        """The points of the case's ``points`` bodies (none: an empty layer)."""
        dim = case.domain.dim
        xs, halves = [np.empty((0, dim))], [np.empty(0)]
        owners = [np.empty(0, dtype=np.int64)]
        for bi, b in enumerate(case.bodies):
            if b.shape == "points":
                x, vol = b.points_um()
                xs.append(x)
                halves.append(0.5 * vol ** (1.0 / dim))
                owners.append(np.full(len(vol), bi, dtype=np.int64))
        return cls(np.concatenate(xs), np.concatenate(halves), np.concatenate(owners))

    def __len__(self) -> int:
        return len(self.x)

    def covers(self, P: np.ndarray, half: float | None = None) -> np.ndarray:
        """Which of the positions P (..., dim) lie in a layer point's square (cube): of its
        volume, or of side 2 ``half`` (the seeding's cell, which a partly filled point holds
        whole)."""
        if self._tree is None:
            return np.zeros(P.shape[:-1], dtype=bool)
        reach = float(self.half.max()) if half is None else half
        d, k = self._tree.query(P, p=np.inf, distance_upper_bound=reach)
        hit = np.isfinite(d)
        out = np.zeros(P.shape[:-1], dtype=bool)
        out[hit] = d[hit] <= (self.half[k[hit]] if half is None else half)
        return out

    def nearest_body(self, P: np.ndarray) -> np.ndarray:
        """The body of the layer point nearest to each position (..., dim)."""
        _, k = self._tree.query(P)
        return self.body[k]

    def gap_to_disc(self, centre: np.ndarray, radius: float) -> float:
        """The smallest gap between the disc's (sphere's) outline and a layer square (um; inf:
        none near)."""
        if self._tree is None:
            return np.inf
        near = self._tree.query_ball_point(centre, radius + 4.0 * float(self.half.max()))
        if not near:
            return np.inf
        d = np.linalg.norm(self.x[near] - centre, axis=1) - radius - self.half[near]
        return float(d.min())


def layer_bridges(
    case, layer: LayerPoints, P: np.ndarray, owner: np.ndarray, spacing: float
) -> None:
    """Give each free position (owner -1) of P (N, dim) in the bridge between a disc (sphere)
    and the layer to the nearer of the two bodies (``owner`` updated in place; lengths um)."""
    rho = case.contact.fillet_radius_um
    dim = P.shape[1]
    step = min(rho, spacing) / (RASTER_PER_RHO if dim == 2 else RASTER_PER_RHO_3D)
    for bi, b in enumerate(case.bodies):
        if b.shape != "disc" or b.perturbation:
            continue
        c, R = np.asarray(b.center_um, dtype=float), b.radius_um
        if layer.gap_to_disc(c, R) >= 2.0 * rho:  # not resting on the layer
            continue
        lo = c - R - 4.0 * rho
        n = int(np.ceil(2.0 * (R + 4.0 * rho) / step))
        cells = (np.arange(n) + 0.5) * step
        grid = np.stack(np.meshgrid(*(lo[a] + cells for a in range(dim)), indexing="ij"), -1)
        d = grid - c
        to_disc = (np.hypot(d[..., 0], d[..., 1]) if dim == 2 else np.linalg.norm(d, axis=-1)) - R
        in_disc = to_disc < 0.0
        in_layer = layer.covers(grid)
        union = in_disc | in_layer
        dilated = distance_transform_edt(~union) * step <= rho
        closed = distance_transform_edt(dilated) * step > rho
        to_layer = distance_transform_edt(~in_layer) * step
        bridge = closed & ~union & (to_disc <= 2.0 * rho + step) & (to_layer <= 2.0 * rho + step)
        if not bridge.any():
            continue
        ijk = np.floor((P - lo) / step).astype(np.int64)
        sel = np.nonzero((owner == -1) & (ijk >= 0).all(axis=1) & (ijk < n).all(axis=1))[0]
        sel = sel[bridge[tuple(ijk[sel].T)]]
        if len(sel) == 0:
            continue
        at = tuple(ijk[sel].T)
        near_disc = to_disc[at] <= to_layer[at]
        owner[sel] = np.where(near_disc, bi, layer.nearest_body(P[sel]))
