"""One-line errors for bad case input: the key, the value and what is allowed."""

from __future__ import annotations

import typing
from typing import Any

from pydantic import BaseModel, ValidationError


class CaseError(ValueError):
    """A case file (or an override) is invalid. The message names key, value and what is allowed."""


_EXPECTED = {
    "float_type": "a number",
    "float_parsing": "a number",
    "int_type": "an integer",
    "int_from_float": "an integer",
    "bool_type": "true or false",
    "string_type": "a string",
    "list_type": "a list",
    "dict_type": "a table",
    "model_type": "a table",
    "model_attributes_type": "a table",
    "finite_number": "a finite number",
}


def _members(tp: Any) -> list[Any]:
    """The member types of a union (Annotated and Optional unwrapped), else [tp]."""
    while typing.get_origin(tp) is typing.Annotated:
        tp = typing.get_args(tp)[0]
    if typing.get_origin(tp) in (typing.Union, getattr(__import__("types"), "UnionType", None)):
        return [a for m in typing.get_args(tp) for a in _members(m)]
    return [tp]


def _tag(tp: Any) -> str | None:
    """The discriminator value of a body model (its ``shape`` literal), if it has one."""
    f = tp.model_fields.get("shape")
    args = typing.get_args(f.annotation) if f is not None else ()
    return args[0] if len(args) == 1 else None


def _walk(model: type[BaseModel], loc: tuple) -> tuple[str, list[Any]]:
    """The dotted key of a pydantic error location (list items as [i], union member tags
    dropped) and the types found at its end."""
    parts: list[str] = []
    types: list[Any] = [model]
    for el in loc:
        nxt: list[Any] = []
        name = None
        for tp in (m for t in types for m in _members(t)):
            origin = typing.get_origin(tp)
            if isinstance(tp, type) and issubclass(tp, BaseModel):
                if isinstance(el, str) and el in tp.model_fields:
                    nxt.append(tp.model_fields[el].annotation)
                    name = f".{el}"
                elif el == _tag(tp):  # a discriminated body: the location names its tag
                    nxt.append(tp)
                    name = name or ""
            elif origin is list and isinstance(el, int):
                nxt.append(typing.get_args(tp)[0])
                name = f"[{el}]"
            elif origin is dict and isinstance(el, str):
                nxt.append(typing.get_args(tp)[1])
                name = f".{el}"
        if name is None:  # a union member's label (float, str, ...): not part of the key
            continue
        parts.append(name)
        types = nxt
    return "".join(parts).lstrip("."), types


def _value(data: Any, loc: tuple) -> Any:
    node = data
    for el in loc:
        try:
            node = node[el]
        except (KeyError, IndexError, TypeError):
            continue  # a union member tag: not part of the data
    return node


def _allowed(err: dict) -> str:
    t, ctx = err["type"], err.get("ctx") or {}
    if t in _EXPECTED:
        return f"expected {_EXPECTED[t]}"
    if t == "literal_error":
        return "allowed values are " + ctx["expected"].replace("'", "").replace(" or ", ", ")
    if t == "greater_than":
        return f"must be > {ctx['gt']:g}"
    if t == "greater_than_equal":
        return f"must be >= {ctx['ge']:g}"
    if t == "less_than":
        return f"must be < {ctx['lt']:g}"
    if t == "less_than_equal":
        return f"must be at most {ctx['le']:g}"
    if t in ("too_short", "too_long"):
        return "expected two numbers [x, y]"
    if t == "value_error":
        return str(ctx["error"])
    return err["msg"]


def case_error(exc: ValidationError, model: type[BaseModel], data: Any) -> CaseError:
    """The first error of a validation as one line naming key, value and what is allowed."""
    errors = exc.errors()
    first = errors[0]
    ctx = first.get("ctx") or {}
    if first["type"] == "value_error" and isinstance(ctx.get("error"), CaseError):
        return ctx["error"]  # a cross-field check: its message already names the keys
    if first["type"] == "extra_forbidden":
        where, types = _walk(model, first["loc"][:-1])
        key = f"{where}.{first['loc'][-1]}".lstrip(".")
        fields = {
            f
            for t in types
            for m in _members(t)
            if isinstance(m, type) and issubclass(m, BaseModel)
            for f in m.model_fields
        }
        return CaseError(f"unknown key {key!r}; allowed here: {', '.join(sorted(fields))}")
    key = _walk(model, first["loc"])[0]
    if first["type"] == "union_tag_invalid":
        tags = ctx.get("expected_tags", "").replace("'", "")
        return CaseError(f"{key}.shape = {ctx.get('tag')!r}: allowed values are {tags}")
    # a union reports one error per member at the same key: say what any member allows
    same = [e for e in errors if _walk(model, e["loc"])[0] == key]
    allowed = " or ".join(dict.fromkeys(_allowed(e) for e in same))
    allowed = allowed.replace(" or expected ", " or ")
    return CaseError(f"{key} = {_value(data, first['loc'])!r}: {allowed}")
