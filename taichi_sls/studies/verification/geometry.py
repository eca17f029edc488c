"""The geometry of a verification case at a resolution (raw case data, in place): a disc at R/h,
a bar of n cells, a slab, Hopper's pair at R0/h."""

from __future__ import annotations

import math

import numpy as np

from .. import references as ref


def disc_geometry(data: dict, R_over_h: float) -> None:
    """Disc of the case at R/h: domain 2R(1 + |eps|) + 12 h square, centre off the grid lines so
    that the seeding is not symmetric about a node (``domain.dim = 3``: a sphere in a cube)."""
    b = data["bodies"][0]
    R = b["radius_um"]
    h = R / R_over_h
    W = h * math.ceil((2 * R * (1 + abs(b.get("perturbation", 0.0))) + 12 * h) / h)
    data["grid"]["spacing_um"] = h
    if data.get("domain", {}).get("dim", 2) == 3:  # a sphere in a cube
        data["domain"] = {"dim": 3, "width_um": W, "height_um": W, "depth_um": W}
        b["center_um"] = [W / 2 + 0.123 * h, W / 2 + 0.377 * h, W / 2 - 0.141 * h]
        return
    data["domain"] = {"width_um": W, "height_um": W}
    b["center_um"] = [W / 2 + 0.123 * h, W / 2 + 0.377 * h]


def bar_geometry(data: dict, cells: int, fixed_fixed: bool) -> None:
    b = data["bodies"][0]
    L = b["max_um"][0]
    h = L / cells
    data["grid"]["spacing_um"] = h
    data["domain"] = {"width_um": L if fixed_fixed else L + 4 * h, "height_um": 4 * h}
    b["max_um"] = [L, h]


def slab_length(data: dict, h: float, length: float) -> None:
    """A 1D slab along x: `length` rounded up to whole cells, two cells of points tall."""
    W = h * math.ceil(length / h - 1e-9)
    data["grid"]["spacing_um"] = h
    data["domain"] = {"width_um": W, "height_um": 4 * h}
    data["bodies"][0]["min_um"] = [0.0, 0.0]
    data["bodies"][0]["max_um"] = [W, 2 * h]


def hopper_radius_um(data: dict) -> float:
    """R0 of a Hopper case (raw case data): the discs' radius, or for an outline the radius of
    each of two discs of its area."""
    b = data["bodies"][0]
    if b.get("shape", "disc") in ("disc", "cylinder"):
        return float(b["radius_um"])
    from ...config import Polygon, Prism

    outline = Prism if b.get("shape") == "prism" else Polygon
    v = np.asarray(outline(**{k: b[k] for k in b if k != "material"}).outline_um(), dtype=float)
    # rounded to 1 nm: the polygon's area falls short of the outline's by ~5e-5
    return round(math.sqrt(abs(ref.polygon_area(v)) / (2.0 * math.pi)), 3)


def _depth_cells(data: dict) -> int:
    """Cells across the depth of a 3D Hopper case file (its depth_um over its spacing_um); 0 in
    2D."""
    d = data.get("domain", {})
    if d.get("dim", 2) != 3:
        return 0
    return max(1, round(float(d["depth_um"]) / float(data["grid"]["spacing_um"])))


def hopper_geometry(data: dict, R0_over_h: float) -> None:
    """Hopper's pair at R0/h (raw case data, in place): domain 4 R0 + 12 h by 3 R0 + 12 h (the
    final circle has radius sqrt(2) R0; turned by ``hopper_angle_deg``, the box that holds the
    turned pair), the mid-plane on a node line or through cell centres
    (verification.hopper_midplane), the line of centres 0.377 h off the node rows and turned by
    hopper_angle_deg about the neck. tau0 = 0: two touching discs; tau0 > 0: the outline at tau0
    as a polygon of 1024 vertices. A 3D case (cases/verification/hopper3d.toml): the same pair
    along a periodic depth of the file's cells, in every x-y section (two touching cylinders, or
    the outline as a prism)."""
    v = data.setdefault("verification", {})
    R0 = hopper_radius_um(data)
    h = R0 / R0_over_h
    turn = math.radians(float(v.get("hopper_angle_deg", 0.0)))
    cos, sin = abs(math.cos(turn)), abs(math.sin(turn))
    W = h * math.ceil((max(4 * cos + 2 * sin, 3.0) * R0 + 12 * h) / h - 1e-9)
    H = h * math.ceil((max(4 * sin + 2 * cos, 3.0) * R0 + 12 * h) / h - 1e-9)
    X = h * round(W / (2 * h)) + (0.5 * h if v.get("hopper_midplane", "node") == "cell" else 0.0)
    Y = H / 2 + 0.377 * h
    depth_cells = _depth_cells(data)
    data["grid"]["spacing_um"] = h
    data["domain"] = {"width_um": W, "height_um": H}
    mat = data["bodies"][0].get("material", "PA12")
    tau0 = float(v.get("hopper_tau0", 0.0))
    if depth_cells:  # 3D: the pair along a periodic depth of as many cells as the file's
        data["domain"].update(dim=3, depth_um=depth_cells * h)
    if tau0 > 0.0:
        outline = ref.hopper_outline(ref.hopper_nu(tau0), R0, 1024, (0.0, 0.0))
        c, s = math.cos(turn), math.sin(turn)
        xy = (
            np.stack(
                [
                    X + c * outline[:, 0] - s * outline[:, 1],
                    Y + s * outline[:, 0] + c * outline[:, 1],
                ],
                axis=1,
            )
            if turn != 0.0
            else outline + np.array([X, Y])
        )
        shape = "prism" if depth_cells else "polygon"
        data["bodies"] = [{"shape": shape, "vertices_um": xy.tolist(), "material": mat}]
    else:  # two touching discs, in 3D two cylinders
        shape, key = ("cylinder", "axis_um") if depth_cells else ("disc", "center_um")
        dx, dy = R0 * math.cos(turn), R0 * math.sin(turn)
        data["bodies"] = [
            {"shape": shape, key: [X + sign * dx, Y + sign * dy], "radius_um": R0, "material": mat}
            for sign in (-1.0, 1.0)
        ]
