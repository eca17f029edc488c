"""``contacts.csv``: one row per contact of a bed run (jobs/bed_outcome.py), rewritten
atomically at every output frame so that it is always valid and a resumed run can continue it.
Lengths in um, times in s; melted_through, refrozen and fused are 0 or 1; an empty neck_melt_um
is a contact that never melted. A 3D bed's rows carry z_um after y_um."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import Any

from .atomic import atomic_write_text
from .series import fmt_cell

COLUMNS = (
    "body_a",
    "body_b",
    "x_um",
    "y_um",
    "neck_initial_um",
    "neck_melt_um",
    "melt_end_s",
    "neck_final_um",
    "neck_region_melted_fraction",
    "melted_through",
    "refrozen",
    "fused",
)
INTEGER = {"body_a", "body_b", "melted_through", "refrozen", "fused"}


def write_contacts(path: Path, rows: list[dict[str, Any]]) -> None:
    """Write the rows (dicts with every column of COLUMNS) as CSV; NaN as an empty cell."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    columns = COLUMNS if not rows or "z_um" not in rows[0] else (*COLUMNS[:4], "z_um", *COLUMNS[4:])
    w.writerow(columns)
    for r in rows:
        cells = []
        for c in columns:
            v = r[c]
            finite = not isinstance(v, float) or math.isfinite(v)
            cells.append(fmt_cell(v) if finite else "")
        w.writerow(cells)
    atomic_write_text(path, buf.getvalue())


def read_contacts(path: Path) -> list[dict[str, float]]:
    """The rows of a contacts table: integers as int, other cells as float (empty: NaN)."""
    with Path(path).open(newline="") as f:
        return [
            {k: (int(v) if k in INTEGER else float(v) if v else math.nan) for k, v in row.items()}
            for row in csv.DictReader(f)
        ]
