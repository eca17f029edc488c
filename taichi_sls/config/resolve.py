"""Resolving a case: what derives from a validated case, built once, explicitly.

Validating a case (schema.py) only checks it. What a run needs beyond the file's keys is built
here, by :func:`resolve`, which the loaders call (loading.py ``case_from_dict``, ``load_case``):
the ``[bed]``'s discs (2D, bed.py) or spheres (3D, bed3d.py) deposited and listed as bodies
after the case's own and the previous layer's (the table then goes), a domain side the case
leaves unset fitted to the bed, and each 3D laser's ``z_start_um`` set (default the mid-depth,
of the fitted domain). The result, a :class:`ResolvedCase`, is itself a valid case: its dump
(``resolved.toml`` in a run's folder) loads back to the same resolved case.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pydantic import Field, ValidationError

from .bed import Bed, bed_discs
from .bed3d import bed_spheres
from .bodies import Disc, LayerBody
from .errors import CaseError, case_error
from .layer_file import read_layer
from .schema import Case

__all__ = ["ResolvedCase", "resolve"]


class ResolvedCase(Case):
    """A case with everything that derives from it built (:func:`resolve`): no ``[bed]`` left,
    every body listed, the domain's sides and every 3D laser's depth set. Neither field below is
    a key of a case file (a dump leaves them out)."""

    bed_report: dict | None = Field(
        None,
        exclude=True,
        description="what the [bed] was: source, disc or sphere count, contacts, packing "
        "fractions (envelope, bulk), mean top height (um); None without a bed",
    )
    given: Case | None = Field(
        None, exclude=True, description="the case as validated, before it was resolved"
    )

    def _bodies_to_check_overlaps(self) -> list:
        """None once resolved from a validated case: its own bodies were checked then, and the
        bed's by the generator (within bed.overlap_tolerance_um)."""
        return self.bodies if self.given is None else []


def resolve(case: Case) -> ResolvedCase:
    """The resolved case of a validated one (the given case is left as it was). A case already
    resolved comes back as it is: there is nothing left to derive."""
    if isinstance(case, ResolvedCase):
        return case
    work = case.model_copy(deep=True)
    report = _deposit_bed(work) if work.bed is not None else None
    if work.domain.dim == 3:
        for las in work.lasers:
            if las.z_start_um is None:
                las.z_start_um = 0.5 * work.domain.depth()
    data: dict[str, Any] = {name: getattr(work, name) for name in Case.model_fields}
    try:  # the checks a case with a [bed] left to this step: the domain and the bodies in it
        return ResolvedCase.model_validate({**data, "bed_report": report, "given": case})
    except ValidationError as e:
        raise case_error(e, ResolvedCase, data) from None


def _deposit_bed(case: Case) -> dict:
    """Replace ``case.bed`` by its discs or spheres, appended to ``case.bodies`` after the
    previous layer's bodies; an unset domain width, height (or 3D depth) is fitted to the bed:
    its x (and z) range, and its top plus one mean diameter, in whole cells. Returns the bed
    generator's report."""
    bed: Bed = case.bed
    dim = case.domain.dim
    below = _previous_layer(case, bed)
    layer = read_layer(bed.previous_layer) if below else None
    given = case.domain.model_fields_set
    width = case.domain.width_um if "width_um" in given else None
    height = case.domain.height_um if "height_um" in given else None
    old = [[*b.center_um, b.radius_um] for b in case.bodies if b.shape == "disc"]
    old = np.array(old, dtype=float).reshape(-1, dim + 1)
    sides = {"width_um": width, "height_um": height}
    if dim == 2:
        if layer is not None:  # the new discs land on the layer's points, each a disc in its square
            old = np.concatenate([old, layer.balls_um()])
        join = 2.0 * case.contact.fillet_radius_um if case.contact.initial == "fillet" else 0.0
        discs = bed_discs(bed, old, width, height, join)
        centres, radii, report = np.stack([discs.x, discs.y], axis=1), discs.r, discs.report
    else:
        # without depth_um the domain is as deep as it is wide (Domain.depth)
        sides["depth_um"] = case.domain.depth_um if case.domain.depth_um is not None else width
        floor = layer.balls_um() if layer is not None else None
        centres, radii, report = bed_spheres(bed, old, *sides.values(), floor=floor)
    if layer is not None:
        report.update(layer.bed_report(bed.previous_layer))
    h = case.grid.spacing_um
    fit = {
        "width_um": max(report["x_range_um"][1], float(np.max(centres[:, 0] + radii))),
        "height_um": float(np.max(centres[:, 1] + radii)) + 2.0 * float(np.mean(radii)),
    }
    if dim == 3:
        fit["depth_um"] = max(report["z_range_um"][1], float(np.max(centres[:, 2] + radii)))
    for key, reach in fit.items():
        if sides[key] is None:
            setattr(case.domain, key, h * math.ceil(reach / h - 1e-9))
    case.bodies = [
        *case.bodies,
        *below,
        *(
            Disc(
                center_um=[float(v) for v in c],
                radius_um=float(r),
                material=bed.material,
                temperature_C=bed.temperature_C,
            )
            for c, r in zip(centres, radii, strict=True)
        ),
    ]
    case.bed = None
    return report


def _previous_layer(case: Case, bed: Bed) -> list[LayerBody]:
    """The bodies of ``bed.previous_layer`` (none without one), checked against the case:
    their materials exist and their points were seeded at this case's point spacing."""
    if bed.previous_layer is None:
        return []
    layer = read_layer(bed.previous_layer)
    key = f"bed.previous_layer = {bed.previous_layer!r}"
    if layer.dim != case.domain.dim:
        raise CaseError(
            f"{key}: a {layer.dim}D layer (x_um with {layer.dim} columns) with domain.dim = "
            f"{case.domain.dim}; allowed: a layer file written by a {case.domain.dim}D run"
        )
    spacing = case.grid.spacing_um / case.grid.points_per_cell
    seeded = float(np.median(layer.spacing_um()))  # most are whole points
    if not 0.8 * spacing <= seeded <= 1.25 * spacing:
        raise CaseError(
            f"{key}: its points are {seeded:.3g} um apart, this case seeds them "
            f"{spacing:.3g} um apart (grid.spacing_um / grid.points_per_cell); allowed: a "
            "layer run on the same grid"
        )
    out = []
    for b in layer.bodies:
        names = {layer.material_names[m] for m in np.unique(layer.material[layer.body == b])}
        missing = sorted(names - set(case.materials))
        if missing:
            raise CaseError(
                f"{key}: body {b} is of material {missing[0]!r}, not defined here; "
                f"defined: {', '.join(case.materials)}"
            )
        out.append(
            LayerBody(
                shape="points",
                file=bed.previous_layer,
                body=int(b),
                material=sorted(names)[0],
                temperature_C=bed.temperature_C,
            )
        )
    return out
