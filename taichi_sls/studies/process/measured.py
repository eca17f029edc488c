"""Published PA12 part densities, each with its source: the package's
``studies/references/data/pa12_density_energy.csv`` (docs/record/pa12_process.md, "Density against
energy density"). Columns: ``source`` (author or document), ``where`` (table, figure, line),
``kind`` (how the value was obtained: ``table``, ``text``, ``figure (digitised)``, ``data sheet``
..., any text naming it), ``material``, ``process``, ``energy_density_J_mm2`` (Andrew number
P / (v h); empty where the source gives none), ``density_g_cm3`` and ``relative_to_g_cm3`` (the
dense reference the relative density divides by), ``note``."""

from __future__ import annotations

import csv
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

COLUMNS = (
    "source",
    "where",
    "kind",
    "material",
    "process",
    "energy_density_J_mm2",
    "density_g_cm3",
    "relative_to_g_cm3",
    "note",
)
REQUIRED_TEXT = ("source", "where", "kind")


class MeasuredDataError(ValueError):
    """A row of the measured-density file is incomplete or unphysical; the message names it."""


@dataclass(frozen=True)
class MeasuredPoint:
    source: str
    where: str
    kind: str
    material: str
    process: str
    energy_J_mm2: float | None  # None: the source gives no energy density
    density_g_cm3: float
    relative_to_g_cm3: float
    note: str

    @property
    def relative_density(self) -> float:
        return self.density_g_cm3 / self.relative_to_g_cm3

    @property
    def label(self) -> str:
        """The source, short: the text before its first parenthesis."""
        return self.source.split("(")[0].strip()


def default_path() -> Path:
    return Path(str(resources.files("taichi_sls.studies.references") / "data")) / (
        "pa12_density_energy.csv"
    )


def _number(row: dict[str, str], key: str, where: str, allow_empty: bool = False) -> float | None:
    text = (row.get(key) or "").strip()
    if not text and allow_empty:
        return None
    try:
        return float(text)
    except ValueError:
        raise MeasuredDataError(f"{where}: {key} = {text!r}: expected a number") from None


def load_measured(path: str | Path | None = None) -> list[MeasuredPoint]:
    """Every row of the file, checked: the source, where and kind named; 0 < density <=
    relative_to (g/cm^3); an energy density empty or >= 0."""
    path = Path(path) if path is not None else default_path()
    with path.open(newline="") as f:
        reader = csv.DictReader(f)
        missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            raise MeasuredDataError(
                f"{path}: no column {missing[0]!r}; needed: {', '.join(COLUMNS)}"
            )
        points = []
        for i, row in enumerate(reader, start=2):
            where = f"{path.name} line {i}"
            if None in row or None in row.values():
                raise MeasuredDataError(
                    f"{where}: {len(row) - (None in row)} columns expected, the row has another "
                    "number of fields (a comma inside an unquoted field?)"
                )
            for key in REQUIRED_TEXT:
                if not (row.get(key) or "").strip():
                    raise MeasuredDataError(f"{where}: {key} is empty; every point names its {key}")
            rho = _number(row, "density_g_cm3", where)
            ref = _number(row, "relative_to_g_cm3", where)
            if not 0.0 < rho <= ref:
                raise MeasuredDataError(
                    f"{where}: density_g_cm3 = {rho}: must lie in (0, relative_to_g_cm3 = {ref}]"
                )
            energy = _number(row, "energy_density_J_mm2", where, allow_empty=True)
            if energy is not None and energy < 0.0:
                raise MeasuredDataError(f"{where}: energy_density_J_mm2 = {energy}: must be >= 0")
            points.append(
                MeasuredPoint(
                    source=row["source"].strip(),
                    where=row["where"].strip(),
                    kind=row["kind"].strip(),
                    material=row["material"].strip(),
                    process=row["process"].strip(),
                    energy_J_mm2=energy,
                    density_g_cm3=rho,
                    relative_to_g_cm3=ref,
                    note=row["note"].strip(),
                )
            )
    return points
