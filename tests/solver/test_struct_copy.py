"""struct_copy: one kernel copies a struct field as Taichi's member-by-member copies do."""

import numpy as np
import pytest

from taichi_sls.backend import ti
from taichi_sls.solver import struct_copy
from taichi_sls.solver.simulation import init_taichi


@pytest.fixture(scope="module", autouse=True)
def taichi():
    init_taichi()


@pytest.mark.parametrize("shape", [(), (3,)])
def test_a_round_trip_matches_taichis_own_copies(shape):
    kind = ti.types.struct(a=float, n=ti.i32, b=float)
    ours, theirs = kind.field(shape=shape), kind.field(shape=shape)
    rng = np.random.default_rng(1)
    arrays = {
        "a": np.asarray(rng.normal(size=shape)),
        "n": np.asarray(rng.integers(-1000, 1000, size=shape), dtype=np.int32),
        "b": np.asarray(rng.normal(size=shape) * 1e-300),
    }
    struct_copy.from_numpy(ours, arrays)
    theirs.from_numpy(arrays)
    back, expected = struct_copy.to_numpy(ours), theirs.to_numpy()
    assert back.keys() == expected.keys()
    for k, v in expected.items():
        assert back[k].dtype == v.dtype and back[k].shape == v.shape
        assert np.array_equal(back[k], v) and np.array_equal(v, arrays[k])


@pytest.mark.parametrize("shape", [(), (5,), (3, 4), (2, 3, 4)])
def test_vectors_matrices_and_a_subset_match_taichis_own_copies(shape):
    """Vector and matrix members (the points' x, F, stress), node-shaped fields in C order (a
    2D grid's and a 3D one's), and a subset of members (a checkpoint's), each equal to Taichi's
    member-by-member copy."""
    kind = ti.types.struct(
        a=float, n=ti.i32, v=ti.types.vector(2, float), M=ti.types.matrix(2, 3, float)
    )
    ours, theirs = kind.field(shape=shape), kind.field(shape=shape)
    rng = np.random.default_rng(2)
    arrays = {
        "a": np.asarray(rng.normal(size=shape)),
        "n": np.asarray(rng.integers(-1000, 1000, size=shape), dtype=np.int32),
        "v": rng.normal(size=shape + (2,)),
        "M": rng.normal(size=shape + (2, 3)),
    }
    struct_copy.from_numpy(ours, arrays)
    theirs.from_numpy(arrays)
    back, expected = struct_copy.to_numpy(ours), theirs.to_numpy()
    for k, v in expected.items():
        assert back[k].dtype == v.dtype and back[k].shape == v.shape
        assert np.array_equal(back[k], v) and np.array_equal(v, arrays[k])
    part = struct_copy.to_numpy(ours, ["M", "a"])
    assert list(part) == ["M", "a"] and np.array_equal(part["M"], arrays["M"])
    struct_copy.from_numpy(ours, {"v": -arrays["v"]})  # the others stay
    back = struct_copy.to_numpy(ours)
    assert np.array_equal(back["v"], -arrays["v"]) and np.array_equal(back["M"], arrays["M"])
