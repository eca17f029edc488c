"""The 3D check of neck growth at any angle to the grid (issue #55): two spheres of Hopper's
fluid (cases/verification/hopper.toml's material, open walls, no heat) joined by a torus fillet
(``contact.initial = "fillet"``), their line of centres along x, along (1, 1, 0) / sqrt 2 or
along (1, 1, 1) / sqrt 3, the contact at the same point of the same cubic box for every
direction (a node plane through it along x; 0.377 h and 0.211 h off the node planes in y and z).
The neck is the per-contact section across the centres (2 sqrt(A / pi), solver/neck_section.py)
over 2 R, read at the same times for every direction; their worst ratio is the angle effect.
``taichi-sls bench isotropy --spheres`` runs the table (docs/record/verification.md, "Neck
growth at any angle")."""

from __future__ import annotations

import math
import time

import numpy as np

from ...config import Case, case_from_dict, deep_update, read_toml
from .isotropy import NeckHistory
from .spec import case_path

DIRECTIONS = {  # name: the unit vector of the line of centres
    "x": (1.0, 0.0, 0.0),
    "xy": (1.0 / math.sqrt(2.0), 1.0 / math.sqrt(2.0), 0.0),
    "xyz": (1.0 / math.sqrt(3.0),) * 3,
}
CONTACT_OFFSET = (0.0, 0.377, 0.211)  # the contact off the box's central node, in cells
MARGIN_CELLS = 4  # empty cells beyond the pair along every axis (open walls, the colour's reach)


def sphere_pair(
    direction: str, R_um: float, R_over_h: float, fillet_um: float, sets: dict | None = None
) -> Case:
    """Two spheres of radius ``R_um`` touching at a point of a cube, their line of centres along
    DIRECTIONS[``direction``], joined by fillets of ``fillet_um``; grid spacing R / R_over_h;
    ``sets`` (nested case keys) merged last. The cube holds the pair along any direction: side
    4 R plus the margins, whole cells."""
    data = read_toml(case_path("hopper"), "verification case")
    h = R_um / R_over_h
    side = h * math.ceil(4.0 * R_um / h + 2 * MARGIN_CELLS)
    contact = np.array([h * round(side / (2 * h))] * 3) + h * np.array(CONTACT_OFFSET)
    d = np.array(DIRECTIONS[direction])
    material = data["bodies"][0]["material"]
    data.pop("verification")
    data["case"] = {"name": f"sphere_pair_{direction}", "description": "3D isotropy check"}
    data["grid"] = {"spacing_um": h}  # seeding "centre": the one built in 3D
    data["domain"] = {"dim": 3, "width_um": side, "height_um": side, "depth_um": side}
    data["bodies"] = [
        {"shape": "disc", "center_um": (contact + s * R_um * d).tolist(), "radius_um": R_um}
        | {"material": material}
        for s in (-1.0, 1.0)
    ]
    data["physics"]["gravity_m_s2"] = [0.0, 0.0, 0.0]
    for wall in ("front", "back"):
        data["boundary"][wall] = {"mechanical": "open"}
    data["contact"] = {"initial": "fillet", "fillet_radius_um": fillet_um}
    data["contact"]["neck_section"] = "centres"
    data["output"]["gif"] = False
    return case_from_dict(deep_update(data, sets or {}))


def sphere_neck_history(case: Case, times: np.ndarray) -> NeckHistory:
    """Run the pair of ``case`` and read its neck over the diameter, 2 sqrt(A / pi) / 2 R, at
    each of ``times`` (s, increasing, the first may be 0); angle_deg: the line of centres' angle
    to the x axis, viscous_time eta_N R / gamma (s)."""
    from ...solver.simulation import Simulation
    from .capillarity import eta_newtonian
    from .common import material

    t0 = time.perf_counter()
    m = material(case)
    R = case.bodies[0].radius_um * 1e-6
    sim = Simulation(case)
    steps0 = sim.state.scalars.step[None]
    neck = []
    for t in times:
        sim.advance_to(float(t))
        neck.append(0.5 * sim.necks.necks_m("colour")[0] / R)
    a, b = (np.array(body.center_um) for body in case.bodies)
    return NeckHistory(
        angle_deg=float(np.degrees(np.arccos(abs(b - a)[0] / np.linalg.norm(b - a)))),
        times=np.asarray(times, dtype=float),
        neck=np.array(neck),
        viscous_time=eta_newtonian(m) * R / m.surface_tension_N_m,
        wall_s=time.perf_counter() - t0,
        steps=int(sim.state.scalars.step[None] - steps0),
    )


def worst_ratio(histories: list[NeckHistory]) -> float:
    """The largest |neck / neck of the first history - 1| over the others and the times."""
    first = histories[0].neck
    return max(float(np.max(np.abs(h.neck / first - 1.0))) for h in histories[1:])
