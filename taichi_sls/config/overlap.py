"""Overlapping [[bodies]]: the scene gives an overlap's points to the first body that holds them
(solver/scene.py), so the later body starts short of them, which a case rarely means. Two plain
discs that overlap are an error unless ``contact.allow_overlap`` says they are meant to (a bed's
CSV discs are checked by config/bed.py, with its own tolerance)."""

from __future__ import annotations

import math
from collections.abc import Sequence

from .errors import CaseError

ROUND_OFF = 1e-9  # of the larger radius: discs given as touching may overlap by round-off


def disc_overlaps(bodies: Sequence) -> list[tuple[int, int, float]]:
    """(i, j, depth in um) for every pair i < j of plain discs (no shape mode) that overlap:
    depth = r_i + r_j - |c_i - c_j| beyond round-off."""
    discs = [(i, b) for i, b in enumerate(bodies) if b.shape == "disc" and b.perturbation == 0.0]
    out = []
    for k, (i, a) in enumerate(discs):
        for j, b in discs[k + 1 :]:
            depth = a.radius_um + b.radius_um - math.dist(a.center_um, b.center_um)
            if depth > ROUND_OFF * max(a.radius_um, b.radius_um):
                out.append((i, j, depth))
    return out


def check_overlaps(bodies: Sequence, allowed: bool) -> None:
    """A clear error for the first pair of overlapping discs, unless ``allowed``."""
    if allowed:
        return
    found = disc_overlaps(bodies)
    if found:
        i, j, depth = found[0]
        raise CaseError(
            f"bodies[{i}] and bodies[{j}]: the discs overlap by {depth:.4g} um (the overlap's "
            f"points would go to bodies[{i}]); allowed: touching or apart, or set "
            "contact.allow_overlap = true if they are meant to overlap"
        )
