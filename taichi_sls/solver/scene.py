"""Bodies -> material points, and the grid that holds them (paper section 3.1, Table 1).

Points are seeded ``n x n`` per cell at the cell's regular sub-positions (2x2: the quarter points)
and kept where they lie inside a body. The grid covers the domain plus ``ghost_cells`` beyond the
left, right and bottom walls (the surface-tension stencil of section 3.1) plus a margin of
``PAD`` cells on every side so that no stencil ever leaves the arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre

from ..config import Case, CaseError
from .contacts import fillet, in_bridge
from .layer_contact import LayerPoints, layer_bridges

PAD = 2  # cells of array margin beyond the ghost layer
AREA_SAMPLES = 8  # grid.seeding = "area": sub-points per point square along each axis


@dataclass
class Scene:
    h: float  # grid spacing (m)
    nx: int  # nodes along x in the arrays
    ny: int
    off: int  # array index of the node at x = 0 (and y = 0)
    width: float  # domain (m)
    height: float
    x: np.ndarray  # (N, dim) point positions (m)
    vol: np.ndarray  # (N,) point volumes (m^2 per unit depth in 2D, m^3 in 3D)
    body: np.ndarray  # (N,) body index
    material: np.ndarray  # (N,) material index
    T0_C: np.ndarray  # (N,) initial temperature (C)
    v0: np.ndarray  # (N, dim) initial velocity (m/s)
    p0: np.ndarray  # (N,) initial in-plane pressure (Pa): surface_tension.initial_stress
    material_names: list[str]
    table1_nodes: int  # nodes of domain plus ghost layer (what the paper's Table 1 counts)
    # a previous layer's points: which carry their state, and the members' values (N, ...)
    carried: np.ndarray | None = None
    carried_state: dict[str, np.ndarray] | None = None
    nz: int = 1  # nodes along z in the arrays (3D)
    depth: float = 0.0  # domain depth (m; 3D)

    @property
    def n_points(self) -> int:
        return len(self.x)

    def reordered(self, order: np.ndarray) -> Scene:
        """The same points in another order (the speed benchmark shuffles them)."""
        per_point = ("x", "vol", "body", "material", "T0_C", "v0", "p0")
        moved = {k: getattr(self, k)[order] for k in per_point}
        if self.carried is not None:
            moved["carried"] = self.carried[order]
            moved["carried_state"] = {k: v[order] for k, v in self.carried_state.items()}
        return Scene(**{**vars(self), **moved})


def inside_polygon(vertices: np.ndarray, px: np.ndarray, py: np.ndarray) -> np.ndarray:
    """Even-odd rule: which of the points (px, py) lie inside the closed outline."""
    inside = np.zeros(px.shape, dtype=bool)
    xa, ya = vertices[:, 0], vertices[:, 1]
    xb, yb = np.roll(xa, -1), np.roll(ya, -1)
    for x0, y0, x1, y1 in zip(xa, ya, xb, yb, strict=True):
        crosses = (y0 > py) != (y1 > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            x_at = x0 + (py - y0) * (x1 - x0) / (y1 - y0)
        inside ^= crosses & (px < x_at)
    return inside


def _inside(body, px: np.ndarray, py: np.ndarray) -> np.ndarray:
    if body.shape == "points":  # a previous layer's points are placed, not seeded
        return np.zeros(px.shape, dtype=bool)
    if body.shape == "disc":
        cx, cy = body.center_um
        dx, dy = px - cx, py - cy
        # r < R (1 + eps cos n theta): a shape mode of the disc (eps = 0: the plain disc)
        r = body.radius_um * (1.0 + body.perturbation * np.cos(body.mode * np.arctan2(dy, dx)))
        return dx**2 + dy**2 < r**2
    if body.shape == "polygon":
        return inside_polygon(np.asarray(body.outline_um(), dtype=float), px, py)
    (x0, y0), (x1, y1) = body.min_um, body.max_um
    return (px > x0) & (px < x1) & (py > y0) & (py < y1)


def _owners_3d(case: Case, P: np.ndarray, spacing: float) -> np.ndarray:
    """The body whose inside holds each candidate point (N, 3) (-1: none), the first that
    does: a sphere (a disc with a 3D centre; with a perturbation, its axisymmetric shape mode
    P_n(cos theta) about x, the 2D mode cos(n theta)'s counterpart), a box (a rect with 3D
    corners), a cylinder or a prism (a disc or a polygon extruded along z); none within a
    previous layer point's cube, and with fillets the bridges to that layer (as in 2D)."""
    owner = np.full(len(P), -1, dtype=np.int64)
    layer = LayerPoints.of_case(case)
    taken = layer.covers(P, 0.5 * spacing)
    owner[taken] = -2
    for bi, b in enumerate(case.bodies):
        if b.shape == "points":  # a previous layer's points are placed, not seeded
            continue
        if b.shape == "disc":
            d = P - np.asarray(b.center_um)
            r2 = (d**2).sum(axis=1)
            R = b.radius_um
            if b.perturbation:  # r < R (1 + eps P_n(cos theta)), theta from the x axis
                cos = d[:, 0] / np.sqrt(np.maximum(r2, 1e-300))
                R = R * (1.0 + b.perturbation * legendre.legval(cos, [0.0] * b.mode + [1.0]))
            inside = r2 < R**2
        elif b.shape == "cylinder":  # a disc extruded along z (config/periodic.py)
            inside = ((P[:, :2] - np.asarray(b.axis_um)) ** 2).sum(axis=1) < b.radius_um**2
        elif b.shape == "prism":  # a polygon extruded along z
            inside = inside_polygon(np.asarray(b.outline_um(), dtype=float), P[:, 0], P[:, 1])
        else:
            inside = ((P > np.asarray(b.min_um)) & (P < np.asarray(b.max_um))).all(axis=1)
        owner[(owner == -1) & inside] = bi
    if case.contact.initial == "fillet":
        if len(layer):
            layer_bridges(case, layer, P, owner, spacing)
        _sphere_bridges(case, P, owner)
    owner[taken] = -1
    return owner


def _sphere_bridges(case: Case, P: np.ndarray, owner: np.ndarray) -> None:
    """``contact.initial = "fillet"`` in 3D: every pair of spheres joined by the 2D fillet's
    bridge turned about their line of centres, the region a torus of tube radius rho cuts off
    (the closing of their union by a ball of radius rho, exact for a pair), each free point
    given to the sphere whose outline is nearer."""
    rho = case.contact.fillet_radius_um
    spheres = [
        (i, np.asarray(b.center_um, float), b.radius_um)
        for i, b in enumerate(case.bodies)
        if b.shape == "disc" and not b.perturbation
    ]
    for k, (ia, ca, ra) in enumerate(spheres):
        for ib, cb, rb in spheres[k + 1 :]:
            d = float(np.linalg.norm(cb - ca))
            f = fillet((0.0, 0.0), ra, (d, 0.0), rb, rho)  # in a plane through the axis
            if f is None:
                continue
            free = np.nonzero(owner == -1)[0]
            rel = P[free] - ca
            s = rel @ ((cb - ca) / d)  # along the axis, and the distance from it
            r = np.sqrt(np.maximum((rel**2).sum(axis=1) - s * s, 0.0))
            sel = in_bridge(f, (0.0, 0.0), (d, 0.0), s, r)
            da = np.linalg.norm(P[free] - ca, axis=1) - ra
            db = np.linalg.norm(P[free] - cb, axis=1) - rb
            owner[free[sel]] = np.where(da[sel] <= db[sel], ia, ib)


def _owners(case: Case, px: np.ndarray, py: np.ndarray, spacing: float) -> np.ndarray:
    """The body each candidate point belongs to (-1: none): the first body that holds it, and
    with ``contact.initial = "fillet"`` the bridges between discs, and between a disc and a
    previous layer, each bridge point given to the body whose outline is nearer. No candidate
    is seeded within a previous layer point's cell (its points are its own)."""
    owner = np.full(px.shape, -1, dtype=np.int64)
    layer = LayerPoints.of_case(case)
    P = np.stack([px, py], axis=-1)
    taken = layer.covers(P, 0.5 * spacing)
    owner[taken] = -2
    for bi, b in enumerate(case.bodies):
        owner[(owner == -1) & _inside(b, px, py)] = bi
    if case.contact.initial != "fillet":
        owner[taken] = -1
        return owner
    if len(layer):
        layer_bridges(case, layer, P, owner, spacing)
    rho = case.contact.fillet_radius_um
    discs = [(i, b) for i, b in enumerate(case.bodies) if b.shape == "disc" and not b.perturbation]
    for k, (ia, a) in enumerate(discs):
        for ib, b in discs[k + 1 :]:
            f = fillet(a.center_um, a.radius_um, b.center_um, b.radius_um, rho)
            if f is None:
                continue
            free = owner == -1
            sel = free & in_bridge(f, a.center_um, b.center_um, px, py)
            da = np.hypot(px - a.center_um[0], py - a.center_um[1]) - a.radius_um
            db = np.hypot(px - b.center_um[0], py - b.center_um[1]) - b.radius_um
            owner[sel] = np.where(da[sel] <= db[sel], ia, ib)
    owner[taken] = -1
    return owner


def _seed(
    case: Case, px: np.ndarray, py: np.ndarray, spacing: float
) -> tuple[np.ndarray, np.ndarray]:
    """(owner, fill) of each candidate point: its body (-1: none) and the fraction of its
    square (side ``spacing``) that the body fills.

    centre: a point belongs to the body that holds its centre and fills its square. area: each
    square is sampled at AREA_SAMPLES^2 sub-points; a point is kept where any sub-point lies in
    a body, belongs to the body holding most of them, and carries the area they fill. The
    outline is then seeded to second order (the node colour reads the body's true area fraction)
    instead of the staircase of +-spacing/2 that a centre test leaves, which moves a narrow
    neck's reading by up to a point spacing at every h."""
    if case.grid.seeding == "centre":
        owner = _owners(case, px, py, spacing)
        return owner, np.ones(px.shape)
    k = AREA_SAMPLES
    u = ((np.arange(k) + 0.5) / k - 0.5) * spacing
    du, dv = (a.ravel() for a in np.meshgrid(u, u, indexing="ij"))
    sub = _owners(case, (px[:, None] + du).ravel(), (py[:, None] + dv).ravel(), spacing)
    sub = sub.reshape(len(px), k * k)
    counts = np.stack([(sub == b).sum(axis=1) for b in range(len(case.bodies))], axis=1)
    held = counts.sum(axis=1)
    owner = np.where(held > 0, np.argmax(counts, axis=1), -1)
    return owner, held / (k * k)


def laplace_pressure(case: Case, body) -> float:
    """Initial pressure of a body (Pa): gamma/R for a disc (Young-Laplace in 2D), 2 gamma/R for
    a sphere (3D), with ``surface_tension.initial_stress = "laplace"`` and surface tension on,
    else 0. A powder
    particle at the preheat temperature has long been in equilibrium with its surface tension;
    started stress-free, the soft discs are compressed by it at t = 0, which opens the neck
    (docs/model.md: the nolaser case)."""
    ph = case.physics
    if (
        case.surface_tension.initial_stress != "laplace"
        or not (ph.surface_tension and ph.mechanics)
        or body.shape != "disc"
    ):
        return 0.0
    # a sphere's two principal curvatures: 2 gamma / R (3D); a cylinder's one: gamma / R (2D)
    curvatures = 2.0 if case.domain.dim == 3 else 1.0
    return curvatures * case.materials[body.material].surface_tension_N_m / (body.radius_um * 1e-6)


def build_scene(case: Case) -> Scene:
    """Seed the points of every body (a point belongs to the first body that holds it): n per
    cell along each of the case's ``domain.dim`` axes."""
    dim = case.domain.dim
    h_um = case.grid.spacing_um
    sides = case.domain_um()
    cells = [int(round(s / h_um)) for s in sides]
    ncx, ncy = cells[:2]
    n = case.grid.points_per_cell
    sub = (np.arange(n) + 0.5) / n  # 2 per cell -> 1/4, 3/4: the quarter points
    axes = [((np.arange(c)[:, None] + sub[None, :]) * h_um).ravel() for c in cells]
    P = [a.ravel() for a in np.meshgrid(*axes, indexing="ij")]
    names = list(case.materials)
    xs, bodies, mats, temps, vels, pres, fills = [], [], [], [], [], [], []
    carried: list[tuple[int, dict[str, np.ndarray]]] = []  # (first point, members)
    if dim == 2:
        owner, fill = _seed(case, *P, h_um / n)
    else:  # centre seeding (config/dim.py refuses area seeding in 3D)
        owner = _owners_3d(case, np.stack(P, axis=1), h_um / n)
        fill = np.ones(len(owner))
    for bi, b in enumerate(case.bodies):
        sel = owner == bi
        xy, f = np.stack([c[sel] for c in P], axis=1), fill[sel]
        if b.shape == "points":  # a previous layer's body: its points, and its fillets' seeded
            placed, vol = b.points_um()
            state = b.carried_state()
            if state is not None:  # the volumes they were seeded with, deformed by their F
                vol = state[0]
                carried.append((sum(len(a) for a in fills), state[1]))
            xy, f = np.concatenate([placed, xy]), np.concatenate([vol / (h_um / n) ** dim, f])
        k = len(f)
        xs.append(xy)
        fills.append(f)
        if k == 0:
            raise CaseError(
                f"bodies[{bi}]: holds no material point at grid.spacing_um = {h_um} "
                f"({case.grid.points_per_cell}x{case.grid.points_per_cell} per cell); make it "
                "larger or the grid finer"
            )
        bodies.append(np.full(k, bi, dtype=np.int32))
        mats.append(np.full(k, names.index(b.material), dtype=np.int32))
        T = case.thermal.initial_C if b.temperature_C is None else b.temperature_C
        temps.append(np.full(k, T))
        v = [*b.velocity_m_s, *(0.0,) * (dim - len(b.velocity_m_s))]  # vz = 0 if left out
        vels.append(np.tile(np.asarray(v, dtype=float), (k, 1)))
        pres.append(np.full(k, laplace_pressure(case, b)))
    x = np.concatenate(xs) * 1e-6
    mask, state = _carried(carried, len(x))
    g = case.grid.ghost_cells
    off = g + PAD
    h = h_um * 1e-6
    z = {}
    if dim == 3:  # ghost cells beyond the front and back walls as beyond the left and right
        z = {"nz": cells[2] + 1 + 2 * off, "depth": sides[2] * 1e-6}
    return Scene(
        h=h,
        nx=ncx + 1 + 2 * off,
        ny=ncy + 1 + 2 * off,
        off=off,
        width=sides[0] * 1e-6,
        height=sides[1] * 1e-6,
        x=x,
        vol=np.concatenate(fills) * (h / n) ** dim,
        body=np.concatenate(bodies),
        material=np.concatenate(mats),
        T0_C=np.concatenate(temps),
        v0=np.concatenate(vels),
        p0=np.concatenate(pres),
        material_names=names,
        table1_nodes=(ncx + 1 + 2 * g) * (ncy + 1 + g) * (cells[2] + 1 + 2 * g if dim == 3 else 1),
        carried=mask,
        carried_state=state,
        **z,
    )


def _carried(
    parts: list[tuple[int, dict[str, np.ndarray]]], n: int
) -> tuple[np.ndarray | None, dict[str, np.ndarray] | None]:
    """The carried state of a previous layer's points as whole-scene arrays (zeros elsewhere)
    and which points it holds; (None, None) without any."""
    if not parts:
        return None, None
    mask = np.zeros(n, dtype=bool)
    state = {k: np.zeros((n, *v.shape[1:])) for k, v in parts[0][1].items()}
    for start, members in parts:
        m = len(next(iter(members.values())))
        mask[start : start + m] = True
        for k, v in members.items():
            state[k][start : start + m] = v
    return mask, state
