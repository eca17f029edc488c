"""A bed's CSV files (docs/record/beds.md): their columns read with one clear error per bad row,
and a CSV bed's particles checked (discs in 2D, spheres in 3D: the dimension is the domain's).

A CSV bed is a previous layer as measured or exported: it is checked (rows, overlaps, support,
domain) and the generator, if asked for particles too, deposits them on top of it. A floating
particle in a CSV bed (touching neither the plate nor a lower particle) is an error: gravity
would drop it at the start, and the contacts are found once, on the seeded points.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .errors import CaseError


def read_columns(
    path: str, key: str, columns: tuple[str, ...], positive_last: bool = True
) -> tuple[np.ndarray, list[int]]:
    """The named columns of a CSV file as an (n, len(columns)) array, with each row's line;
    ``positive_last``: the last column must be > 0 (a radius or a diameter)."""
    rows, lines, header = [], [], None
    for no, raw in enumerate(Path(path).read_text().splitlines(), start=1):
        text = raw.split("#", 1)[0].strip()
        if not text:
            continue
        cells = [c.strip() for c in text.split(",")]
        if header is None:
            missing = [c for c in columns if c not in cells]
            if missing:
                raise CaseError(
                    f"{key} = {path!r} line {no}: header {text!r} lacks {', '.join(missing)}; "
                    f"expected a header row naming the columns {', '.join(columns)}"
                )
            header = [cells.index(c) for c in columns]
            width = len(cells)
            continue
        if len(cells) != width:
            raise CaseError(
                f"{key} = {path!r} line {no}: {len(cells)} fields, the header has {width}"
            )
        try:
            values = [float(cells[i]) for i in header]
        except ValueError:
            raise CaseError(
                f"{key} = {path!r} line {no}: {text!r}: {', '.join(columns)} must be numbers"
            ) from None
        if not all(math.isfinite(v) for v in values) or (positive_last and values[-1] <= 0):
            allowed = f" and {columns[-1]} > 0" if positive_last else ""
            raise CaseError(
                f"{key} = {path!r} line {no}: {text!r}: finite numbers{allowed} are allowed"
            )
        rows.append(values)
        lines.append(no)
    if not rows:
        raise CaseError(f"{key} = {path!r}: no data rows; expected {', '.join(columns)} rows")
    return np.array(rows), lines


def check_csv_rows(
    path: str, tol: float, rows: np.ndarray, lines: list[int], old: np.ndarray, box
) -> None:
    """The particles of the bed CSV at ``path`` (rows: centre coordinates then radius, um;
    discs in 2D, spheres in 3D), checked to within ``tol`` (bed.overlap_tolerance_um): inside
    the domain ``box`` (its extents; None: sized to the bed), overlapping neither each other
    nor the earlier body particles ``old`` (rows of the same columns), and each supported by
    the plate or a lower particle."""
    key = f"bed.csv = {path!r}"
    dim = len(box)
    noun = "disc" if dim == 2 else "sphere"
    c, r = rows[:, :dim], rows[:, dim]
    hi = np.array([math.inf if s is None else s for s in box])
    out = np.any((c - r[:, None] < -tol) | (c + r[:, None] > hi + tol), axis=1)
    if out.any():
        k = int(np.argmax(out))
        at = ", ".join(f"{v:g}" for v in c[k])
        extent = " x ".join(f"0..{v:g}" for v in hi)
        names = "domain.width_um, domain.height_um" + (", domain.depth_um" if dim == 3 else "")
        raise CaseError(
            f"{key} line {lines[k]}: the {noun} at ({at}) um of radius {r[k]:g} um lies outside "
            f"the domain {extent} um ({names}; y = 0 is the plate)"
        )
    ac, ar = np.concatenate([c, old[:, :dim]]), np.concatenate([r, old[:, dim]])
    n = len(r)
    gap = np.linalg.norm(c[:, None] - ac[None], axis=2) - (r[:, None] + ar)
    gap[np.arange(n), np.arange(n)] = np.inf
    earlier = np.arange(len(ar))[None, :] < np.arange(n)[:, None]
    earlier[:, n:] = True  # the body particles come before every row
    bad = np.nonzero(((gap < -tol) & earlier).any(axis=1))[0]
    if len(bad):  # the first row that overlaps a particle before it
        i = int(bad[0])
        j = int(np.argmin(np.where(earlier[i], gap[i], np.inf)))
        other = f"line {lines[j]}" if j < n else f"{noun} body {j - n} of [[bodies]]"
        raise CaseError(
            f"{key} line {lines[i]}: the {noun} overlaps {other} by {-gap[i, j]:.4g} um; at "
            f"most bed.overlap_tolerance_um = {tol} is allowed"
        )
    below = ac[None, :, 1] < c[:, None, 1]
    supported = (c[:, 1] - r <= tol) | ((gap <= tol) & below).any(axis=1)
    if not supported.all():
        k = int(np.argmin(supported))
        at = ", ".join(f"{v:g}" for v in c[k])
        raise CaseError(
            f"{key} line {lines[k]}: the {noun} at ({at}) um floats: it touches neither the "
            f"plate nor a lower {noun} (within bed.overlap_tolerance_um = {tol}); floating "
            "particles are not allowed"
        )
