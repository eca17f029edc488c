"""Bundled materials a case names instead of writing every value: ``[materials.NAME] preset =
"pa12_process"``. Each preset is one TOML file of ``taichi_sls/materials``, the single source of
its values: every entry holds the case key, its value, the published range and the source it
was read from (docs/record/pa12_process.md renders the table from it; a test keeps the two equal).
Keys written beside ``preset`` in the case override the preset's."""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

from .errors import CaseError

COLUMNS = ("value", "range", "source", "note")


def presets_folder() -> Path:
    """The folder of the bundled material files (``taichi_sls/materials``)."""
    return Path(str(resources.files("taichi_sls") / "materials"))


def preset_names() -> list[str]:
    """The names of the bundled materials, sorted."""
    return sorted(p.stem for p in presets_folder().glob("*.toml"))


def read_preset(name: str) -> dict[str, Any]:
    """The whole preset file: ``material`` (case key -> entry), ``process`` (keys of other
    tables a case using it should set, e.g. ``lasers.absorptivity``) and ``description``."""
    path = presets_folder() / f"{name}.toml"
    with path.open("rb") as f:
        return tomllib.load(f)


def preset_values(name: str) -> dict[str, Any]:
    """The material keys of a preset as a case's ``[materials.NAME]`` table (dotted keys such as
    ``crystallization_kinetics.n`` become nested tables)."""
    out: dict[str, Any] = {}
    for key, entry in read_preset(name)["material"].items():
        node = out
        *parents, last = key.split(".")
        for p in parents:
            node = node.setdefault(p, {})
        node[last] = entry["value"]
    return out


def expand_presets(data: Any) -> Any:
    """Raw case data with every ``[materials.NAME]`` that names a preset filled in from it, the
    case's own keys over the preset's (``preset`` stays, so the resolved case says where its
    values came from and loads back to the same material)."""
    mats = data.get("materials") if isinstance(data, dict) else None
    if not isinstance(mats, dict):
        return data
    out = dict(data)
    out["materials"] = {}
    for name, table in mats.items():
        # None: a dumped material without one (model_dump keeps the unset key)
        if isinstance(table, dict) and table.get("preset") is not None:
            preset = table["preset"]
            if not isinstance(preset, str) or preset not in preset_names():
                raise CaseError(
                    f"materials.{name}.preset = {preset!r}: no such bundled material; "
                    f"allowed values are {', '.join(preset_names())}"
                )
            table = _merge(preset_values(preset), table)
        out["materials"][name] = table
    return out


def _merge(base: dict, extra: dict) -> dict:
    merged = dict(base)
    for k, v in extra.items():
        both = isinstance(v, dict) and isinstance(base.get(k), dict)
        merged[k] = _merge(base[k], v) if both else v
    return merged


def _cell(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    return str(v).replace("|", "\\|")


def preset_table(name: str) -> str:
    """The preset as a markdown table: the case key, its value, the published range, the source
    and a note (docs/record/pa12_process.md)."""
    data = read_preset(name)
    rows = [
        "| Case key | Value | Published range | Source | Note |",
        "| --- | --- | --- | --- | --- |",
    ]
    for section in ("material", "process"):
        for key, e in data[section].items():
            shown = key if section == "process" else f"materials.NAME.{key}"
            cells = [f"`{shown}`", *(_cell(e.get(c, "")) for c in COLUMNS)]
            rows.append("| " + " | ".join(cells) + " |")
    return "\n".join(rows) + "\n"
