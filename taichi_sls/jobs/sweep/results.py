"""The sweep's results table: ``results.csv`` (and ``results.parquet`` with pyarrow), one row per
finished case, rewritten atomically."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

from ...io.atomic import atomic_path


def _number(text: str) -> Any:
    """CSV cell -> int/float where it reads as one, else the string."""
    if text == "":
        return ""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


def read_results(path: str | Path) -> list[dict[str, Any]]:
    """Rows of a results.csv (numbers parsed; empty cells as ""); [] if it does not exist."""
    path = Path(path)
    if not path.is_file():
        return []
    with path.open(newline="") as f:
        return [
            {k: (v if k in ("id", "status", "error") else _number(v)) for k, v in r.items()}
            for r in csv.DictReader(f)
        ]


def write_results(out: Path, rows: list[dict[str, Any]], columns: list[str]) -> None:
    """Write results.csv (and results.parquet if pyarrow is importable), each atomically."""
    cols = list(columns)
    for r in rows:
        cols += [k for k in r if k not in cols]
    with atomic_path(out / "results.csv") as tmp:
        with tmp.open("w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=cols, extrasaction="ignore")
            w.writeheader()
            for r in rows:
                w.writerow({c: "" if r.get(c) is None else r[c] for c in cols})
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return
    table: dict[str, list] = {}
    for c in cols:
        vals = [r.get(c) for r in rows]
        present = [v for v in vals if v not in (None, "")]
        if present and all(isinstance(v, (int, float)) for v in present):
            table[c] = [float(v) if v not in (None, "") else None for v in vals]
        else:
            table[c] = [None if v is None else str(v) for v in vals]
    with atomic_path(out / "results.parquet") as tmp:
        pq.write_table(pa.table(table), tmp)
