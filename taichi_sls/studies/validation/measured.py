"""The measured PA12 data of the package (``taichi_sls/data/pa12/``, its README.md: sources and
caveats; the curves are digitised), read as typed records in which every point carries its
source. The source of a file whose rows have no ``source`` column is the one ``sources.toml``
names for it (for the hot-stage pairs, for the series).

Units are those of the files' column names: times in s, temperatures in C, radii in um, a/R
dimensionless, each density or porosity with its ``unit``.
"""

from __future__ import annotations

import csv
import math
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from ..process.measured import MeasuredDataError

NECK_FILE = "pulse_pair_R125_neck.csv"
TEMPERATURE_FILE = "pulse_pair_R125_temperature.csv"
HOT_STAGE_FILE = "hot_stage_pairs.csv"
DENSITY_FILE = "part_and_powder_density.csv"
SOURCES_FILE = "sources.toml"

# the pulsed pair's conditions (README.md): radius and chamber temperature
PULSE_PAIR_RADIUS_UM = 125.0
PULSE_PAIR_CHAMBER_C = 155.0

__all__ = [
    "DensityRecord",
    "MeasuredDataError",
    "NeckPoint",
    "TemperaturePoint",
    "data_folder",
    "load_densities",
    "load_hot_stage",
    "load_pulse_neck",
    "load_pulse_temperature",
]


@dataclass(frozen=True)
class NeckPoint:
    """One measured a/R: ``series`` names the pair (the file's stem for the pulsed pair)."""

    series: str
    radius_um: float
    t_s: float
    neck_over_radius: float
    source: str
    digitised: str


@dataclass(frozen=True)
class TemperaturePoint:
    t_s: float
    T_C: float
    source: str
    digitised: str


@dataclass(frozen=True)
class DensityRecord:
    quantity: str
    value: float
    unit: str
    method: str
    specimen: str
    source: str


def data_folder() -> Path:
    """The package's folder of measured PA12 data."""
    return Path(str(resources.files("taichi_sls") / "data" / "pa12"))


def _rows(path: Path, columns: tuple[str, ...]) -> list[tuple[str, dict[str, str]]]:
    """The file's rows under its header (lines starting with # skipped), each with where it is
    (file and line) for messages; every column named must be in the header."""
    lines = path.read_text().splitlines()
    body = [(i, line) for i, line in enumerate(lines, start=1) if not line.startswith("#")]
    if not body:
        raise MeasuredDataError(f"{path}: no header; expected columns {', '.join(columns)}")
    header_no = body[0][0]
    reader = csv.DictReader([line for _, line in body])
    missing = [c for c in columns if c not in (reader.fieldnames or [])]
    if missing:
        raise MeasuredDataError(
            f"{path} line {header_no}: no column {missing[0]!r}; needed: {', '.join(columns)}"
        )
    out = []
    for (no, _), row in zip(body[1:], reader, strict=True):
        where = f"{path.name} line {no}"
        if None in row or None in row.values():
            raise MeasuredDataError(f"{where}: the row's fields do not match the header")
        out.append((where, row))
    if not out:
        raise MeasuredDataError(f"{path}: no data rows")
    return out


def _number(row: dict[str, str], key: str, where: str) -> float:
    text = (row.get(key) or "").strip()
    try:
        value = float(text)
    except ValueError:
        raise MeasuredDataError(f"{where}: {key} = {text!r}: expected a number") from None
    if not math.isfinite(value):
        raise MeasuredDataError(f"{where}: {key} = {text!r}: expected a finite number")
    return value


def _sources(folder: Path) -> dict:
    path = folder / SOURCES_FILE
    with path.open("rb") as f:
        return tomllib.load(f)


def _file_source(folder: Path, name: str) -> tuple[str, str]:
    entry = _sources(folder).get(name)
    if not isinstance(entry, dict) or not str(entry.get("source", "")).strip():
        raise MeasuredDataError(f"{folder / SOURCES_FILE}: no source for {name!r}")
    return str(entry["source"]), str(entry.get("digitised", ""))


def _check_times(points: list, where: str) -> None:
    times = [p.t_s for p in points]
    if any(t < 0.0 for t in times) or any(b <= a for a, b in zip(times, times[1:], strict=False)):
        raise MeasuredDataError(f"{where}: t_s must be >= 0 and increasing")


def load_pulse_neck(folder: str | Path | None = None) -> list[NeckPoint]:
    """The pulsed pair's measured a/R against time (0 <= a/R, times increasing)."""
    folder = Path(folder) if folder is not None else data_folder()
    source, digitised = _file_source(folder, NECK_FILE)
    points = []
    for where, row in _rows(folder / NECK_FILE, ("t_s", "neck_over_radius")):
        a = _number(row, "neck_over_radius", where)
        if a < 0.0:
            raise MeasuredDataError(f"{where}: neck_over_radius = {a}: must be >= 0")
        points.append(
            NeckPoint(
                series=Path(NECK_FILE).stem,
                radius_um=PULSE_PAIR_RADIUS_UM,
                t_s=_number(row, "t_s", where),
                neck_over_radius=a,
                source=source,
                digitised=digitised,
            )
        )
    _check_times(points, NECK_FILE)
    return points


def load_pulse_temperature(folder: str | Path | None = None) -> list[TemperaturePoint]:
    """The pulsed pair's measured temperature against time (C; times increasing)."""
    folder = Path(folder) if folder is not None else data_folder()
    source, digitised = _file_source(folder, TEMPERATURE_FILE)
    points = []
    for where, row in _rows(folder / TEMPERATURE_FILE, ("t_s", "T_C")):
        T = _number(row, "T_C", where)
        if T <= -273.15:
            raise MeasuredDataError(f"{where}: T_C = {T}: must be above absolute zero")
        points.append(TemperaturePoint(_number(row, "t_s", where), T, source, digitised))
    _check_times(points, TEMPERATURE_FILE)
    return points


def load_hot_stage(folder: str | Path | None = None) -> dict[str, list[NeckPoint]]:
    """The hot-stage pairs' a/R by series (times increasing within each); each series takes the
    source that ``sources.toml`` names for the longest key its name starts with."""
    folder = Path(folder) if folder is not None else data_folder()
    table = _sources(folder).get(HOT_STAGE_FILE, {}).get("series", {})
    keys = sorted(table, key=len, reverse=True)
    series: dict[str, list[NeckPoint]] = {}
    columns = ("series", "radius_um", "t_s", "neck_over_radius")
    for where, row in _rows(folder / HOT_STAGE_FILE, columns):
        name = row["series"].strip()
        key = next((k for k in keys if name.startswith(k)), None)
        if key is None:
            raise MeasuredDataError(
                f"{where}: series {name!r} has no source in {SOURCES_FILE}; "
                f"its name must start with one of {', '.join(keys) or '(none)'}"
            )
        R = _number(row, "radius_um", where)
        a = _number(row, "neck_over_radius", where)
        if R <= 0.0 or a < 0.0:
            raise MeasuredDataError(f"{where}: radius_um > 0 and neck_over_radius >= 0 needed")
        series.setdefault(name, []).append(
            NeckPoint(
                name,
                R,
                _number(row, "t_s", where),
                a,
                str(table[key]["source"]),
                str(table[key].get("digitised", "")),
            )
        )
    for name, points in series.items():
        if len({p.radius_um for p in points}) != 1:
            raise MeasuredDataError(f"{HOT_STAGE_FILE}: series {name!r} has more than one radius")
        _check_times(points, f"{HOT_STAGE_FILE} series {name!r}")
    return series


def load_densities(folder: str | Path | None = None) -> list[DensityRecord]:
    """The measured part and powder densities and porosities, each row with its own source."""
    folder = Path(folder) if folder is not None else data_folder()
    columns = ("quantity", "value", "unit", "method", "specimen", "source")
    records = []
    for where, row in _rows(folder / DENSITY_FILE, columns):
        for key in ("quantity", "unit", "source"):
            if not (row.get(key) or "").strip():
                raise MeasuredDataError(f"{where}: {key} is empty; every row names its {key}")
        value = _number(row, "value", where)
        if value <= 0.0:
            raise MeasuredDataError(f"{where}: value = {value}: must be > 0")
        records.append(
            DensityRecord(
                quantity=row["quantity"].strip(),
                value=value,
                unit=row["unit"].strip(),
                method=row["method"].strip(),
                specimen=row["specimen"].strip(),
                source=row["source"].strip(),
            )
        )
    return records
