"""The implicit step's linear solves, A x = b with A symmetric positive definite, reusing work.

A factorization costs far more than a solve with it, and the matrices of consecutive Newton
iterations and steps differ little (the points move a fraction of a cell per step). So a
factorization is kept and, while the next matrix has the same sparsity pattern, it
preconditions conjugate gradients on that matrix; when CG needs more than ``refresh_after``
iterations (the matrix has drifted) the factorization is refreshed.

A solve may ask for a fresh factorization (``refresh``): the implicit step asks whenever it
takes a new tangent, and solves with that very matrix over its next Newton iterations (direct:
the factorization alone, no CG). CG is written out here (``preconditioned_cg``): its iterations
are few, and scipy's wrapper adds a per-call overhead of the order of theirs.

- ``direct``: CHOLMOD's supernodal Cholesky (through cvxopt; its numeric refactorization reuses
  the symbolic one while the pattern is unchanged), or where a matrix is not positive definite
  qdldl's LDL^T with AMD ordering: exact for the matrix it was built from.
- ``amg``: pyamg's smoothed-aggregation hierarchy as the preconditioner (memory and time linear
  in the unknowns, for the large systems where a factorization's fill grows too big); given
  ``near_null`` (the implicit step gives the rigid-body modes of its grid velocities, 3 in 2D
  and 6 in 3D), its aggregates interpolate those exactly, as elasticity wants.
"""

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..config import Case

CG_MAX_ITERATIONS = 500


class LinearSolveError(RuntimeError):
    """No factorization of the matrix exists (singular or indefinite), or conjugate gradients
    with a fresh preconditioner did not converge."""


# time.direct_max_unknowns unset: the largest direct solve by dimension (docs/record/implicit.md)
DIRECT_MAX_UNKNOWNS = {2: 200_000, 3: 40_000}


def direct_max_unknowns(case: Case) -> int:
    """``time.direct_max_unknowns``, or where unset the dimension's DIRECT_MAX_UNKNOWNS."""
    limit = case.time.direct_max_unknowns
    return DIRECT_MAX_UNKNOWNS[case.domain.dim] if limit is None else limit


def linear_solver(case: Case, n: int, assembled: bool = False) -> str:
    """The solver for n unknowns: ``time.linear_solver``, "auto" by size; ``assembled``: a
    system whose rows are assembled anyway (the backward-Euler heat's), where "matrix_free"
    reads as "auto"."""
    choice = case.time.linear_solver
    if choice == "auto" or (assembled and choice == "matrix_free"):
        choice = "direct" if n <= direct_max_unknowns(case) else "amg"
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
        self._factored: sp.csr_matrix | None = None  # the matrix the factorization is of
        self._precondition: Callable[[np.ndarray], np.ndarray] | None = None
        # amg: the matrix's near-null modes (columns), which smoothed aggregation keeps exact
        # on its coarse levels; None: the constant vector (pyamg's default)
        self.near_null: np.ndarray | None = None

    def solve(self, A: sp.csr_matrix, b: np.ndarray, refresh: bool = False) -> np.ndarray:
        """x with |A x - b| <= rtol |b|; ``refresh``: factorize A afresh (direct: solve with it;
        amg: a new hierarchy) even where the kept one would do."""
        self.stats.solves += 1
        if A is self._factored and self.how == "direct":
            return self._factor.solve(b)
        same = self._same_pattern(A)
        fresh = refresh or not same
        if fresh:
            self._factorize(A, new_pattern=not same)
            if self.how == "direct":
                return self._factor.solve(b)
        # a fresh hierarchy is not set up again: CG runs on to its limit with it (the same
        # iterates as a second set-up from the same matrix, at half the cost)
        x, converged = self._cg(A, b, CG_MAX_ITERATIONS if fresh else self.refresh_after)
        if not converged and not fresh:
            self._factorize(A, new_pattern=False)
            if self.how == "direct":
                return self._factor.solve(b)
            x, converged = self._cg(A, b, CG_MAX_ITERATIONS)
        if not converged:
            raise LinearSolveError(
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
            try:
                if new_pattern or self._factor is None:
                    self._factor = DirectFactor(A)
                else:
                    self._factor.update(A)
            except LinearSolveError:  # nothing kept: the next matrix starts afresh
                self._factor = self._factored = self._pattern = None
                raise
            self._precondition = self._factor.solve
        else:
            import pyamg

            ml = pyamg.smoothed_aggregation_solver(
                A, B=self.near_null, symmetry="symmetric", max_coarse=500
            )
            self._factor = ml
            self._precondition = ml.aspreconditioner(cycle="V").matvec
        self._pattern = (A.indptr.copy(), A.indices.copy())
        self._factored = A

    def _cg(self, A: sp.csr_matrix, b: np.ndarray, limit: int) -> tuple[np.ndarray, bool]:
        x, iterations, converged = preconditioned_cg(A, b, self._precondition, self.rtol, limit)
        self.stats.cg_iterations += iterations
        return x, converged


class DirectFactor:
    """A factorization of a symmetric matrix A (CSR, both triangles stored) that a matrix of the
    same pattern can refresh: CHOLMOD's supernodal Cholesky of A's lower triangle, faster than
    qdldl's simplicial LDL^T on the implicit step's matrices (docs/record/implicit.md); qdldl
    where Cholesky finds A not positive definite."""

    def __init__(self, A: sp.csr_matrix) -> None:
        from cvxopt import matrix, spmatrix

        n = A.shape[0]
        rows = np.repeat(np.arange(n), np.diff(A.indptr))
        lower = np.flatnonzero(rows >= A.indices)
        # CHOLMOD keeps the entries in column order: build the matrix once with each entry's
        # index in A.data as its value, and read back where each of A's entries goes
        self._lower = spmatrix(
            matrix(lower.astype(float)),
            matrix(rows[lower].astype(np.int64)),
            matrix(A.indices[lower].astype(np.int64)),
            (n, n),
        )
        self._order = np.asarray(self._lower.V).ravel().astype(np.int64)
        self._symbolic = None
        self.update(A)

    def update(self, A: sp.csr_matrix) -> None:
        """Factorize A, whose pattern is the one this factor was built with."""
        from cvxopt import cholmod, matrix

        self._lower.V = matrix(A.data[self._order])
        self._ldl = None
        try:
            if self._symbolic is None:
                self._symbolic = cholmod.symbolic(self._lower)
            cholmod.numeric(self._lower, self._symbolic)
        except ArithmeticError:  # not positive definite: LDL^T, and a fresh analysis next time
            import qdldl

            self._symbolic = None
            try:
                self._ldl = qdldl.Solver(A.tocsc())  # symmetric: its CSC is its CSR transposed
            except RuntimeError as e:  # a zero pivot: singular, or not quasi-definite
                raise LinearSolveError(
                    f"neither Cholesky nor LDL^T factorizes the {A.shape[0]} x {A.shape[0]} "
                    f"matrix ({e})"
                ) from e

    @property
    def cholesky(self) -> bool:
        """Whether the last update found the matrix positive definite (CHOLMOD holds it)."""
        return self._ldl is None

    def solve(self, b: np.ndarray) -> np.ndarray:
        if self._ldl is not None:
            return self._ldl.solve(b)
        from cvxopt import cholmod, matrix

        x = matrix(b)
        cholmod.solve(self._symbolic, x)
        return np.asarray(x).ravel()


def preconditioned_cg(
    A: sp.csr_matrix,
    b: np.ndarray,
    precondition: Callable[[np.ndarray], np.ndarray],
    rtol: float,
    limit: int,
) -> tuple[np.ndarray, int, bool]:
    """Conjugate gradients from x = 0 to |b - A x| <= rtol |b| in at most ``limit``
    iterations: (x, iterations, converged). A and the preconditioner symmetric positive
    definite."""
    x = np.zeros_like(b)
    r = b.copy()
    target = rtol * np.linalg.norm(b)
    if np.linalg.norm(r) <= target:
        return x, 0, True
    z = precondition(r)
    p = z.copy()
    rz = r @ z
    for k in range(1, limit + 1):
        Ap = A @ p
        alpha = rz / (p @ Ap)
        x += alpha * p
        r -= alpha * Ap
        if np.linalg.norm(r) <= target:
            return x, k, True
        z = precondition(r)
        rz, rz_old = r @ z, rz
        p *= rz / rz_old
        p += z
    return x, limit, False
