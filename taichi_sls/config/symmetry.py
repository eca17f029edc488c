"""Checks of mirror walls (``boundary.<side>.mechanical = "mirror"``, physics/mirror.py): the
case is the half of a scene symmetric about each mirror, so what crosses a mirror must be
symmetric about it, and the solver paths that do not fold their grid sums are refused. Each
refusal is one CaseError naming the key, its value and what is allowed."""

from __future__ import annotations

from typing import Any

from .errors import CaseError

SIDES = ("left", "right", "bottom", "top", "front", "back")  # the solver's wall order
AXES = "xyz"
TOLERANCE_UM = 1e-6  # a centre this close to the plane lies on it


def mirrors(case: Any) -> list[tuple[str, int, float]]:
    """(side, axis, plane coordinate in um) of every mirror wall of the case."""
    sides = case.domain_um()
    walls = case.boundary.walls(case.domain.dim)
    return [
        (SIDES[k], k // 2, 0.0 if k % 2 == 0 else sides[k // 2])
        for k, w in enumerate(walls)
        if w.mechanical == "mirror"
    ]


def centred_on(body: Any, axis: int, plane: float) -> bool:
    """Whether the body is a disc (sphere) whose centre lies on the plane."""
    return body.shape == "disc" and abs(body.center_um[axis] - plane) <= TOLERANCE_UM


def within_mirrors(case: Any, body: Any, lo: tuple, hi: tuple) -> tuple[tuple, tuple]:
    """The body's extent (lo, hi) cut at the mirrors it is centred on (its mirrored half lies
    beyond them, outside the domain by design)."""
    lo, hi = list(lo), list(hi)
    for _, d, plane in mirrors(case):
        if centred_on(body, d, plane):
            if plane == 0.0:
                lo[d] = plane
            else:
                hi[d] = plane
    return tuple(lo), tuple(hi)


def check_symmetry(case: Any) -> None:
    """Refuse a mirror wall the solver cannot run, or a scene that is not symmetric about it."""
    planes = mirrors(case)
    if not planes:
        return
    side = planes[0][0]
    key = f"boundary.{side}.mechanical"
    for name, _, _ in planes:
        w = getattr(case.boundary, name)
        if w.thermal != "insulated":
            raise CaseError(
                f'boundary.{name}.thermal = "{w.thermal}": a mirror wall is a plane of symmetry, '
                'insulated (allowed with mechanical = "mirror": "insulated")'
            )
    refusals = (
        (
            case.physics.surface_tension and case.surface_tension.method == "csf",
            'surface_tension.method = "csf"',
            '"surface_energy" (the CSF level set is not mirrored)',
        ),
        (
            case.implicit_mechanics(),
            f'time.integrator = "{case.time.integrator}"',
            '"explicit" (the implicit step does not fold its grid sums)',
        ),
        (
            case.solver.update == "musl",
            'solver.update = "musl"',
            '"usl" (the MUSL remap does not fold its momenta)',
        ),
        (case.bed is not None, "[bed]", "bodies placed by hand (a packed bed is not symmetric)"),
    )
    for refused, what, allowed in refusals:
        if refused:
            raise CaseError(f'{what} with {key} = "mirror": allowed {allowed}')
    for i, b in enumerate(case.bodies):
        for name, d, plane in planes:
            lo, hi = b.centres_extent() if b.shape == "points" else b.extent()
            if lo[d] < plane - TOLERANCE_UM and hi[d] > plane + TOLERANCE_UM:
                if not centred_on(b, d, plane):
                    raise CaseError(
                        f"bodies[{i}]: crosses the mirror boundary.{name} ({AXES[d]} = {plane} "
                        f"um); allowed: a disc centred on it ({AXES[d]} = {plane}) or a body "
                        "clear of it"
                    )
    _check_lasers(case, planes)


def _check_lasers(case: Any, planes: list[tuple[str, int, float]]) -> None:
    """A beam must be symmetric about every mirror: its centre on the plane and its scan along
    it (a y mirror would cut the beam's column: refused with a laser)."""
    for i, las in enumerate(case.lasers):
        for name, d, plane in planes:
            if d == 1:
                raise CaseError(
                    f'lasers[{i}] with boundary.{name}.mechanical = "mirror": the beam comes '
                    "from above; allowed: mirrors in x or z with a laser"
                )
            start = las.x_start_um if d == 0 else las.z_start_um
            if start is None:
                start = case.domain.depth() / 2
            key = "x_start_um" if d == 0 else "z_start_um"
            if abs(start - plane) > TOLERANCE_UM:
                raise CaseError(
                    f"lasers[{i}].{key} = {start}: the beam must be centred on the mirror "
                    f"boundary.{name} (allowed: {plane})"
                )
            moves_across = las.speed_m_s != 0.0 and las.direction == AXES[d]
            if moves_across or (d == 0 and las.scan == "across"):
                raise CaseError(
                    f"lasers[{i}].speed_m_s = {las.speed_m_s}: the beam moves across the mirror "
                    f"boundary.{name}; allowed: 0 or a scan along the plane"
                )
