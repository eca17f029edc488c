"""A struct field's members copied from or to NumPy by one kernel, not one per member.

Taichi's ``StructField.from_numpy`` copies member by member, each through a kernel of its own
that compiles (front end and JIT) the first time: ~25 ms each, a second for the materials'
40 members. These two kernels copy every scalar member at once through a float64 table (exact
for the f32, f64 and i32 members the solver's structs hold), with the same values as Taichi's.
"""

from collections.abc import Mapping

import numpy as np

from taichi_sls.backend import ti

_NUMPY = {ti.f32: np.float32, ti.f64: np.float64, ti.i32: np.int32}


@ti.kernel
def _from_table(sf: ti.template(), table: ti.types.ndarray()):
    for i in range(table.shape[0]):
        for k in ti.static(range(len(sf.keys))):
            f = ti.static(sf.field_dict[sf.keys[k]])
            if ti.static(len(sf.shape) == 0):
                f[None] = ti.cast(table[i, k], f.dtype)
            else:
                f[i] = ti.cast(table[i, k], f.dtype)


@ti.kernel
def _to_table(sf: ti.template(), table: ti.types.ndarray()):
    for i in range(table.shape[0]):
        for k in ti.static(range(len(sf.keys))):
            f = ti.static(sf.field_dict[sf.keys[k]])
            if ti.static(len(sf.shape) == 0):
                table[i, k] = ti.cast(f[None], ti.f64)
            else:
                table[i, k] = ti.cast(f[i], ti.f64)


def _rows(sf) -> int:
    assert len(sf.shape) <= 1, "struct_copy: a 0-d or 1-d struct field"
    return sf.shape[0] if sf.shape else 1


def from_numpy(sf, arrays: Mapping[str, np.ndarray]) -> None:
    """``sf.from_numpy(arrays)`` in one kernel (every member a scalar)."""
    table = np.empty((_rows(sf), len(sf.keys)), dtype=np.float64)
    for k, name in enumerate(sf.keys):
        table[:, k] = np.asarray(arrays[name], dtype=np.float64).reshape(-1)
    _from_table(sf, table)


def to_numpy(sf) -> dict[str, np.ndarray]:
    """``sf.to_numpy()`` in one kernel (every member a scalar): the same dtypes and shapes."""
    table = np.empty((_rows(sf), len(sf.keys)), dtype=np.float64)
    _to_table(sf, table)
    return {
        name: table[:, k].reshape(sf.shape).astype(_NUMPY[sf.field_dict[name].dtype])
        for k, name in enumerate(sf.keys)
    }
