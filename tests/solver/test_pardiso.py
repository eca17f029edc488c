"""MKL PARDISO as the direct factorization (solver/pardiso.py, ``time.direct_solver``): its
Cholesky solves the implicit step's 3D pattern to round-off, a refresh on the same pattern
solves the new matrix, an indefinite matrix falls back to LDL^T, and a case that asks for it
where MKL is missing is refused naming the key. Each test needs MKL (the ``mkl`` package,
a dependency on x86_64)."""

import numpy as np
import pytest
import scipy.sparse as sp
from helpers import grid_rows
from test_matrix_free import pair3d_steps

from taichi_sls.config import CaseError, load_case
from taichi_sls.solver import linear_solve
from taichi_sls.solver.direct_factor import DirectFactor
from taichi_sls.solver.linear_solve import LinearSolver, direct_backend
from taichi_sls.solver.pardiso import PardisoFactor, available

needs_mkl = pytest.mark.skipif(not available(), reason="MKL (the mkl package) is not installed")


@needs_mkl
@pytest.mark.parametrize("ordering", ["nested_dissection", "amd"])
def test_pardiso_solves_3d_rows_and_refreshes_on_their_pattern(ordering):
    """On 8^3 nodes (1,536 unknowns, well conditioned): one and two right-hand sides to a
    relative residual of 1e-12 (round-off times the condition number, under 10 here), then
    the same pattern with other values, refreshed in place, solved as well."""
    A = grid_rows(8)
    b = np.random.default_rng(1).random((A.shape[0], 2))
    factor = PardisoFactor(A, ordering)
    for matrix in (A, (A + A.multiply(A)).tocsr()):
        if matrix is not A:
            factor.update(matrix)
        x = factor.solve(b[:, 0])
        assert np.linalg.norm(matrix @ x - b[:, 0]) <= 1e-12 * np.linalg.norm(b[:, 0])
        X = factor.solve(b)
        assert X.shape == b.shape
        assert np.linalg.norm(matrix @ X - b) <= 1e-12 * np.linalg.norm(b)


@needs_mkl
def test_pardiso_falls_back_to_ldlt_on_an_indefinite_matrix():
    """DirectFactor on PARDISO: Cholesky on an SPD matrix, qdldl's LDL^T where the refreshed
    matrix has eigenvalues on both sides of zero (PARDISO reports a negative pivot), Cholesky
    again on the next SPD one; each solved to round-off (1e-10: the shifted matrix is the
    worse conditioned)."""
    n = 20
    lap = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    A = (sp.kronsum(lap, lap) + 0.01 * sp.eye(n * n)).tocsr()
    shifted = (A - 1.5 * sp.eye(n * n)).tocsr()
    b = np.random.default_rng(7).normal(size=n * n)
    factor = DirectFactor(A, backend="pardiso")
    for matrix, definite in ((A, True), (shifted, False), (2.0 * A, True)):
        factor.update(matrix)
        assert factor.cholesky == definite
        x = factor.solve(b)
        assert np.linalg.norm(matrix @ x - b) <= 1e-10 * np.linalg.norm(b)


@needs_mkl
def test_pardiso_and_cholmod_give_one_answer():
    """The two libraries on one 3D matrix through the LinearSolver (nested dissection each):
    the same solution to 1e-12 of its size (both to round-off of a matrix conditioned under
    10)."""
    A = grid_rows(9)
    nodes = np.repeat(np.arange(9**3), 3)
    b = np.random.default_rng(2).random(A.shape[0])
    x = {}
    for backend in ("cholmod", "pardiso"):
        solver = LinearSolver("direct", 1e-10, backend=backend)
        solver.nodes = nodes
        x[backend] = solver.solve(A, b)
    assert np.abs(x["pardiso"] - x["cholmod"]).max() <= 1e-12 * np.abs(x["cholmod"]).max()


def test_direct_solver_chooses_and_refuses(monkeypatch):
    """auto: PARDISO in 3D where MKL loads, CHOLMOD in 2D and where it does not; "pardiso"
    without MKL is refused in one line naming the key and what is allowed."""
    case3, case2 = load_case("pair3d_25W"), load_case("power25W_coarse")
    assert direct_backend(case2) == "cholmod"
    assert direct_backend(case3) == ("pardiso" if available() else "cholmod")
    monkeypatch.setattr(linear_solve, "available", lambda: False)
    assert direct_backend(case3) == "cholmod"
    asked = load_case("pair3d_25W", ["time.direct_solver=pardiso"])
    with pytest.raises(CaseError, match=r'time\.direct_solver = "pardiso".*allowed'):
        direct_backend(asked)
    with pytest.raises(CaseError, match=r"time\.direct_solver.*cholmod"):
        load_case("pair3d_25W", ["time.direct_solver=umfpack"])


@needs_mkl
def test_implicit_3d_steps_are_the_same_on_either_library():
    """Three implicit steps of a molten 3D pair (test_matrix_free's, h = 4 um): the points
    where CHOLMOD puts them, to 1e-8 of a cell (both factorizations are exact to round-off,
    measured 2e-12, and Newton takes the same iterations; its tolerance, 1e-6 of the force
    scale, would allow far more), and the same Newton iterations."""
    positions, iterations = {}, {}
    for backend in ("cholmod", "pardiso"):
        sim = pair3d_steps(3, direct_solver=backend)
        positions[backend] = sim.state.points.x.to_numpy()
        iterations[backend] = sim.implicit.newton_total
        assert sim.implicit.linear.backend == backend
    assert iterations["pardiso"] == iterations["cholmod"]
    assert np.abs(positions["pardiso"] - positions["cholmod"]).max() <= 1e-8 * 4e-6
