"""MKL PARDISO's Cholesky of a sparse symmetric positive definite matrix, through ctypes.

The 3D implicit step's Newton matrices fill their factors heavily (3D rows of up to 375
entries), so their factorization is dense-matrix work: PARDISO runs it on MKL's threaded BLAS,
where cvxopt's CHOLMOD runs on a serial ATLAS (docs/record/implicit.md has the measured
factor). ``time.direct_solver`` chooses between them; the ``mkl`` package (x86_64) brings the
library, found here beside the interpreter as pip installs it.

The interface is :class:`~taichi_sls.solver.linear_solve.DirectFactor`'s: a factor built from
a CSR matrix with both triangles stored, refreshed in place by a matrix of the same pattern
(PARDISO's analysis kept), solving for a vector or columns.
"""

from __future__ import annotations

import ctypes
import functools
import glob
import site
import sys
import weakref
from ctypes.util import find_library

import numpy as np
import scipy.sparse as sp

SPD = 2  # PARDISO's matrix type: real symmetric positive definite (Cholesky)
ANALYSIS, FACTORIZATION, SOLVE, RELEASE = 11, 22, 33, -1  # its phases
NOT_POSITIVE_DEFINITE = (-4,)  # zero or negative pivot
ORDERINGS = {"amd": 0, "nested_dissection": 2}  # iparm[1]: minimum degree, METIS
ERRORS = {
    -1: "input inconsistent",
    -2: "not enough memory",
    -3: "reordering problem",
    -4: "zero or negative pivot: not positive definite",
    -7: "diagonal matrix is singular",
    -8: "32-bit integer overflow",
}


class PardisoError(RuntimeError):
    """PARDISO returned an error code (``code``)."""

    def __init__(self, code: int, phase: int) -> None:
        self.code = code
        super().__init__(f"PARDISO phase {phase}: error {code} ({ERRORS.get(code, 'see MKL')})")


@functools.cache
def library() -> ctypes.CDLL | None:
    """MKL's single dynamic library, or None where it is not installed."""
    found = find_library("mkl_rt")
    candidates = [found] if found else []
    for prefix in (sys.prefix, site.getuserbase()):
        candidates += sorted(glob.glob(f"{prefix}/lib/libmkl_rt.so*"), key=len)
    for path in candidates:
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        if hasattr(lib, "pardiso"):
            _declare(lib.pardiso)
            return lib
    return None


def available() -> bool:
    """Whether PARDISO can run here (the ``mkl`` package installed)."""
    return library() is not None


def _declare(fn: ctypes._CFuncPtr) -> None:
    i32, ptr = ctypes.POINTER(ctypes.c_int32), ctypes.c_void_p
    # pt, maxfct, mnum, mtype, phase, n, a, ia, ja, perm, nrhs, iparm, msglvl, b, x, error
    fn.argtypes = [ptr, i32, i32, i32, i32, i32, ptr, ptr, ptr, ptr, i32, ptr, i32, ptr, ptr, i32]
    fn.restype = None


class PardisoFactor:
    """PARDISO's Cholesky of A (CSR, both triangles; module docstring). ``ordering``: "amd"
    (minimum degree) or "nested_dissection" (METIS). Raises :class:`PardisoError`, whose
    code is in NOT_POSITIVE_DEFINITE where A is not positive definite."""

    def __init__(self, A: sp.csr_matrix, ordering: str = "nested_dissection") -> None:
        lib = library()
        if lib is None:
            raise RuntimeError("PARDISO needs the mkl package (pip install mkl)")
        self._pardiso = lib.pardiso
        self._handle = np.zeros(64, dtype=np.int64)  # PARDISO's own pointers: never moved
        self._iparm = np.zeros(64, dtype=np.int32)
        # PARDISO's memory goes with this object (or at exit, while the modules still exist)
        weakref.finalize(self, _invoke, self._pardiso, self._handle, self._iparm, RELEASE)
        self._iparm[0] = 1  # these settings, not the defaults
        self._iparm[1] = ORDERINGS[ordering]
        self._iparm[34] = 1  # zero-based indices
        upper = sp.triu(A, format="csr")
        upper.sort_indices()
        self._indptr = upper.indptr.astype(np.int32)
        self._indices = upper.indices.astype(np.int32)
        # where each of the upper triangle's entries lies in A.data, for a refresh
        rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
        self._take = np.flatnonzero(A.indices >= rows)
        self._values = np.ascontiguousarray(upper.data)
        self._call(ANALYSIS)
        self._call(FACTORIZATION)

    def update(self, A: sp.csr_matrix) -> None:
        """Factorize A, whose pattern is the one this factor was built with."""
        self._values = np.ascontiguousarray(A.data[self._take])
        self._call(FACTORIZATION)

    def solve(self, b: np.ndarray) -> np.ndarray:
        """A^-1 b, b a vector or a matrix of columns."""
        rhs = np.asfortranarray(b, dtype=np.float64)
        x = np.zeros_like(rhs)
        self._call(SOLVE, rhs, x, 1 if b.ndim == 1 else b.shape[1])
        return np.ascontiguousarray(x)

    def _call(
        self, phase: int, b: np.ndarray | None = None, x: np.ndarray | None = None, nrhs: int = 1
    ) -> None:
        matrix = (self._values, self._indptr, self._indices)
        error = _invoke(self._pardiso, self._handle, self._iparm, phase, matrix, b, x, nrhs)
        if error != 0:
            raise PardisoError(error, phase)


def _invoke(
    pardiso: ctypes._CFuncPtr,
    handle: np.ndarray,
    iparm: np.ndarray,
    phase: int,
    matrix: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    b: np.ndarray | None = None,
    x: np.ndarray | None = None,
    nrhs: int = 1,
) -> int:
    """One call of ``pardiso`` on the factorization behind ``handle``: ``matrix`` the upper
    triangle's (values, indptr, indices) in CSR, None for the release. Returns PARDISO's error
    code (0: none)."""
    error = ctypes.c_int32(0)

    def int32(v: int) -> ctypes.c_int32:
        return ctypes.byref(ctypes.c_int32(v))

    values, indptr, indices = (None, None, None) if matrix is None else matrix
    n = 0 if indptr is None else len(indptr) - 1
    pardiso(
        handle.ctypes.data,
        int32(1),  # maxfct
        int32(1),  # mnum
        int32(SPD),
        int32(phase),
        int32(n),
        None if values is None else values.ctypes.data,
        None if indptr is None else indptr.ctypes.data,
        None if indices is None else indices.ctypes.data,
        None,  # perm
        int32(nrhs),
        iparm.ctypes.data,
        int32(0),  # msglvl
        None if b is None else b.ctypes.data,
        None if x is None else x.ctypes.data,
        ctypes.byref(error),
    )
    return error.value
