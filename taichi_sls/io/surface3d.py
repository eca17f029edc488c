"""The material of a 3D run as a colour on a grid, and its c = 1/2 surface as triangles, in numpy
(no GPU, no new dependency: PyVista would do it offscreen but is a large install; docs/running.md).

**Colour.** Each point spreads its share of a point cube (side ``spacing``, the seeding's point
spacing) onto the nodes of a grid of that same spacing with the quadratic B-spline of the MPM
transfer: the colour c is 1 inside a body, 0 outside, and for a regular lattice exactly 1/2 on
the body's true face, half a spacing beyond the last row of points. A point field travels with
it, weighted the same way (:class:`ColourGrid`).

**Surface.** Marching tetrahedra (as physics/tetra.py, in numpy): each grid cube is cut into
six tetrahedra around its diagonal (Kuhn's triangulation), so cubes share their faces'
diagonals and the surface is closed; a tetrahedron with one or three corners inside gives one
triangle, with two a quadrilateral cut into two. A vertex lies on one grid edge and is shared by
every triangle that crosses it (:func:`surface`): the mesh is watertight, each triangle turned
with its normal outwards (towards falling colour)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SURFACE_LEVEL = 0.5  # the colour of the drawn surface: a lattice's true face
PAD_NODES = 3  # grid margin beyond the box, in nodes: more than the B-spline's reach


@dataclass
class ColourGrid:
    """c (nx, ny, nz) on nodes ``lo + spacing * (i, j, k)`` (um), and ``sums[name]``: the point
    field ``name`` summed with the colour's weights (its value where c > 0: sums / c)."""

    lo: np.ndarray
    spacing: float
    c: np.ndarray
    sums: dict[str, np.ndarray]

    def value(self, name: str) -> np.ndarray:
        """The field on the nodes, NaN where no point reaches."""
        return np.divide(
            self.sums[name], self.c, out=np.full_like(self.c, np.nan), where=self.c > 0.0
        )


def colour_grid(
    x_um: np.ndarray,
    fields: dict[str, np.ndarray],
    spacing_um: float,
    box_um: tuple[tuple[float, float], tuple[float, float], tuple[float, float]],
) -> ColourGrid:
    """The colour of points ``x_um`` (N, 3) of volume ``spacing_um``^3 each on a grid of that
    spacing over ``box_um`` ((xmin, xmax), (ymin, ymax), (zmin, zmax)) plus PAD_NODES nodes;
    a point that is not finite or off the grid is left out."""
    h = float(spacing_um)
    lo = np.array([b[0] for b in box_um], dtype=float) - PAD_NODES * h
    hi = np.array([b[1] for b in box_um], dtype=float) + PAD_NODES * h
    shape = tuple(int(n) for n in np.ceil((hi - lo) / h).astype(int) + 1)
    x = np.asarray(x_um, dtype=float).reshape(-1, 3)
    with np.errstate(invalid="ignore", over="ignore"):
        r = (x - lo) / h
        base = np.floor(r - 0.5)
    on = np.isfinite(base).all(axis=1)
    on &= (base >= 0).all(axis=1) & (base + 2 < np.array(shape)).all(axis=1)
    base, f = base[on].astype(np.int64), (r - base)[on]
    w = np.stack([0.5 * (1.5 - f) ** 2, 0.75 - (f - 1.0) ** 2, 0.5 * (f - 0.5) ** 2])  # (3, M, 3)
    vals = {k: np.asarray(v, dtype=float).ravel()[on] for k, v in fields.items()}
    size = shape[0] * shape[1] * shape[2]
    c = np.zeros(size)
    sums = {k: np.zeros(size) for k in vals}
    for a in range(3):
        for b in range(3):
            for d in range(3):
                wt = w[a, :, 0] * w[b, :, 1] * w[d, :, 2]
                node = ((base[:, 0] + a) * shape[1] + base[:, 1] + b) * shape[2] + base[:, 2] + d
                c += np.bincount(node, weights=wt, minlength=size)
                for k, v in vals.items():
                    good = np.isfinite(v)
                    sums[k] += np.bincount(node[good], weights=wt[good] * v[good], minlength=size)
    return ColourGrid(lo, h, c.reshape(shape), {k: s.reshape(shape) for k, s in sums.items()})


@dataclass
class Surface:
    """Triangles ``tris`` (T, 3) into ``verts`` (V, 3) in um, outward normals by the right-hand
    rule; ``values[name]`` (V,) a grid field at each vertex."""

    verts: np.ndarray
    tris: np.ndarray
    values: dict[str, np.ndarray]

    def areas(self) -> np.ndarray:
        v = self.verts[self.tris]
        return 0.5 * np.linalg.norm(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), axis=1)

    def normals(self) -> np.ndarray:
        """Unit normals of the triangles (outwards); a degenerate one reads (0, 0, 0)."""
        v = self.verts[self.tris]
        n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
        norm = np.linalg.norm(n, axis=1, keepdims=True)
        return np.divide(n, norm, out=np.zeros_like(n), where=norm > 0.0)


def _kuhn_offsets() -> np.ndarray:
    """(6, 4, 3): corner k of tetrahedron t of the unit cube, as physics/tetra.tet_corner."""
    out = np.zeros((6, 4, 3), dtype=np.int64)
    for t in range(6):
        a = t // 2
        b = (a + 1 + t % 2) % 3
        axes = (a, b, 3 - a - b)
        for k in range(1, 4):
            out[t, k] = out[t, k - 1]
            out[t, k, axes[k - 1]] = 1
    return out


KUHN = _kuhn_offsets()


def surface(grid: ColourGrid, level: float = SURFACE_LEVEL) -> Surface:
    """The ``level`` surface of ``grid.c`` by marching tetrahedra; each field of ``grid.sums``
    read at the vertices (colour-weighted along the edge: the material's side counts)."""
    c = grid.c
    nx, ny, nz = c.shape
    flat_c = c.ravel()
    inside_node = flat_c > level
    idx = np.arange(c.size).reshape(c.shape)
    cube = idx[:-1, :-1, :-1].ravel()
    stride = np.array([ny * nz, nz, 1])
    corners = cube[None, :, None] + (KUHN @ stride)[:, None, :]  # (6, cubes, 4)
    corners = corners.reshape(-1, 4)
    inside = inside_node[corners]
    n_in = inside.sum(axis=1)
    keep = (n_in > 0) & (n_in < 4)
    corners, inside, n_in = corners[keep], inside[keep], n_in[keep]
    order = np.argsort(~inside, axis=1, kind="stable")  # inside corners first
    sc = np.take_along_axis(corners, order, axis=1)
    edges = []  # (T, 3, 2) node pairs of each triangle's vertices
    for n, pairs in (
        (1, [((0, 1), (0, 2), (0, 3))]),
        (3, [((3, 0), (3, 1), (3, 2))]),
        (2, [((0, 2), (0, 3), (1, 3)), ((0, 2), (1, 3), (1, 2))]),
    ):
        s = sc[n_in == n]
        for tri in pairs:
            edges.append(np.stack([np.stack([s[:, a], s[:, b]], axis=1) for a, b in tri], axis=1))
    e = np.concatenate(edges) if edges else np.zeros((0, 3, 2), dtype=np.int64)
    # one vertex per grid edge: keyed by its two nodes
    pair = np.sort(e.reshape(-1, 2), axis=1)
    key = pair[:, 0] * c.size + pair[:, 1]
    ukey, inv = np.unique(key, return_inverse=True)
    na, nb = ukey // c.size, ukey % c.size
    ca, cb = flat_c[na], flat_c[nb]
    t = (level - ca) / (cb - ca)
    pos = np.stack(np.unravel_index(np.concatenate([na, nb]), c.shape), axis=1).astype(float)
    pos = grid.lo + grid.spacing * pos
    pa, pb = pos[: len(na)], pos[len(na) :]
    verts = pa + t[:, None] * (pb - pa)
    tris = inv.reshape(-1, 3)
    # outwards: the normal of the triangle of its edges' midpoints (never degenerate, turned
    # as the true one, which is degenerate where a node's colour is the level) along its first
    # edge, from the inside node to the outside one
    mid = 0.5 * (pos_of(e[..., 0], grid) + pos_of(e[..., 1], grid))  # (T, 3, 3)
    normal = np.cross(mid[:, 1] - mid[:, 0], mid[:, 2] - mid[:, 0])
    first = e[:, 0, :]
    out_dir = pos_of(first[:, 1], grid) - pos_of(first[:, 0], grid)
    out_dir *= np.where(inside_node[first[:, 0]], 1.0, -1.0)[:, None]
    flip = (normal * out_dir).sum(axis=1) < 0.0
    tris[flip] = tris[flip][:, ::-1]
    # the weighted sums and the colour, both linear along the edge: their ratio
    c_at = (1.0 - t) * ca + t * cb  # = level
    values = {
        k: ((1.0 - t) * s.ravel()[na] + t * s.ravel()[nb]) / c_at for k, s in grid.sums.items()
    }
    return Surface(verts, tris, values)


def pos_of(node: np.ndarray, grid: ColourGrid) -> np.ndarray:
    """Positions (um) of flat node indices of ``grid``: (..., 3) for indices (...)."""
    return grid.lo + grid.spacing * np.stack(np.unravel_index(node, grid.c.shape), axis=-1)
