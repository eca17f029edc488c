"""A struct field's members copied from or to NumPy by one kernel, not one per member.

Taichi's ``StructField.from_numpy`` and each member field's ``to_numpy`` / ``from_numpy`` copy
member by member, each through a kernel of its own that compiles (front end and JIT) the first
time, ~25 ms each: the materials' 40 members, the checkpoint's 19 point members both ways, the
monitors' totals. One kernel copies any set of members (scalars, vectors and matrices) at
once through a float64 table, one row per element and one column per component (exact for the
f32, f64 and i32 members the solver's structs hold), with the same values as Taichi's.
"""

from collections.abc import Iterable, Mapping

import numpy as np

from taichi_sls.backend import ti

_NUMPY = {ti.f32: np.float32, ti.f64: np.float64, ti.i32: np.int32}

# (member, first column, component shape) of each member copied: a static plan of the table
Layout = tuple[tuple[str, int, tuple[int, ...]], ...]


@ti.func
def _element(shape: ti.template(), i):
    """The index of row i of a field of ``shape``, rows in C order."""
    index = ti.Vector.zero(ti.i32, ti.static(len(shape)))
    rest = i
    for d in ti.static(range(len(shape) - 1, -1, -1)):
        index[d] = rest % shape[d]
        rest //= shape[d]
    return index


@ti.kernel
def _copy(
    sf: ti.template(),
    layout: ti.template(),
    table: ti.types.ndarray(),
    into_table: ti.template(),
):
    for i in range(table.shape[0]):
        if ti.static(len(sf.shape) == 0):
            _row(sf, layout, None, table, i, into_table)
        else:
            _row(sf, layout, _element(sf.shape, i), table, i, into_table)


@ti.func
def _row(
    sf: ti.template(),
    layout: ti.template(),
    at: ti.template(),
    table: ti.template(),
    i,
    into_table: ti.template(),
):
    for k in ti.static(range(len(layout))):
        name, col, comp = ti.static(layout[k])
        if ti.static(into_table):
            _get(sf.field_dict[name], at, comp, col, table, i)
        else:
            _put(sf.field_dict[name], at, comp, col, table, i)


@ti.func
def _put(
    f: ti.template(),
    at: ti.template(),
    comp: ti.template(),
    col: ti.template(),
    table: ti.template(),
    i,
):
    if ti.static(len(comp) == 0):
        f[at] = ti.cast(table[i, col], f.dtype)
    elif ti.static(len(comp) == 1):
        for a in ti.static(range(comp[0])):
            f[at][a] = ti.cast(table[i, col + a], f.dtype)
    else:
        for a, b in ti.static(ti.ndrange(comp[0], comp[1])):
            f[at][a, b] = ti.cast(table[i, col + a * comp[1] + b], f.dtype)


@ti.func
def _get(
    f: ti.template(),
    at: ti.template(),
    comp: ti.template(),
    col: ti.template(),
    table: ti.template(),
    i,
):
    if ti.static(len(comp) == 0):
        table[i, col] = ti.cast(f[at], ti.f64)
    elif ti.static(len(comp) == 1):
        for a in ti.static(range(comp[0])):
            table[i, col + a] = ti.cast(f[at][a], ti.f64)
    else:
        for a, b in ti.static(ti.ndrange(comp[0], comp[1])):
            table[i, col + a * comp[1] + b] = ti.cast(f[at][a, b], ti.f64)


def _components(f) -> tuple[int, ...]:
    if getattr(f, "ndim", 0) == 2:
        return (f.n, f.m)
    if getattr(f, "ndim", 0) == 1:
        return (f.n,)
    return ()


def _layout(sf, keys: Iterable[str]) -> tuple[Layout, int]:
    out, col = [], 0
    for name in keys:
        comp = _components(sf.field_dict[name])
        out.append((name, col, comp))
        col += int(np.prod(comp, dtype=int))
    return tuple(out), col


def _rows(sf) -> int:
    return int(np.prod(sf.shape, dtype=int)) if sf.shape else 1


def from_numpy(sf, arrays: Mapping[str, np.ndarray]) -> None:
    """``sf.from_numpy(arrays)`` in one kernel, for the members ``arrays`` names (each of the
    member's shape: the field's, then its components')."""
    layout, width = _layout(sf, arrays.keys())
    rows = _rows(sf)
    table = np.empty((rows, width), dtype=np.float64)
    for name, col, comp in layout:
        n = int(np.prod(comp, dtype=int))
        table[:, col : col + n] = np.asarray(arrays[name], dtype=np.float64).reshape(rows, n)
    _copy(sf, layout, table, False)


def to_numpy(sf, keys: Iterable[str] | None = None) -> dict[str, np.ndarray]:
    """``sf.to_numpy()`` in one kernel (every member, or those of ``keys``): the same dtypes
    and shapes as Taichi's."""
    layout, width = _layout(sf, sf.keys if keys is None else keys)
    table = np.empty((_rows(sf), width), dtype=np.float64)
    _copy(sf, layout, table, True)
    return {
        name: table[:, col : col + int(np.prod(comp, dtype=int))]
        .reshape(tuple(sf.shape) + comp)
        .astype(_NUMPY[sf.field_dict[name].dtype])
        for name, col, comp in layout
    }
