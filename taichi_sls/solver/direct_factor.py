"""The direct factorization of one symmetric matrix, refreshed by others of its pattern.

A supernodal Cholesky by one of two libraries (``time.direct_solver``): CHOLMOD through cvxopt
(its BLAS a serial ATLAS) or MKL PARDISO (solver/pardiso.py, MKL's threaded BLAS), and qdldl's
LDL^T with AMD ordering where Cholesky finds a matrix not positive definite. Each is exact for
the matrix it was built from; solver/linear_solve.py keeps one across solves.
"""

import numpy as np
import scipy.sparse as sp

from .ordering import nested_dissection
from .pardiso import NOT_POSITIVE_DEFINITE, PardisoError, PardisoFactor

CHOLMOD, PARDISO = "cholmod", "pardiso"  # time.direct_solver's libraries


class LinearSolveError(RuntimeError):
    """No factorization of the matrix exists (singular or indefinite), or conjugate gradients
    with a fresh preconditioner did not converge. ``advice``: what a case can change."""

    # a node with almost no mass and stiffness leaves the matrix near singular
    advice = "try a smaller time.dt_s or time.implicit_velocity_penalty = 1e-6"


class DirectFactor:
    """A factorization of a symmetric matrix A (CSR, both triangles stored) that a matrix of the
    same pattern can refresh: a supernodal Cholesky, CHOLMOD's (through cvxopt) of A's lower
    triangle or PARDISO's (solver/pardiso.py; ``backend``), faster than qdldl's simplicial
    LDL^T on the implicit step's matrices (docs/record/implicit.md); qdldl where Cholesky finds
    A not positive definite."""

    def __init__(
        self, A: sp.csr_matrix, nodes: np.ndarray | None = None, backend: str = CHOLMOD
    ) -> None:
        """``nodes``: each unknown's grid node, where the elimination orders by nested
        dissection (CHOLMOD: of the nodes' graph, solver/ordering.py; PARDISO: its own METIS);
        None: CHOLMOD's AMD, PARDISO's minimum degree. ``backend``: "cholmod" or "pardiso"."""
        self.backend, self._nested = backend, nodes is not None
        self._pardiso: PardisoFactor | None = None
        self._symbolic = None
        if backend == PARDISO:
            self.update(A)
            return
        from cvxopt import matrix, spmatrix

        order = None if nodes is None else nested_dissection(A, nodes)
        self._p = None if order is None else matrix(order.astype(np.int32).tolist())

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
        self.update(A)

    def update(self, A: sp.csr_matrix) -> None:
        """Factorize A, whose pattern is the one this factor was built with."""
        self._ldl = None
        try:
            if self.backend == PARDISO:
                self._factorize_pardiso(A)
            else:
                self._factorize_cholmod(A)
        except ArithmeticError:
            # not positive definite: LDL^T, and a fresh analysis next time
            import qdldl

            self._symbolic = self._pardiso = None
            try:
                self._ldl = qdldl.Solver(A.tocsc())  # symmetric: its CSC is its CSR transposed
            except RuntimeError as e:  # a zero pivot: singular, or not quasi-definite
                raise LinearSolveError(
                    f"neither Cholesky nor LDL^T factorizes the {A.shape[0]} x {A.shape[0]} "
                    f"matrix ({e})"
                ) from e

    def _factorize_cholmod(self, A: sp.csr_matrix) -> None:
        from cvxopt import cholmod, matrix

        self._lower.V = matrix(A.data[self._order])
        if self._symbolic is None:
            if self._p is None:
                self._symbolic = cholmod.symbolic(self._lower)
            else:
                self._symbolic = cholmod.symbolic(self._lower, p=self._p)
        cholmod.numeric(self._lower, self._symbolic)

    def _factorize_pardiso(self, A: sp.csr_matrix) -> None:
        try:
            if self._pardiso is None:
                self._pardiso = PardisoFactor(A, "nested_dissection" if self._nested else "amd")
            else:
                self._pardiso.update(A)
        except PardisoError as e:
            if e.code in NOT_POSITIVE_DEFINITE:
                raise NotPositiveDefinite(str(e)) from e
            raise LinearSolveError(f"PARDISO failed on the {A.shape[0]} unknowns: {e}") from e

    @property
    def cholesky(self) -> bool:
        """Whether the last update found the matrix positive definite (Cholesky holds it)."""
        return self._ldl is None

    def solve(self, b: np.ndarray) -> np.ndarray:
        """A^-1 b, b a vector or a matrix of columns."""
        if self._ldl is not None:
            if b.ndim == 2:
                return np.column_stack([self._ldl.solve(c) for c in b.T])
            return self._ldl.solve(b)
        if self._pardiso is not None:
            return self._pardiso.solve(b)
        from cvxopt import cholmod, matrix

        x = matrix(np.ascontiguousarray(b))
        cholmod.solve(self._symbolic, x)
        return np.asarray(x).reshape(b.shape)


class NotPositiveDefinite(ArithmeticError):
    """A Cholesky factorization met a pivot that is not positive."""
