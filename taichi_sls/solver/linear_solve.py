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

- ``direct``: a supernodal Cholesky (``time.direct_solver``: CHOLMOD's through cvxopt, or MKL
  PARDISO's, solver/pardiso.py; the numeric refactorization reuses the symbolic one while the
  pattern is unchanged), or where a matrix is not positive definite qdldl's LDL^T with AMD
  ordering: exact for the matrix it was built from.
- ``amg``: pyamg's smoothed-aggregation hierarchy as the preconditioner (memory and time linear
  in the unknowns, for the large systems where a factorization's fill grows too big); given
  ``near_null`` (the implicit step gives the rigid-body modes of its grid velocities, 3 in 2D
  and 6 in 3D), its aggregates interpolate those exactly, as elasticity wants.
"""

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse as sp

from ..config import Case
from ..config.errors import CaseError
from .direct_factor import CHOLMOD, PARDISO, DirectFactor, LinearSolveError
from .pardiso import available

CG_MAX_ITERATIONS = 500
# LinearSolver._mapped: the most unknowns leaving the system whose effect on the kept
# factorization is corrected exactly (a solve each)
WOODBURY_MAX = 64
# preconditioned_cg(predict=True): the iterations after which it judges its rate
PREDICT_AFTER = 5


# time.direct_max_unknowns unset: the largest direct solve by dimension (docs/record/implicit.md)
DIRECT_MAX_UNKNOWNS = {2: 200_000, 3: 40_000}


def direct_max_unknowns(case: Case) -> int:
    """``time.direct_max_unknowns``, or where unset the dimension's DIRECT_MAX_UNKNOWNS."""
    limit = case.time.direct_max_unknowns
    return DIRECT_MAX_UNKNOWNS[case.domain.dim] if limit is None else limit


def direct_backend(case: Case) -> str:
    """``time.direct_solver``; "auto": PARDISO in 3D where MKL is installed, else CHOLMOD."""
    choice = case.time.direct_solver
    if choice == "auto":
        return PARDISO if case.domain.dim == 3 and available() else CHOLMOD
    if choice == PARDISO and not available():
        raise CaseError(
            'time.direct_solver = "pardiso": MKL is not installed here (pip install mkl, on '
            'x86_64); allowed: "cholmod" or "auto"'
        )
    return choice


def nested_ordering(case: Case) -> bool:
    """Whether the direct factorizations order by nested dissection (``time.direct_ordering``;
    "auto": in 3D)."""
    choice = case.time.direct_ordering
    return choice == "nested_dissection" or (choice == "auto" and case.domain.dim == 3)


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
    """Work done so far: factorizations (or multigrid set-ups), those of a new pattern (a new
    analysis), CG iterations and solves."""

    factorizations: int = 0
    analyses: int = 0
    cg_iterations: int = 0
    solves: int = 0


class LinearSolver:
    """A x = b for a sequence of SPD matrices (module docstring). ``how``: "direct" or "amg";
    ``rtol``: the relative residual of a preconditioned CG solve; ``backend``: the direct
    factorization's library, "cholmod" or "pardiso"."""

    def __init__(
        self, how: str, rtol: float, refresh_after: int = 20, backend: str = CHOLMOD
    ) -> None:
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
        # direct: each unknown's node (a label), where the factorization is ordered by nested
        # dissection (time.direct_ordering; DirectFactor); None: AMD or minimum degree
        self.nodes: np.ndarray | None = None
        self._keys: np.ndarray | None = None  # the factorized matrix's unknowns (ascending)
        self._map: tuple | None = None  # (keys, preconditioner) of _mapped's last call
        self._kept_failed = False  # the kept factorization failed the last matrix it met
        self.backend = backend  # direct: the factorization's library (time.direct_solver)

    @classmethod
    def for_case(cls, case: Case, how: str, rtol: float) -> "LinearSolver":
        """The solver of a case's systems: its direct factorizations by ``time.direct_solver``."""
        return cls(how, rtol, backend=direct_backend(case))

    def solve(
        self,
        A: sp.csr_matrix,
        b: np.ndarray,
        refresh: bool = False,
        keys: np.ndarray | None = None,
    ) -> np.ndarray:
        """x with |A x - b| <= rtol |b|; ``refresh``: factorize A afresh (direct: solve with it;
        amg: a new hierarchy) even where the kept one would do. ``keys``: what each unknown is
        (ascending integers, a node and component each): a direct factorization kept from
        unknowns that were partly others then preconditions CG on the ones both share
        (:meth:`_mapped`), so that a node entering or leaving the system does not cost a new
        factorization while the kept one still contracts CG within ``refresh_after``
        iterations."""
        self.stats.solves += 1
        if A is self._factored and self.how == "direct":
            return self._factor.solve(b)
        same = self._same_pattern(A)
        mapped = (
            not same
            and not refresh
            and keys is not None
            and self.how == "direct"
            and self._keys is not None
        )
        fresh = refresh or not (same or mapped)
        if keys is not None and not fresh and self._kept_failed:
            # the kept factorization failed the last new matrix: this one is factorized
            # afresh, the next tries the kept one again (a hold's steps change dt twofold)
            fresh, self._kept_failed = True, False
        if fresh:
            self._factorize(A, new_pattern=not same, keys=keys)
            if self.how == "direct":
                return self._factor.solve(b)
        # a fresh hierarchy is not set up again: CG runs on to its limit with it (the same
        # iterates as a second set-up from the same matrix, at half the cost)
        precondition = self._mapped(A, keys) if mapped else self._precondition
        limit = CG_MAX_ITERATIONS if fresh else self.refresh_after
        # with keys, CG on a kept factorization stops as soon as its rate of convergence
        # shows it would not reach rtol within the limit
        x, converged = self._cg(A, b, limit, precondition, keys is not None and not fresh)
        if not converged and not fresh:
            self._kept_failed = keys is not None
            self._factorize(A, new_pattern=not same, keys=keys)
            if self.how == "direct":
                return self._factor.solve(b)
            x, converged = self._cg(A, b, CG_MAX_ITERATIONS, self._precondition)
        if not converged:
            raise LinearSolveError(
                f"conjugate gradients with a fresh {self.how} preconditioner did not reach "
                f"the relative residual {self.rtol:g} in {CG_MAX_ITERATIONS} iterations"
            )
        return x

    def _mapped(self, A: sp.csr_matrix, keys: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
        """The kept factorization of A_old as a preconditioner of A over other unknowns: on
        the unknowns both share, the inverse of A_old's block there (symmetric positive
        definite, as CG needs), from A_old^-1 by the Woodbury identity over the unknowns that
        left (up to WOODBURY_MAX of them; beyond, A_old^-1's block there); on A's new
        unknowns, the inverse of A's diagonal. Each unknown that left or entered otherwise
        costs CG about one iteration. Kept for the next solve with the same ``keys``."""
        if self._map is not None and self._map[0] is keys:
            return self._map[1]
        old = self._keys
        at = np.minimum(np.searchsorted(old, keys), len(old) - 1)
        shared = old[at] == keys
        into = at[shared]
        left = np.setdiff1d(np.arange(len(old)), into, assume_unique=True)
        inverse_diagonal = 1.0 / A.diagonal()
        solve = self._factor.solve
        correct = None
        if 0 < len(left) <= WOODBURY_MAX:
            unit = np.zeros((len(old), len(left)))
            unit[left, np.arange(len(left))] = 1.0
            columns = solve(unit)  # A_old^-1 at the unknowns that left
            block = scipy.linalg.cho_factor(columns[left])

            def correct(y: np.ndarray) -> np.ndarray:
                return y - columns @ scipy.linalg.cho_solve(block, y[left])

        def precondition(r: np.ndarray) -> np.ndarray:
            full = np.zeros(len(old))
            full[into] = r[shared]
            y = solve(full)
            if correct is not None:
                y = correct(y)
            z = r * inverse_diagonal
            z[shared] = y[into]
            return z

        self._map = (keys, precondition)
        return precondition

    def _same_pattern(self, A: sp.csr_matrix) -> bool:
        if self._pattern is None:
            return False
        indptr, indices = self._pattern
        return np.array_equal(indptr, A.indptr) and np.array_equal(indices, A.indices)

    def _factorize(
        self, A: sp.csr_matrix, new_pattern: bool, keys: np.ndarray | None = None
    ) -> None:
        self.stats.factorizations += 1
        self._keys, self._map = keys, None
        if self.how == "direct":
            try:
                if new_pattern or self._factor is None:
                    self.stats.analyses += 1
                    self._factor = DirectFactor(A, self.nodes, self.backend)
                else:
                    self._factor.update(A)
            except LinearSolveError:  # nothing kept: the next matrix starts afresh
                self._factor = self._factored = self._pattern = self._keys = None
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

    def _cg(
        self,
        A: sp.csr_matrix,
        b: np.ndarray,
        limit: int,
        precondition: Callable[[np.ndarray], np.ndarray],
        predict: bool = False,
    ) -> tuple[np.ndarray, bool]:
        x, iterations, converged = preconditioned_cg(A, b, precondition, self.rtol, limit, predict)
        self.stats.cg_iterations += iterations
        return x, converged


def preconditioned_cg(
    A: sp.csr_matrix,
    b: np.ndarray,
    precondition: Callable[[np.ndarray], np.ndarray],
    rtol: float,
    limit: int,
    predict: bool = False,
) -> tuple[np.ndarray, int, bool]:
    """Conjugate gradients from x = 0 to |b - A x| <= rtol |b| in at most ``limit``
    iterations: (x, iterations, converged). A and the preconditioner symmetric positive
    definite. ``predict``: give up after PREDICT_AFTER iterations where the residual's mean
    rate of decrease so far would need more than ``limit`` in all."""
    x = np.zeros_like(b)
    r = b.copy()
    norm_b = np.linalg.norm(b)
    target = rtol * norm_b
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
        norm_r = np.linalg.norm(r)
        if norm_r <= target:
            return x, k, True
        if predict and k == PREDICT_AFTER:
            rate = (norm_r / norm_b) ** (1.0 / k)
            if rate >= 1.0 or np.log(rtol) / np.log(rate) > limit:
                return x, k, False
        z = precondition(r)
        rz, rz_old = r @ z, rz
        p *= rz / rz_old
        p += z
    return x, limit, False
