"""Random sequential deposition with rolling, in the dimension of the ranges it is given: one
lateral range (x), discs in 2D (deposition_discs.py); two (x and z), spheres in 3D
(deposition_spheres.py). The two algorithms differ (a disc rolls over one disc to rest on two,
a sphere over one or two to rest on three) and stand behind this one call; the particle sizes
are drawn here for both.

Lengths in any one unit (the case reads um).
"""

from __future__ import annotations

import numpy as np

from .deposition_discs import deposit_discs
from .deposition_spheres import Lateral, deposit_spheres

TRUNCATE_SIGMA = 3.0  # log-normal diameters are redrawn beyond this many sigma of ln d


def lognormal_diameters(
    rng: np.random.Generator, n: int, median: float, spread: float
) -> np.ndarray:
    """n diameters with ln d normal about ln(median) with standard deviation ``spread`` (the
    geometric standard deviation is exp(spread); 0: all equal), truncated at TRUNCATE_SIGMA."""
    z = rng.standard_normal(n)
    while (bad := np.abs(z) > TRUNCATE_SIGMA).any():
        z[bad] = rng.standard_normal(int(bad.sum()))
    return median * np.exp(spread * z)


def deposit(
    radii: np.ndarray,
    ranges: list[tuple[float, float]],
    rng: np.random.Generator,
    existing: np.ndarray | None = None,
    lateral: Lateral = "walls",
) -> np.ndarray:
    """Drop particles of the given radii, in order, over the lateral ``ranges`` (x: discs; x and
    z: spheres) onto the plate (y = 0) and onto the ``existing`` particles (rows of centre
    coordinates then radius: a previous layer). ``lateral``: side walls at the ranges' ends, or
    (3D only) periodic. Returns the new centres, (n, dim)."""
    dim = len(ranges) + 1
    if dim not in (2, 3):
        raise ValueError(f"deposition over {len(ranges)} lateral ranges; 1 (2D) or 2 (3D) allowed")
    old = np.empty((0, dim + 1)) if existing is None else np.asarray(existing, float)
    if dim == 2:
        if lateral != "walls":
            raise ValueError(f"lateral = {lateral!r}: a 2D deposition has side walls only")
        return deposit_discs(radii, ranges[0], rng, old.reshape(-1, 3))
    return deposit_spheres(radii, ranges[0], ranges[1], rng, lateral, old.reshape(-1, 4))
