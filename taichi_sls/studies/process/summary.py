"""What the three process sweeps say, read from their ``results.csv``: the density against the
Andrew number, the bed temperature where densification stops, and the density's change for each
uncertain input at the reference setting (:mod:`.design`)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from ...jobs.sweep.results import read_results

INITIAL = "bed.relative_density.initial"
FINAL = "bed.relative_density.final"
# a bed temperature "densifies" when its gain is at least this share of the hottest bed's gain
DENSIFIES_SHARE = 0.5


def _rows(results_csv: str | Path, ids: set[str] | None) -> list[dict[str, Any]]:
    """The table's rows, only those of ``ids`` when given (a results.csv keeps the rows of cases
    no longer swept, e.g. those of a base before its material changed)."""
    rows = read_results(results_csv)
    return rows if ids is None else [r for r in rows if r["id"] in ids]


def _done(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Complete rows with both densities, each with ``gain`` = final - initial."""
    out = []
    for r in rows:
        if r.get("status") != "complete" or r.get(FINAL) in ("", None):
            continue
        out.append({**r, "gain": float(r[FINAL]) - float(r[INITIAL])})
    return out


def energy_summary(results_csv: str | Path, ids: set[str] | None = None) -> list[dict[str, Any]]:
    """The energy sweep's complete rows by increasing Andrew number (then hatch, then the bed's
    seed where a 3D sweep draws other beds)."""
    rows = _done(_rows(results_csv, ids))
    return sorted(rows, key=lambda r: (r["andrew_J_mm2"], r["hatch_um"], r.get("seed", 0)))


def bed_summary(results_csv: str | Path, ids: set[str] | None = None) -> dict[str, Any]:
    """The bed-temperature rows by temperature and the threshold: the lowest bed temperature
    above which every bed gains at least ``DENSIFIES_SHARE`` of the hottest bed's gain (NaN when
    fewer than two rows finished)."""
    rows = sorted(_done(_rows(results_csv, ids)), key=lambda r: r["bed_C"])
    threshold = math.nan
    if len(rows) >= 2:
        top = rows[-1]["gain"]
        for r in reversed(rows):
            if top > 0 and r["gain"] >= DENSIFIES_SHARE * top:
                threshold = r["bed_C"]
            else:
                break
    return {"rows": rows, "threshold_C": threshold, "share": DENSIFIES_SHARE}


def sensitivity_summary(results_csv: str | Path, ids: set[str] | None = None) -> dict[str, Any]:
    """The reference's final density and, for each factor, the change of the density gained
    over the layer time at its two levels (gain - reference gain) and of the final density (a
    factor that moves the settled powder's density moves the start too), largest change of the
    gain first; failed levels with their error; the ``layer time`` row as the plateau check."""
    every = _rows(results_csv, ids)
    rows = _done(every)
    ref = next((r for r in rows if r["factor"] == "reference"), None)
    if ref is None:
        return {"reference": None, "factors": [], "plateau": None}
    failed: dict[str, dict[str, str]] = {}  # factor -> level -> the run's status and error
    for r in every:
        if r.get("status") not in ("complete", None) and r["factor"] not in ("reference",):
            failed.setdefault(r["factor"], {})[str(r["level"])] = f"{r['status']}: {r['error']}"
    base = float(ref[FINAL])
    factors: dict[str, dict[str, float]] = {}
    gains: dict[str, dict[str, float]] = {}  # the change of the gain: the start moves too
    plateau = None
    for r in rows:
        if r["factor"] == "reference":
            continue
        delta = float(r[FINAL]) - base
        if r["factor"] == "layer time":
            plateau = {"level": r["level"], "final": float(r[FINAL]), "change": delta}
            continue
        factors.setdefault(r["factor"], {})[str(r["level"])] = delta
        gains.setdefault(r["factor"], {})[str(r["level"])] = r["gain"] - ref["gain"]
    for k in failed:
        factors.setdefault(k, {})
        gains.setdefault(k, {})
    # largest change of the gain first: on a bed of a few tens of discs the settled packing itself
    # moves by points between draws (docs/record/sweeps.md), so the gain is what the factor does
    ordered = sorted(
        factors.items(), key=lambda kv: -max([abs(v) for v in gains[kv[0]].values()] + [0])
    )
    return {
        "reference": {"initial": float(ref[INITIAL]), "final": base, "gain": ref["gain"]},
        "factors": [
            {"factor": k, "changes": v, "gain_changes": gains[k], "failed": failed.get(k, {})}
            for k, v in ordered
            if k != "layer time"
        ],
        "plateau": plateau,
    }
