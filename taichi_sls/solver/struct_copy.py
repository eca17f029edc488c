"""Struct fields' members copied from or to NumPy by one kernel, not one per member.

Taichi's ``StructField.from_numpy`` and each member field's ``to_numpy`` / ``from_numpy`` copy
member by member, each through a kernel of its own that compiles (front end and JIT) the first
time (docs/record/compile.md): the materials' 40 members, the checkpoint's 19 point members
both ways, the monitors' totals. One kernel copies any set of members (scalars, vectors and
matrices) at once through a float64 table, one row per element and one column per component
(exact for the f32, f64 and i32 members the solver's structs hold), with the same values as
Taichi's.

Which field, which members and which way are chosen at run time (a column per member, or -1),
so the struct fields of one :class:`CopyGroup` (a run's state: :func:`share_kernel`) compile
one kernel for all their copies; a kernel's compilation costs tens of ms whatever its size
(docs/record/compile.md). A field's copies range over the members :func:`copies_among` names, or
all.
"""

from collections.abc import Iterable, Mapping

import numpy as np

from taichi_sls.backend import ti

_NUMPY = {ti.f32: np.float32, ti.f64: np.float64, ti.i32: np.int32}

# (member, component shape) of each member a copy may take: a static plan of the kernel
Layout = tuple[tuple[str, tuple[int, ...]], ...]


@ti.func
def _element(shape: ti.template(), i):
    """The index of row i of a field of ``shape``, rows in C order."""
    index = ti.Vector.zero(ti.i32, ti.static(len(shape)))
    rest = i
    for d in ti.static(range(len(shape) - 1, -1, -1)):
        index[d] = rest % shape[d]
        rest //= shape[d]
    return index


@ti.data_oriented
class CopyGroup:
    """Struct fields that share one copy kernel, each with its static layout."""

    def __init__(self, fields, every_member: bool = False) -> None:
        self.fields = tuple(fields)
        self.layouts = tuple(
            _layout(sf, sf.keys if every_member else getattr(sf, "_sls_copies", sf.keys))
            for sf in self.fields
        )


def share_kernel(*fields) -> None:
    """Copy these struct fields (each's copies set by :func:`copies_among` first) by one
    kernel."""
    group = CopyGroup(fields)
    for k, sf in enumerate(group.fields):
        sf._sls_group = (group, k)


@ti.kernel
def _copy(
    group: ti.template(),
    table: ti.types.ndarray(),
    into_table: ti.i32,
    which: ti.i32,
    columns: ti.types.ndarray(),
):
    for i in range(table.shape[0]):
        for s in ti.static(range(len(group.fields))):
            if which == s:
                sf = ti.static(group.fields[s])
                if ti.static(len(sf.shape) == 0):
                    _row(sf, group.layouts[s], None, table, i, into_table, columns)
                else:
                    _row(sf, group.layouts[s], _element(sf.shape, i), table, i, into_table, columns)


@ti.func
def _row(
    sf: ti.template(),
    layout: ti.template(),
    at: ti.template(),
    table: ti.template(),
    i,
    into_table,
    columns: ti.template(),
):
    # the components by a run-time loop (dynamic indexing): one copy of the body per member
    for k in ti.static(range(len(layout))):
        name, comp = ti.static(layout[k])
        f = ti.static(sf.field_dict[name])
        col = columns[k]
        if col >= 0:
            if ti.static(len(comp) == 0):
                if into_table:
                    table[i, col] = ti.cast(f[at], ti.f64)
                else:
                    f[at] = ti.cast(table[i, col], f.dtype)
            elif ti.static(len(comp) == 1):
                for a in range(comp[0]):
                    if into_table:
                        table[i, col + a] = ti.cast(f[at][a], ti.f64)
                    else:
                        f[at][a] = ti.cast(table[i, col + a], f.dtype)
            else:
                for c in range(comp[0] * comp[1]):
                    a, b = c // comp[1], c % comp[1]
                    if into_table:
                        table[i, col + c] = ti.cast(f[at][a, b], ti.f64)
                    else:
                        f[at][a, b] = ti.cast(table[i, col + c], f.dtype)


def _components(f) -> tuple[int, ...]:
    if getattr(f, "ndim", 0) == 2:
        return (f.n, f.m)
    if getattr(f, "ndim", 0) == 1:
        return (f.n,)
    return ()


def copies_among(sf, members: Iterable[str]) -> None:
    """The members every copy of ``sf`` ranges over (the others are never copied): a smaller
    kernel than one over all of them. Before :func:`share_kernel`."""
    sf._sls_copies = tuple(members)


def _layout(sf, among: Iterable[str]) -> Layout:
    return tuple((name, _components(sf.field_dict[name])) for name in among)


def _plan(sf, keys: Iterable[str]) -> tuple[CopyGroup, int, np.ndarray, list, int]:
    """The group whose kernel copies ``sf`` and sf's place in it, each member's column in the
    table (-1: not copied) and the (member, column, components) copied, in the order of
    ``keys``. A field in no group, or asked for a member outside its copies, gets a group of
    its own over all its members."""
    keys = list(dict.fromkeys(keys))  # each member once
    group, which = getattr(sf, "_sls_group", (None, 0))
    if group is None or not set(keys) <= {name for name, _ in group.layouts[which]}:
        full = getattr(sf, "_sls_full", None)
        if full is None:
            full = sf._sls_full = CopyGroup((sf,), every_member=True)
        group, which = full, 0
    layout = group.layouts[which]
    columns = np.full(len(layout), -1, dtype=np.int32)
    index = {name: k for k, (name, _) in enumerate(layout)}
    copied, col = [], 0
    for name in keys:
        comp = layout[index[name]][1]
        columns[index[name]] = col
        copied.append((name, col, comp))
        col += int(np.prod(comp, dtype=int))
    return group, which, columns, copied, col


def _rows(sf) -> int:
    return int(np.prod(sf.shape, dtype=int)) if sf.shape else 1


def from_numpy(sf, arrays: Mapping[str, np.ndarray]) -> None:
    """``sf.from_numpy(arrays)`` in one kernel, for the members ``arrays`` names (each of the
    member's shape: the field's, then its components')."""
    group, which, columns, copied, width = _plan(sf, arrays.keys())
    rows = _rows(sf)
    table = np.empty((rows, width), dtype=np.float64)
    for name, col, comp in copied:
        n = int(np.prod(comp, dtype=int))
        table[:, col : col + n] = np.asarray(arrays[name], dtype=np.float64).reshape(rows, n)
    _copy(group, table, False, which, columns)


def to_numpy(sf, keys: Iterable[str] | None = None) -> dict[str, np.ndarray]:
    """``sf.to_numpy()`` in one kernel (every member, or those of ``keys``): the same dtypes
    and shapes as Taichi's."""
    group, which, columns, copied, width = _plan(sf, sf.keys if keys is None else keys)
    table = np.empty((_rows(sf), width), dtype=np.float64)
    _copy(group, table, True, which, columns)
    return {
        name: table[:, col : col + int(np.prod(comp, dtype=int))]
        .reshape(tuple(sf.shape) + comp)
        .astype(_NUMPY[sf.field_dict[name].dtype])
        for name, col, comp in copied
    }
