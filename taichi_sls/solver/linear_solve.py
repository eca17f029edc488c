"""The implicit step's linear solves, A x = b with A symmetric positive definite, reusing work.

A factorization costs far more than a solve with it, and the matrices of consecutive Newton
iterations and steps differ little (the points move a fraction of a cell per step). So a
factorization is kept and, while the next matrix has the same sparsity pattern, it
preconditions conjugate gradients on that matrix; when CG needs more than ``refresh_after``
iterations (the matrix has drifted) the factorization is refreshed.

- ``direct``: LDL^T with AMD ordering (qdldl; its numeric refactorization reuses the symbolic
  one when the pattern is unchanged): exact for the matrix it was built from.
- ``amg``: pyamg's smoothed-aggregation hierarchy as the preconditioner (memory and time linear
  in the unknowns, for the large systems where a factorization's fill grows too big).
"""

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..config import Case

CG_MAX_ITERATIONS = 500


def linear_solver(case: Case, n: int) -> str:
    """The solver for n unknowns: ``time.linear_solver``, "auto" by size."""
    choice = case.time.linear_solver
    if choice == "auto":
        choice = "direct" if n <= case.time.direct_max_unknowns else "amg"
    return choice


@dataclass
class SolveStats:
    """Work done so far: factorizations (or multigrid set-ups) and CG iterations."""

    factorizations: int = 0
    cg_iterations: int = 0
    solves: int = 0


class LinearSolver:
    """A x = b for a sequence of SPD matrices (module docstring). ``how``: "direct" or "amg";
    ``rtol``: the relative residual of a preconditioned CG solve."""

    def __init__(self, how: str, rtol: float, refresh_after: int = 20) -> None:
        if how not in ("direct", "amg"):
            raise ValueError(f"linear solver {how!r}: allowed: direct, amg")
        self.how = how
        self.rtol = rtol
        self.refresh_after = refresh_after
        self.stats = SolveStats()
        self._pattern: tuple[np.ndarray, np.ndarray] | None = None
        self._factor = None
        self._precondition: spla.LinearOperator | None = None

    def solve(self, A: sp.csr_matrix, b: np.ndarray) -> np.ndarray:
        self.stats.solves += 1
        if not self._same_pattern(A):
            self._factorize(A, new_pattern=True)
            if self.how == "direct":
                return self._factor.solve(b)
        x, converged = self._cg(A, b, self.refresh_after)
        if not converged:
            self._factorize(A, new_pattern=False)
            if self.how == "direct":
                return self._factor.solve(b)
            x, converged = self._cg(A, b, CG_MAX_ITERATIONS)
            if not converged:
                raise RuntimeError(
                    f"conjugate gradients with a fresh {self.how} preconditioner did not reach "
                    f"the relative residual {self.rtol:g} in {CG_MAX_ITERATIONS} iterations"
                )
        return x

    def _same_pattern(self, A: sp.csr_matrix) -> bool:
        if self._pattern is None:
            return False
        indptr, indices = self._pattern
        return np.array_equal(indptr, A.indptr) and np.array_equal(indices, A.indices)

    def _factorize(self, A: sp.csr_matrix, new_pattern: bool) -> None:
        self.stats.factorizations += 1
        if self.how == "direct":
            import qdldl

            csc = A.tocsc()  # A is symmetric: its CSC is its CSR transposed, the same matrix
            if new_pattern or self._factor is None:
                self._factor = qdldl.Solver(csc)
            else:
                self._factor.update(csc)
            solve = self._factor.solve
        else:
            import pyamg

            ml = pyamg.smoothed_aggregation_solver(A, symmetry="symmetric", max_coarse=500)
            self._factor = ml
            solve = ml.aspreconditioner(cycle="V").matvec
        self._pattern = (A.indptr.copy(), A.indices.copy())
        n = A.shape[0]
        self._precondition = spla.LinearOperator((n, n), matvec=solve, dtype=float)

    def _cg(self, A: sp.csr_matrix, b: np.ndarray, limit: int) -> tuple[np.ndarray, bool]:
        count = [0]

        def tick(_x: np.ndarray) -> None:
            count[0] += 1

        x, info = spla.cg(A, b, rtol=self.rtol, maxiter=limit, M=self._precondition, callback=tick)
        self.stats.cg_iterations += count[0]
        return x, info == 0
