"""The Newton system's unknowns kept across steps (solver/envelope.py, ``time.direct_pattern =
"envelope"``): the step's own equations, the envelope's other unknowns pinned at zero, and an
analysis of the factorization only when the material leaves the envelope."""

import numpy as np
import pytest
from test_matrix_free import pair, pair3d_steps

from taichi_sls.config import case_from_dict, load_case
from taichi_sls.solver.envelope import envelope_pattern
from taichi_sls.solver.simulation import Simulation


def _system(sim: Simulation):
    sys_ = sim.implicit.prepare()
    f_int, tangent = sim.implicit.internal(sys_, sys_.v0)
    return sys_, sys_.matrix(sys_.fixed + tangent), f_int


def test_the_envelope_holds_the_steps_equations_and_pins_the_rest():
    """The molten 3D pair's first Newton system in the envelope and in the step's own
    unknowns: on the step's unknowns the same matrix, right-hand side, first iterate and force
    (the same gathers, to the bit); the other unknowns of the envelope (light nodes, 0.1 to 1
    of the mass cut) pinned: a positive diagonal alone in their rows and columns, nothing on
    the right, at rest, so every solve gives them zero and the step's unknowns their own
    solution."""
    data = pair(3, 4.0, "direct", dt_s=1e-3)
    data["time"]["implicit_small_mass"] = 1e-2  # the beds' mass cut: light nodes below it
    sim = Simulation(case_from_dict(data))
    assert sim.implicit.envelope is not None  # the 3D default
    env, A_env, f_env = _system(sim)
    sim.implicit.envelope = None
    own, A_own, f_own = _system(sim)
    assert env.n > own.n
    at = np.searchsorted(env.keys, own.keys)
    assert np.array_equal(env.keys[at], own.keys)
    assert (A_env[at][:, at] != A_own).nnz == 0
    for a, b in ((env.rhs, own.rhs), (env.v0, own.v0), (f_env, f_own)):
        assert np.array_equal(a[at], b)
    pinned = np.ones(env.n, dtype=bool)
    pinned[at] = False
    block = A_env[pinned]
    assert np.array_equal(block.nonzero()[0], np.arange(pinned.sum()))  # one entry a row ...
    assert np.array_equal(block.nonzero()[1], np.flatnonzero(pinned))  # ... on the diagonal
    assert (A_env.diagonal()[pinned] > 0).all()
    assert A_env[:, pinned][at].count_nonzero() == 0
    assert not env.rhs[pinned].any() and not f_env[pinned].any()
    # the pattern holds their full reach all the same: the next step may free them
    assert A_env.nnz > A_own.nnz + pinned.sum()


def test_implicit_3d_steps_are_the_same_in_the_envelope():
    """Five implicit steps of the molten 3D pair (h = 4 um): the points where the steps' own
    factorizations put them, to 1e-8 of a cell (both exact to round-off: measured 5e-13), with
    the same Newton iterations and fewer analyses of a new pattern (2 against 3: the fifth
    step's nodes change, and stay within the envelope of the fourth)."""
    positions, analyses, iterations = {}, {}, {}
    for mode in ("step", "envelope"):
        sim = pair3d_steps(5, direct_pattern=mode)
        positions[mode] = sim.state.points.x.to_numpy()
        analyses[mode] = sim.implicit.linear.stats.analyses
        iterations[mode] = sim.implicit.newton_total
    assert iterations["envelope"] == iterations["step"]
    assert analyses["envelope"] < analyses["step"]
    assert np.abs(positions["envelope"] - positions["step"]).max() <= 1e-8 * 4e-6


@pytest.mark.parametrize(
    ("name", "sets", "expected"),
    [
        ("pair3d_25W", [], True),
        ("power25W_coarse", [], False),
        ("power25W_coarse", ["time.direct_pattern=envelope"], True),
        ("pair3d_25W", ["time.direct_pattern=step"], False),
        ("pair3d_25W", ["time.refactorize=when_slow"], False),
        ("pair3d_25W", ["time.linear_solver=matrix_free"], False),
        ("pair3d_25W", ["time.implicit_velocity_penalty=1e-6"], False),
    ],
)
def test_the_envelope_is_the_3d_default(name, sets, expected):
    """``time.direct_pattern = "auto"``: the envelope in 3D, the steps' own unknowns in 2D
    (its answers unchanged to the bit); never with a kept factorization (which maps unknowns
    itself), the matrix-free step or the velocity penalty (which would couple the pinned)."""
    assert envelope_pattern(load_case(name, sets)) is expected
