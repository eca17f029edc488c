"""Resolving a case: what derives from a validated case, built once, explicitly.

Validating a case (schema.py) only checks it. What a run needs beyond the file's keys is built
here, by :func:`resolve`, which the loaders call (loading.py ``case_from_dict``, ``load_case``):
the ``[bed]``'s discs (2D) or spheres (3D) deposited (bed.py) and listed as bodies
after the case's own and the previous layer's (the table then goes), a domain side the case
leaves unset fitted to the bed, and each 3D laser's ``z_start_um`` set (default the mid-depth,
of the fitted domain). The result, a :class:`ResolvedCase`, is itself a valid case: its dump
(``resolved.toml`` in a run's folder) loads back to the same resolved case.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field, ValidationError

from .bed import Bed, expand_bed
from .bodies import LayerBody
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
    previous layer's bodies, and fit an unset domain side to the bed (config/bed.py
    ``expand_bed``). Returns the bed generator's report."""
    return expand_bed(case, _previous_layer(case, case.bed))


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
