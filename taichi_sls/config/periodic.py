"""A periodic depth and the cylinder body: ``boundary.front`` and ``boundary.back``
with ``mechanical = "periodic"`` wrap z with the period ``domain.depth_um`` (solver/periodic.py),
a ``shape = "cylinder"`` body is a disc extruded along z across the whole depth, and a
``shape = "prism"`` body a polygon's outline extruded so. All are 3D only; each bad combination
is refused by its key."""

from __future__ import annotations

from typing import Any

from .errors import CaseError

SIDES = ("left", "right", "bottom", "top")


def check_periodic(case: Any) -> None:
    """Refuse a periodic wall other than the front-back pair, a periodic depth in 2D, one of
    the pair alone, a fixed temperature on it, and a cylinder or a prism in 2D."""
    b, dim = case.boundary, case.domain.dim
    for key in SIDES:
        if getattr(b, key).mechanical == "periodic":
            raise CaseError(
                f'boundary.{key}.mechanical = "periodic": only the depth is periodic (front and '
                'back, 3D); allowed: "slip", "stick", "open"'
            )
    front, back = b.front.mechanical == "periodic", b.back.mechanical == "periodic"
    if (front or back) and dim == 2:
        key = "front" if front else "back"
        raise CaseError(
            f'boundary.{key}.mechanical = "periodic" with domain.dim = 2: a periodic depth is '
            "3D only (a 2D plane section has no depth to wrap); allowed in 2D: unset"
        )
    if front != back:
        key, other = ("back", "front") if front else ("front", "back")
        raise CaseError(
            f"boundary.{key}.mechanical = {getattr(b, key).mechanical!r} with "
            f'boundary.{other}.mechanical = "periodic": the depth wraps at both or neither; '
            'allowed: "periodic"'
        )
    if front:
        for key in ("front", "back"):
            if getattr(b, key).thermal != "insulated":
                raise CaseError(
                    f"boundary.{key}.thermal = {getattr(b, key).thermal!r} with a periodic "
                    'depth: no wall there to hold a temperature; allowed: "insulated"'
                )
        for key in SIDES:
            if getattr(b, key).mechanical == "mirror":
                raise CaseError(
                    f'boundary.{key}.mechanical = "mirror" with a periodic depth: the two folds '
                    'of ghost nodes are not built together; allowed: "slip", "stick", "open"'
                )
        if case.solver.update != "usl":
            raise CaseError(
                f"solver.update = {case.solver.update!r} with a periodic depth: the MUSL remap "
                'is not folded over the period; allowed: "usl"'
            )
    for i, body in enumerate(case.bodies):
        section = {"cylinder": "disc", "prism": "polygon"}.get(body.shape)
        if section and dim == 2:
            raise CaseError(
                f'bodies[{i}].shape = "{body.shape}" with domain.dim = 2: a {body.shape} is a '
                f'{section} extruded along z, 3D only; allowed in 2D: "{section}" (its section)'
            )
