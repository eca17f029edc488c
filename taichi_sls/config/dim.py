"""The case's dimension (``domain.dim``): coordinates of the right length, and in 3D a one-line
refusal of everything the 3D solver does not build yet (or, for the polygon outline and the
paper's level-set CSF, ever), each naming its key, its value and what is allowed; the laser's
3D keys checked against the dimension."""

from __future__ import annotations

from typing import Any

from .errors import CaseError
from .periodic import check_periodic
from .sections import Wall


def check_dimension(case: Any) -> None:
    """Refuse what ``case.domain.dim`` cannot run; called before any other cross-check."""
    dim = case.domain.dim
    check_periodic(case)  # config/periodic.py: the periodic depth and the cylinder
    _check_coordinates(case, dim)
    if dim == 2:
        # a wall in z set away from its default (a dumped 2D case carries the defaults)
        for key in ("front", "back"):
            if getattr(case.boundary, key) != Wall():
                raise CaseError(
                    f"boundary.{key}: a wall in z, 3D only (domain.dim = 2; allowed: left, "
                    "right, bottom, top)"
                )
        if case.bed is not None and case.bed.z_range_um is not None:
            raise CaseError(
                f"bed.z_range_um = {case.bed.z_range_um}: 3D only (domain.dim = 2 deposits "
                "discs over bed.x_range_um)"
            )
        if case.time.implicit_rows == "blocks":
            raise CaseError(
                'time.implicit_rows = "blocks": 3D only (domain.dim = 2 keeps its rows dense '
                'over the grid; allowed: "auto", "dense")'
            )
        if case.domain.depth_um is not None:
            raise CaseError(
                f"domain.depth_um = {case.domain.depth_um}: 3D only (domain.dim = 2 is a plane "
                "section, per unit depth)"
            )
        for i, las in enumerate(case.lasers):
            for key, v, allowed in (
                ("direction", las.direction, '"x" (the plane\'s x)'),
                ("z_start_um", las.z_start_um, "unset"),
                ("z_end_um", las.z_end_um, "unset"),
            ):
                if v != ("x" if key == "direction" else None):
                    raise CaseError(
                        f"lasers[{i}].{key} = {v!r}: 3D only (domain.dim = 2; allowed: {allowed})"
                    )
        return
    _refuse_in_3d(case)
    _check_lasers_3d(case)


def _check_lasers_3d(case: Any) -> None:
    """The 3D spot (physics/laser.py): tracks lie in the bed, so no plane to cross; the end key
    names the scan axis (z_start_um's default, the mid-depth, is set by config/resolve.py)."""
    for i, las in enumerate(case.lasers):
        if las.scan == "across":
            raise CaseError(
                f'lasers[{i}].scan = "across" with domain.dim = 3: a 3D bed holds its tracks; '
                'allowed in 3D: "along" (with tracks, hatch_um, return_s and direction)'
            )
        other = "x_end_um" if las.direction == "z" else "z_end_um"
        if getattr(las, other) is not None:
            raise CaseError(
                f"lasers[{i}].{other} = {getattr(las, other)} with direction = "
                f'"{las.direction}": the end is along the scan direction (allowed: unset)'
            )
        if las.tracks > 1 and las.return_s is None:
            raise CaseError(
                f"lasers[{i}].return_s = None: {las.tracks} tracks need the time between "
                "their starts (allowed: > 0 s)"
            )


def _check_coordinates(case: Any, dim: int) -> None:
    """Positions have ``dim`` components; a velocity or gravity may leave z out in 3D (0)."""
    for i, b in enumerate(case.bodies):
        for key in ("center_um", "min_um", "max_um"):
            v = getattr(b, key, None)
            if v is not None and len(v) != dim:
                raise CaseError(
                    f"bodies[{i}].{key} = {v}: {len(v)} coordinates with domain.dim = {dim}; "
                    f"allowed: {_form(dim)}"
                )
    vectors = [(f"bodies[{i}].velocity_m_s", b.velocity_m_s) for i, b in enumerate(case.bodies)]
    for key, v in [*vectors, ("physics.gravity_m_s2", case.physics.gravity_m_s2)]:
        if len(v) > dim:
            raise CaseError(
                f"{key} = {v}: {len(v)} components with domain.dim = {dim}; allowed: {_form(dim)}"
            )


def _form(dim: int) -> str:
    return "[x, y]" if dim == 2 else "[x, y, z]"


def _refuse_in_3d(case: Any) -> None:
    """Each feature the 3D solver lacks, refused by its key (the first one met)."""
    not_yet = "not built in 3D yet"
    ph, st = case.physics, case.surface_tension
    if ph.surface_tension and ph.mechanics and st.method == "csf":
        raise CaseError(
            'surface_tension.method = "csf" with domain.dim = 3: the paper\'s level-set CSF is '
            '2D only; allowed in 3D: "surface_energy" (or physics.surface_tension = false)'
        )
    for i, b in enumerate(case.bodies):
        if b.shape == "polygon":
            raise CaseError(
                f'bodies[{i}].shape = "polygon" with domain.dim = 3: a polygon is a 2D outline; '
                'allowed in 3D: "disc" (a sphere), "rect" (a box), "cylinder", "prism" (an '
                "outline extruded along z)"
            )
    if case.grid.seeding == "area":
        raise CaseError(
            f'grid.seeding = "area" with domain.dim = 3: area seeding is {not_yet}; allowed in '
            '3D: "centre"'
        )
    if case.solver.layout == "blocks":
        raise CaseError(
            f'solver.layout = "blocks" with domain.dim = 3: the race-free colouring is 4 '
            f'colours of 2D blocks, {not_yet}; allowed in 3D: "auto", "serial", "parallel"'
        )
