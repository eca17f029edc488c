"""Case files on disk: TOML in, ``--set`` overrides, validation, TOML out, bundled cases."""

from __future__ import annotations

import copy
import tomllib
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any, TypeVar

import tomli_w
from pydantic import ValidationError

from .base_case import over_base
from .errors import CaseError, case_error
from .resolve import ResolvedCase, resolve
from .schema import Case

T = TypeVar("T")


def read_toml(path: str | Path, what: str, error: type[Exception] = CaseError) -> dict:
    """Parse a TOML file, turning a missing, unreadable, binary, non-UTF-8 or empty file, or bad
    syntax, into one line of ``error`` that names the path."""
    path = Path(path)
    if not path.is_file():
        raise error(f"{what} {str(path)!r} does not exist")
    try:
        raw = path.read_bytes()
    except OSError as e:
        raise error(f"{what} {str(path)!r}: cannot be read ({e.strerror or e})") from None
    if b"\0" in raw:  # UTF-8 text never holds a NUL byte: an image, an archive, a .npz ...
        raise error(f"{path}: a binary file, not TOML text; a {what} is UTF-8 text")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        line = raw[: e.start].count(b"\n") + 1
        raise error(
            f"{path}: not UTF-8 text (byte 0x{raw[e.start]:02x} on line {line}); save the "
            f"{what} as UTF-8"
        ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise error(f"{path}: not valid TOML: {e}") from None
    if not data:  # blank or comments only: say so, not what the first missing key would be
        raise error(f"{path}: the {what} is empty (no key and no table)")
    return data


def deep_update(base: dict, extra: dict) -> dict:
    """A copy of ``base`` with the nested dict ``extra`` merged in (lists are replaced)."""
    out = copy.deepcopy(base)
    for k, v in extra.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = deep_update(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def parse_override(text: str, what: str = "--set") -> tuple[list[str], Any]:
    """``section.key=value`` -> (key path, value); the value is read as TOML, and a bare word
    that is no TOML value is a string (``--set solver.transfer=flip``)."""
    if "=" not in text:
        raise CaseError(f"{what} {text!r}: expected section.key=value")
    path, raw = text.split("=", 1)
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    return path.strip().split("."), value


def add_set_argument(parser: Any, help: str) -> None:
    """The ``--set KEY=VALUE`` option of the command lines (an argparse parser)."""
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help=help)


def apply_override(data: dict, text: str) -> None:
    """Apply one ``section.key=value`` override to raw case data. List items: ``bodies.0.radius_um``
    or ``lasers.0.power_W``."""
    parts, value = parse_override(text)
    node: Any = data
    for i, p in enumerate(parts[:-1]):
        if isinstance(node, list):
            if not p.isdigit() or int(p) >= len(node):
                raise CaseError(f"--set {text!r}: {'.'.join(parts[: i + 1])} is no list index")
            node = node[int(p)]
        else:
            if p not in node and parts[i + 1].isdigit():
                raise CaseError(f"--set {text!r}: {'.'.join(parts[: i + 1])} is no list")
            node = node.setdefault(p, {})
            if not isinstance(node, (dict, list)):
                raise CaseError(f"--set {text!r}: {'.'.join(parts[: i + 1])} is not a table")
    last = parts[-1]
    if isinstance(node, list):
        if not last.isdigit() or int(last) >= len(node):
            raise CaseError(f"--set {text!r}: {last!r} is no list index")
        node[int(last)] = value
    else:
        node[last] = value


def validate_case(data: dict) -> Case:
    """Validate raw TOML data as a :class:`Case` (checks only: ``data`` and nothing else is
    changed, and nothing is derived yet)."""
    try:
        return Case.model_validate(data)
    except ValidationError as e:
        raise case_error(e, Case, data) from None


def case_from_dict(data: dict) -> ResolvedCase:
    """Validate raw TOML data and resolve it (config/resolve.py): the case a run takes."""
    return resolve(validate_case(data))


def resolve_files(data: dict, folder: Path) -> None:
    """Body, bed and temperature-table files named relative to the case file, made absolute."""
    tables = data.get("bodies", []) if isinstance(data.get("bodies"), list) else []
    keys = [(b, k) for b in tables if isinstance(b, dict) for k in ("vertices_file", "file")]
    if isinstance(data.get("bed"), dict):
        keys += [(data["bed"], k) for k in ("csv", "sizes_csv", "previous_layer")]
    if isinstance(data.get("thermal"), dict):
        keys.append((data["thermal"], "imposed_temperature_csv"))
    for table, key in keys:
        f = table.get(key)
        if isinstance(f, str) and not Path(f).is_absolute():
            table[key] = str((folder / f).resolve())


def read_case_file(path: Path) -> dict:
    """A case file's raw data over its ``base`` case's (base_case.py), followed from base to
    base; the bases' files made absolute (the file's own are left to the caller)."""
    return _over_bases(path, ())


def _over_bases(path: Path, seen: tuple[Path, ...]) -> dict:
    data = read_toml(path, "case file")
    if "base" not in data:
        return data
    name = data.pop("base")
    base = find_base(name, path)
    chain = (*seen, path.resolve())
    if base.resolve() in chain:
        cycle = " -> ".join(p.name for p in (*chain, base))
        raise CaseError(
            f"{path}: base = {name!r}: a cycle of bases ({cycle}); allowed: a case "
            "that does not lead back to this file"
        )
    below = _over_bases(base, chain)
    resolve_files(below, base.parent)
    if isinstance(below.get("case"), dict):
        below["case"].pop("name", None)  # a case is named by its own file
    try:
        return over_base(below, data)
    except CaseError as e:
        raise CaseError(f"{path}: {e}") from None


def find_base(name: Any, path: Path) -> Path:
    """The file a case file's ``base`` names: a path relative to the file, else a bundled case
    by name."""
    if not isinstance(name, str) or not name:
        raise CaseError(f"{path}: base = {name!r}: expected a case name or a case file's path")
    for p in (path.parent / name, path.parent / f"{name}.toml", bundled_root() / f"{name}.toml"):
        if p.is_file():
            return p
    raise CaseError(
        f"{path}: base = {name!r}: no such case file (relative to {path.parent}) or bundled case"
    )


def load_case(path: str | Path, overrides: list[str] | None = None) -> ResolvedCase:
    """Read a case file (a path, or the name of a bundled case) over its ``base``, apply
    ``--set`` overrides, validate and resolve it: the :class:`ResolvedCase` a run takes."""
    path = find_case(path)
    data = read_case_file(path)
    for o in overrides or []:
        apply_override(data, o)
    if "case" not in data or "name" not in data.get("case", {}):
        data.setdefault("case", {})["name"] = path.stem
    resolve_files(data, path.parent)
    return in_file(path, case_from_dict, data)


def in_file(path: Path, build: Callable[[dict], T], data: dict) -> T:
    """``build(data)``, its CaseError prefixed with the file the data came from (the line
    then names the file as well as the key)."""
    try:
        return build(data)
    except CaseError as e:
        raise CaseError(f"{path}: {e}") from None


def case_to_dict(case: Case) -> dict:
    """A case as plain data (None values dropped: TOML has no null; a 2D case has no walls in
    z; a side a [bed] is to fit stays unset). It loads back to the same case."""
    z_walls = {"boundary": {"front", "back"}} if case.domain.dim == 2 else None
    out = case.model_dump(exclude_none=True, exclude=z_walls)
    if case.bed is not None:
        for key in ("width_um", "height_um"):
            if key not in case.domain.model_fields_set:
                del out["domain"][key]
    return out


def case_to_toml(case: Case) -> str:
    """A case as TOML text: every default filled in; it loads back to the same case."""
    return tomli_w.dumps(case_to_dict(case))


# ---------------------------------------------------------------------------- bundled cases


def bundled_root() -> Path:
    """The folder of the case files shipped with the package (``taichi_sls/cases``)."""
    return Path(str(resources.files("taichi_sls") / "cases"))


def bundled_cases(folder: str = "") -> list[Path]:
    """The bundled case files (of a subfolder such as ``verification``), sorted by name."""
    return sorted((bundled_root() / folder).glob("*.toml"))


def bundled_case(name: str) -> Path:
    """A bundled case by name (``power25W``, ``verification/laplace``)."""
    p = bundled_root() / f"{name}.toml"
    if not p.is_file():
        names = ", ".join(q.stem for q in bundled_cases())
        raise CaseError(f"case {name!r}: no such bundled case; bundled: {names}")
    return p


def find_case(path: str | Path) -> Path:
    """A case file as given; failing that, a bundled one by name or by its path under
    ``cases/`` (so ``cases/power25W.toml`` works from any folder once installed)."""
    p = Path(path)
    if p.is_file():
        return p
    name = p.with_suffix("").as_posix()
    name = name.split("cases/", 1)[1] if "cases/" in name else name
    q = bundled_root() / f"{name}.toml"
    if q.is_file():
        return q
    raise CaseError(f"case file {str(path)!r} does not exist")
