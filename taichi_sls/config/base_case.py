"""A case file's ``base``: another case whose keys it starts from, its own keys over them.

Tables merge key by key, at any depth. A list (``[[bodies]]``, ``[[lasers]]``) given whole
replaces the base's list; a table of list indices (``[lasers.0]``, as ``--set lasers.0.power_W``
names an item) changes those items of the base's list, key by key. The base's ``case.name`` is
not inherited: a case is named by its own file (or its own ``case.name``)."""

from __future__ import annotations

import copy
from typing import Any

from .errors import CaseError


def over_base(base: dict, own: dict, prefix: str = "") -> dict:
    """``own`` merged over a copy of ``base`` (the rules above); ``prefix``: the key path of
    these tables, for the errors."""
    out = copy.deepcopy(base)
    for k, v in own.items():
        key = f"{prefix}{k}"
        old = out.get(k)
        if isinstance(v, dict) and isinstance(old, dict):
            out[k] = over_base(old, v, f"{key}.")
        elif isinstance(v, dict) and isinstance(old, list) and v and all(i.isdigit() for i in v):
            out[k] = _by_index(old, v, key)
        else:
            out[k] = copy.deepcopy(v)
    return out


def _by_index(items: list, changes: dict[str, Any], key: str) -> list:
    out = copy.deepcopy(items)
    for i, change in changes.items():
        n = int(i)
        if n >= len(out):
            raise CaseError(
                f"{key}.{i}: no such item; the base's {key} has {len(out)} (allowed: 0 to "
                f"{len(out) - 1}, or the whole list)"
            )
        if isinstance(change, dict) and isinstance(out[n], dict):
            out[n] = over_base(out[n], change, f"{key}.{i}.")
        else:
            out[n] = copy.deepcopy(change)
    return out
