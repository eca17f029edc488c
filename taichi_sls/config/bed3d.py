"""The ``[bed]`` of a 3D case (``domain.dim = 3``): spheres deposited by random sequential
deposition with rolling (deposition3d.py) between the domain's side walls, read from a CSV file
of spheres, or both, turned into ``[[bodies]]`` spheres when the case is validated, as the 2D
bed's discs are (bed.py; docs/record/beds.md, "3D beds")."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from .bed import Bed, bed_diameters, check_csv_rows, read_columns
from .bodies import Disc
from .deposition3d import deposit_spheres
from .errors import CaseError
from .layer_file import read_layer
from .packing3d import packing_fractions_3d

MAX_SPHERES = 20_000  # the generator takes about a minute at this count
FCC = math.pi / (3 * math.sqrt(2))  # densest packing of spheres: no bed can exceed it
COLUMNS = ("x_um", "y_um", "z_um", "radius_um")


def expand_bed_3d(case: Any, below: list | None = None) -> None:
    """Replace ``case.bed`` by its spheres, appended to ``case.bodies`` (the resolved case lists
    them and loads back to the same bed); an unset domain width, height or depth is fitted to
    the bed (its x and z ranges; its top plus one mean diameter), in whole cells. ``below``: the
    bodies of ``bed.previous_layer`` (LayerBody), listed before the new spheres, which land on
    its points (each a sphere in its cube, as 2D's discs land on squares)."""
    bed: Bed = case.bed
    if bed.material not in case.materials:
        raise CaseError(
            f"bed.material = {bed.material!r}: no such material; defined: "
            f"{', '.join(case.materials)}"
        )
    given = case.domain.model_fields_set
    size = [
        case.domain.width_um if "width_um" in given else None,
        case.domain.height_um if "height_um" in given else None,
        None,
    ]
    # without depth_um the domain is as deep as it is wide (Domain.depth)
    size[2] = case.domain.depth_um if case.domain.depth_um is not None else size[0]
    old = [[*b.center_um, b.radius_um] for b in case.bodies if b.shape == "disc"]
    layer = read_layer(bed.previous_layer) if below else None
    floor = layer.balls_um() if layer else None
    c, r, report = bed_spheres(bed, np.array(old, float).reshape(-1, 4), *size, floor=floor)
    if layer:
        report.update(layer.bed_report(bed.previous_layer))
    h = case.grid.spacing_um
    fit = [
        max(report["x_range_um"][1], float(np.max(c[:, 0] + r))),
        float(np.max(c[:, 1] + r)) + 2.0 * float(np.mean(r)),
        max(report["z_range_um"][1], float(np.max(c[:, 2] + r))),
    ]
    for key, s, f in zip(("width_um", "height_um", "depth_um"), size, fit, strict=True):
        if s is None:
            setattr(case.domain, key, h * math.ceil(f / h - 1e-9))
    case.bodies = [
        *case.bodies,
        *(below or []),
        *(
            Disc(
                center_um=[float(v) for v in ci],
                radius_um=float(ri),
                material=bed.material,
                temperature_C=bed.temperature_C,
            )
            for ci, ri in zip(c, r, strict=True)
        ),
    ]
    case.bed = None
    case._bed_report = report


def _ranges(bed: Bed, width, depth, csv: np.ndarray) -> list[tuple[float, float]]:
    """The x and z ranges the spheres are deposited over (side walls at their ends)."""
    out = []
    for key, given, extent, axis in (
        ("x", bed.x_range_um, width, 0),
        ("z", bed.z_range_um, depth, 2),
    ):
        name = f"bed.{key}_range_um"
        if given is not None:
            lo, hi = given
        elif extent is not None:
            lo, hi = 0.0, extent
        elif len(csv):
            lo, hi = 0.0, float(np.max(csv[:, axis] + csv[:, 3]))
        elif key == "z":  # a domain fitted to the bed: as deep as it is wide
            lo, hi = out[0]
        else:
            raise CaseError(
                f"{name}: required to generate a bed when domain.width_um is not given (the "
                "domain is then sized to the bed)"
            )
        if not hi > lo:
            raise CaseError(f"{name} = {[lo, hi]}: {key}1 must exceed {key}0")
        if lo < 0 or (extent is not None and hi > extent):
            side = "domain.width_um" if key == "x" else "domain.depth_um"
            raise CaseError(
                f"{name} = {[lo, hi]}: must lie within the domain, {key} from 0 to {side} = "
                f"{extent}"
            )
        out.append((float(lo), float(hi)))
    return out


def bed_spheres(
    bed: Bed,
    old: np.ndarray,
    width: float | None,
    height: float | None,
    depth: float | None,
    floor: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, dict]:
    """The bed's spheres (centres (n, 3), radii; um) and the case report: the CSV's, checked,
    then the generated ones on top of them and of the earlier sphere bodies ``old`` (rows x, y,
    z, r). width, height, depth: the domain they must fit (None: sized to the bed). ``floor``:
    a previous layer's points as spheres (rows x, y, z, r), landed on like ``old`` but left out
    of the contact count (its points touch each other)."""
    bodies = old
    if floor is not None:
        old = np.concatenate([old, floor])
    if bed.csv is None and bed.count is None and bed.layers is None:
        raise CaseError("bed: no spheres; give bed.count or bed.layers (generate), or bed.csv")
    if bed.count is not None and bed.layers is not None:
        raise CaseError(
            f"bed.layers = {bed.layers}: give bed.count = {bed.count} or bed.layers, not both"
        )
    csv, source = np.empty((0, 4)), []
    if bed.csv is not None:
        csv, lines = read_columns(bed.csv, "bed.csv", COLUMNS)
        check_csv_rows(bed, csv, lines, old, (width, height, depth))
        source.append(f"csv {Path(bed.csv).name}")
    (x0, x1), (z0, z1) = _ranges(bed, width, depth, csv)
    n = bed.count
    if bed.layers is not None:  # a monolayer: one sphere per median diameter squared
        n = max(1, round(bed.layers * (x1 - x0) * (z1 - z0) / bed.median_diameter_um**2))
        if n > MAX_SPHERES:
            raise CaseError(f"bed.layers = {bed.layers}: {n} spheres; at most {MAX_SPHERES}")
    c, r = csv[:, :3], csv[:, 3]
    if n:
        rng = np.random.default_rng(bed.seed)
        d = bed_diameters(bed, n, rng)
        if d.max() > min(x1 - x0, z1 - z0):
            raise CaseError(
                f"bed.x_range_um, bed.z_range_um = {[x0, x1]}, {[z0, z1]}: narrower than a "
                f"sphere of {d.max():.4g} um; allowed: ranges wider than the largest diameter"
            )
        room = (x1 - x0) * (z1 - z0) * (height if height is not None else math.inf)
        if np.sum(np.pi * d**3 / 6) > FCC * room:
            raise CaseError(
                f"bed: {n} spheres of median {bed.median_diameter_um} um fill more than a close "
                f"packing holds under domain.height_um = {height:g}; allowed: fewer spheres "
                "(bed.count, bed.layers) or a larger domain"
            )
        below = np.concatenate([csv, old]) if len(old) else csv
        gc = deposit_spheres(d / 2, (x0, x1), (z0, z1), rng, "walls", below)
        top = float(np.max(gc[:, 1] + d / 2))
        if height is not None and top > height:
            raise CaseError(
                f"bed: {n} deposited spheres reach y = {top:.4g} um, above domain.height_um = "
                f"{height}; allowed: fewer spheres (bed.count, bed.layers) or a taller domain"
            )
        c, r = np.concatenate([c, gc]), np.concatenate([r, d / 2])
        source.append(f"deposition of {n} (seed {bed.seed})")
    frac = packing_fractions_3d(c, r, (x0, x1), (z0, z1))
    report = {
        "spheres": len(r),
        "source": " + ".join(source),
        "x_range_um": [x0, x1],
        "z_range_um": [z0, z1],
        "contacts": _contacts(
            np.concatenate([c, bodies[:, :3]]), np.concatenate([r, bodies[:, 3]])
        ),
        **frac,
    }
    return c, r, report


def _contacts(c: np.ndarray, r: np.ndarray) -> int:
    """Touching pairs (gap within round-off of the larger radius)."""
    from scipy.spatial import cKDTree  # only a bed needs it

    pairs = cKDTree(c).query_pairs(2 * float(np.max(r)) * (1 + 1e-9), output_type="ndarray")
    if len(pairs) == 0:
        return 0
    a, b = pairs.T
    gap = np.linalg.norm(c[a] - c[b], axis=1) - r[a] - r[b]
    return int(np.sum(gap <= 1e-9 * np.maximum(r[a], r[b])))
