"""Sweep files: the grid of overrides, explicit cases, stable ids (see :mod:`.runner` for the
file format)."""

from __future__ import annotations

import hashlib
import itertools
import json
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import tomli_w

from ...config import CaseError, read_toml
from ...config.loading import find_case, parse_override

IMAGE_KEYS = ("output.png", "output.gif")
_SWEEP_KEYS = {"name", "base", "collect", "set"}


class SweepError(ValueError):
    """The sweep file is invalid; the message names the key and what is allowed."""


@dataclass
class SweepCase:
    id: str
    overrides: list[str]  # every override, ``set`` included, in application order
    params: dict[str, Any]  # the swept keys of this case -> values (the CSV columns)


@dataclass
class Sweep:
    name: str
    base: Path  # resolved, absolute
    base_text: str  # as written (part of the ids)
    collect: list[str]
    keys: list[str]  # every swept key, in order of first appearance
    cases: list[SweepCase] = field(default_factory=list)

    @property
    def quantities(self) -> list[str]:
        """Collected columns apart from status and error (which every row has)."""
        return [c for c in self.collect if c not in ("status", "error", "id", "wall_s")]

    @property
    def columns(self) -> list[str]:
        return ["id", *self.keys, *self.quantities, "status", "error", "wall_s"]


def toml_value(v: Any) -> str:
    """A Python value as TOML value syntax (the right-hand side of an override)."""
    if not isinstance(v, (bool, int, float, str, list)):
        raise SweepError(f"value {v!r}: only numbers, booleans, strings and lists can be swept")
    return tomli_w.dumps({"v": v}).split("=", 1)[1].strip().replace("\n", " ")


def case_id(base_text: str, overrides: list[str]) -> str:
    """Stable id of a case: a short hash of its base (as written) and sorted overrides."""
    blob = json.dumps([base_text, sorted(overrides)], separators=(",", ":"))
    return hashlib.sha1(blob.encode()).hexdigest()[:10]


def _resolve_base(text: str, sweep_path: Path) -> Path:
    p = Path(text).expanduser()
    if p.is_absolute():
        tried = [p]
    else:
        folder = sweep_path.resolve().parent
        tried = [folder / p, folder.parent / p, Path.cwd() / p]
    for t in tried:
        if t.is_file():
            return t.resolve()
    try:
        return find_case(text).resolve()
    except CaseError:
        pass
    raise SweepError(f"sweep.base = {text!r}: no such file; tried {', '.join(map(str, tried))}")


def _split_override(text: str, where: str) -> tuple[str, str]:
    try:
        parts, _ = parse_override(text, where)
    except CaseError as e:
        raise SweepError(str(e)) from None
    return ".".join(parts), text.split("=", 1)[1].strip()


def find_sweep(path: str | Path) -> Path:
    """A sweep file as given, else a bundled one by name (``paper``, ``sweeps/paper.toml``)."""
    p = Path(path)
    if p.is_file():
        return p
    q = Path(str(resources.files("taichi_sls") / "sweeps")) / f"{p.with_suffix('').name}.toml"
    return q if q.is_file() else p


def _axis(name: str, values: Any) -> list[dict[str, Any]]:
    """One grid axis as a list of {key: value} settings."""
    if not isinstance(values, list) or not values:
        raise SweepError(f"grid.{name!r} = {values!r}: expected a non-empty list")
    if all(isinstance(v, dict) for v in values):
        return [dict(v) for v in values]
    if any(isinstance(v, dict) for v in values):
        raise SweepError(f"grid.{name!r}: mixes tables and values")
    return [{name: v} for v in values]


def load_sweep(path: str | Path, extra_set: list[str] | None = None) -> Sweep:
    """Read and check a sweep file; ``extra_set`` overrides apply to every case after ``set``."""
    path = find_sweep(path)
    data = read_toml(path, "sweep file", SweepError)
    unknown = sorted(set(data) - {"sweep", "grid", "cases"})
    if unknown:
        raise SweepError(f"unknown table {unknown[0]!r}; allowed: sweep, grid, cases")
    head = data.get("sweep", {})
    unknown = sorted(set(head) - _SWEEP_KEYS)
    if unknown:
        raise SweepError(
            f"unknown key sweep.{unknown[0]}; allowed: {', '.join(sorted(_SWEEP_KEYS))}"
        )
    if "base" not in head:
        raise SweepError("sweep.base: required (the case file every run starts from)")
    base_text = str(head["base"])
    base = _resolve_base(base_text, path)
    collect = head.get("collect", ["T_peak_C", "contact_line_um", "neck_span_um", "status"])
    if not isinstance(collect, list) or not all(isinstance(c, str) for c in collect):
        raise SweepError(f"sweep.collect = {collect!r}: expected a list of names")
    common_list = list(head.get("set", [])) + list(extra_set or [])
    common: dict[str, str] = {k: "false" for k in IMAGE_KEYS}
    for text in common_list:
        k, v = _split_override(str(text), "sweep.set")
        common[k] = v

    grid = data.get("grid", {})
    explicit = data.get("cases", [])
    if not isinstance(explicit, list) or not all(isinstance(c, dict) for c in explicit):
        raise SweepError("cases: expected [[cases]] tables of key = value")
    settings: list[dict[str, Any]] = []
    if grid:
        axes = [_axis(name, vals) for name, vals in grid.items()]
        for combo in itertools.product(*axes):
            merged: dict[str, Any] = {}
            for part in combo:
                merged.update(part)
            settings.append(merged)
    settings += [dict(c) for c in explicit]
    if not settings:
        settings = [{}]  # the base case alone (with ``set``)

    sweep = Sweep(
        name=str(head.get("name", path.stem)),
        base=base,
        base_text=base_text,
        collect=list(collect),
        keys=[],
    )
    seen: set[str] = set()
    for s in settings:
        ov = dict(common)
        for k, v in s.items():
            if isinstance(v, dict):
                raise SweepError(f"{k!r} = {v!r}: expected a value, not a table")
            ov[k] = toml_value(v)
            if k not in sweep.keys:
                sweep.keys.append(k)
        overrides = [f"{k}={v}" for k, v in ov.items()]
        cid = case_id(base_text, overrides)
        if cid not in seen:
            seen.add(cid)
            sweep.cases.append(SweepCase(cid, overrides, dict(s)))
    return sweep
