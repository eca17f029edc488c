"""The implicit step's Newton systems without assembled tangent rows (``time.linear_solver =
"matrix_free"``): conjugate gradients preconditioned by a geometric multigrid on the MPM grid.

The operator. A x = F x + K x: F the fixed part (inertia, capillary stiffness: scalar rows
times the identity, read on the grid, solver/implicit_system.py FixedRows), K the points' tangent
applied through the points (physics/tangent_operator.py), so that the tangent costs three
numbers a point instead of 375 entries a node row.

The preconditioner, one V-cycle (the model: HOT, Wang et al. 2020, a multigrid on the MPM grid):
level 0 is the step's grid, level k a grid of spacing 2^k h whose nodes sit on every other node
of level k - 1. A coarse level's operator is the same points' tangent rediscretised with its
shape functions, plus its lumped mass over dt (the capillary stiffness, a surface term, is left
to the finest level's smoother); a coarse velocity component is an unknown where the level's
mass exceeds the mass cut scaled by its cell volume and no constrained fine component (a wall)
lies under it. Prolongation P is linear interpolation between the node lattices, restriction
its transpose. The smoother is Chebyshev on the dim x dim block-Jacobi operator D^-1 A, its
largest eigenvalue estimated by power iterations on each level when the tangent is taken; the
coarsest level is solved by a dense Cholesky factor of its matrix, assembled from its
quadrature points. The same polynomial before and after the coarse correction keeps the cycle
symmetric positive definite, as CG needs.
"""

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
import scipy.sparse as sp
from threadpoolctl import ThreadpoolController

from ..physics.tangent_operator import (
    apply_point_tangent,
    point_tangent_diagonal,
    point_tangent_matrix,
    points_quadrature,
)
from .fields import State
from .implicit_system import FixedRows, GridSystem
from .linear_solve import CG_MAX_ITERATIONS, LinearSolveError, SolveStats

# the relative residual of each Newton direction, as the assembled solves' (solver/implicit.py
# LINEAR_RTOL; a looser one, 1e-3, doubled the Newton iterations of a viscous step and cost more)
LINEAR_RTOL = 1e-6

SMOOTHING_DEGREE = 4  # Chebyshev degree before and after the coarse correction
COARSEST_DEGREE = 24  # on the coarsest level, in place of a solve
COARSEST_NODES = 500  # coarsen until a level has this many unknown nodes or fewer
COARSEST_UNKNOWNS = 3000  # the coarsest level is solved by Cholesky up to this size
MAX_LEVELS = 8
POWER_ITERATIONS = 12  # the largest eigenvalue of D^-1 A, per level
EIGEN_SAFETY = 1.15  # over the power iterations' estimate (which approaches from below)
SMOOTHED_FRACTION = 0.1  # Chebyshev damps eigenvalues in [this x lambda_max, lambda_max]


class MatrixFreeError(LinearSolveError):
    """Conjugate gradients did not reach the tolerance: the message says how far it got."""

    # the velocity penalty is refused with the matrix-free step; the direct solve is exact
    advice = 'try a smaller time.dt_s, or time.linear_solver = "direct"'


def _prolongation_1d(n_fine: int, n_coarse: int, shift: int) -> sp.csr_matrix:
    """Linear interpolation along one axis: fine node i = 2 J + shift is coarse node J, the
    fine nodes between two coarse ones take their mean."""
    rows, cols, vals = [], [], []
    for i in range(n_fine):
        j, odd = divmod(i - shift, 2)
        for J, wt in ((j, 1.0),) if not odd else ((j, 0.5), (j + 1, 0.5)):
            if 0 <= J < n_coarse:
                rows.append(i)
                cols.append(J)
                vals.append(wt)
    return sp.csr_matrix((vals, (rows, cols)), shape=(n_fine, n_coarse))


@dataclass
class Level:
    """One grid of the hierarchy: ``shape`` nodes of spacing h, node ``off`` at x = 0."""

    shape: tuple[int, ...]
    h: float
    off: int
    lp: float  # the uGIMP half-width of its quadrature points (m)
    quadrature: np.ndarray = field(default=None)  # rows (x, V, a_lambda, a_mu, mass)
    free: np.ndarray = field(default=None)  # (nodes, dim) bool: the unknown components
    mass: np.ndarray = field(default=None)  # (nodes,) lumped mass (kg)
    diagonal: np.ndarray = field(default=None)  # (nodes, dim, dim): A's diagonal blocks
    inverse_diagonal: np.ndarray = field(default=None)  # their inverses on the unknowns
    lambda_max: float = 1.0
    prolong_axes: list = field(default_factory=list)  # to the finer level, one per axis

    @property
    def nodes(self) -> int:
        return int(np.prod(self.shape))


class GridMultigrid:
    """The operator and its V-cycle for one Newton tangent of one step (module docstring)."""

    def __init__(self, st: State, dof_node: np.ndarray, fixed: FixedRows) -> None:
        self.st = st
        cfg = st.cfg
        self.dim = cfg.dim
        self.dt = float(st.scalars.dt[None])
        self.fixed = fixed
        fine = Level(tuple(cfg.shape), cfg.h, cfg.off, cfg.lp)
        strides = np.cumprod((1, *fine.shape[::-1]))[:-1][::-1]
        self.unknown_node = dof_node[:, : self.dim] @ strides  # the flat node of unknown k
        self.unknown_comp = dof_node[:, self.dim]
        fine.free = np.zeros((fine.nodes, self.dim), dtype=bool)
        fine.free[self.unknown_node, self.unknown_comp] = True
        self.levels = [fine]
        active = int(fine.free.any(axis=1).sum())  # about 2^dim fewer on each coarser level
        while len(self.levels) < MAX_LEVELS and min(self.levels[-1].shape) >= 5:
            if active <= COARSEST_NODES:
                break
            self.levels.append(self._coarser(self.levels[-1]))
            active //= 2**self.dim

    def _coarser(self, fine: Level) -> Level:
        shift = fine.off % 2
        shape = tuple((n - 1 - shift) // 2 + 2 for n in fine.shape)
        # its quadrature points merge those of a cell of the finer level: half a cell wide
        level = Level(shape, 2.0 * fine.h, (fine.off - shift) // 2, 0.5 * fine.h)
        level.prolong_axes = [
            _prolongation_1d(nf, nc, shift).toarray()
            for nf, nc in zip(fine.shape, shape, strict=True)
        ]
        return level

    # ----------------------------------------------------------------- set-up per tangent
    def set_tangent(self) -> None:
        """Take the points' moduli as they are (the tangent the implicit step just took):
        each level's mass, unknowns, block diagonal and eigenvalue bound."""
        cut = float(self.st.cfg.mass_cut)
        fine = self.levels[0]
        wall = np.zeros_like(fine.free)
        for k, level in enumerate(self.levels):
            if k == 0:
                level.quadrature = np.empty((self.st.cfg.n_points, self.dim + 4))
                points_quadrature(self.st, level.quadrature)
            else:
                level.quadrature = merged_quadrature(self.levels[k - 1], self.dim)
            diag = np.zeros(level.nodes * self.dim * self.dim)
            level.mass = np.zeros(level.nodes)
            point_tangent_diagonal(self.dim, level.quadrature, diag, level.mass, *self._grid(level))
            diag = diag.reshape(level.nodes, self.dim, self.dim)
            if k == 0:
                wall = (fine.mass[:, None] > cut) & ~fine.free  # walls hold these
                d = self.fixed.diagonal()
                diag[self.unknown_node, self.unknown_comp, self.unknown_comp] += d
            else:
                wall = self._restrict_values(k, wall.astype(float)) > 0.0
                level.free = (level.mass[:, None] > cut * 2 ** (self.dim * k)) & ~wall
                idx = np.arange(self.dim)
                diag[:, idx, idx] += (level.mass / self.dt)[:, None]
            level.diagonal = diag
            level.inverse_diagonal = _masked_inverse(diag, level.free)
            level.lambda_max = EIGEN_SAFETY * self._power_iteration(k)
        self.coarsest = self._coarsest_factor()

    def coarsest_matrix(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The coarsest level's unknowns (flat node * dim + component) and its matrix over
        them, assembled from its quadrature points by one kernel (the tangent's entries, the
        lumped mass over dt); None where the finest level is the only one or the coarsest has
        more than COARSEST_UNKNOWNS unknowns."""
        k = len(self.levels) - 1
        level = self.levels[k]
        rows = np.flatnonzero(level.free.reshape(-1))
        if k == 0 or len(rows) > COARSEST_UNKNOWNS:
            return None
        unknown = np.full(level.free.size, -1, dtype=np.int32)
        unknown[rows] = np.arange(len(rows), dtype=np.int32)
        M = np.zeros((len(rows), len(rows)))
        point_tangent_matrix(self.dim, level.quadrature, unknown, M, *self._grid(level))
        M[np.diag_indices_from(M)] += np.repeat(level.mass / self.dt, self.dim)[rows]
        return rows, M

    def _coarsest_factor(self):
        """:meth:`coarsest_matrix`'s Cholesky factor; None where there is none or the matrix
        is not positive definite (the cycle then smooths there instead)."""
        coarsest = self.coarsest_matrix()
        if coarsest is None:
            return None
        rows, M = coarsest
        try:
            return rows, scipy.linalg.cho_factor(0.5 * (M + M.T))
        except np.linalg.LinAlgError:
            return None

    @property
    def nbytes(self) -> int:
        """The hierarchy's arrays (host memory), summed over its levels."""
        arrays = ("free", "mass", "diagonal", "inverse_diagonal", "quadrature")
        return sum(
            getattr(level, a).nbytes
            for level in self.levels
            for a in arrays
            if getattr(level, a) is not None
        )

    @staticmethod
    def _grid(level: Level) -> tuple:
        """The kernels' grid arguments: shape, 1 / h, h, the quadrature's l_p, the origin."""
        shape = np.asarray(level.shape, dtype=np.int32)
        return shape, 1.0 / level.h, level.h, level.lp, level.off

    def _power_iteration(self, k: int) -> float:
        level = self.levels[k]
        rng = np.random.default_rng(0)
        x = rng.standard_normal((level.nodes, self.dim)) * level.free
        lam = 1.0
        for _ in range(POWER_ITERATIONS):
            norm = np.linalg.norm(x)
            if norm == 0.0:
                return 1.0
            x /= norm
            y = self._jacobi(k, self.apply(k, x))
            lam = float(np.sum(x * y))
            x = y
        return max(lam, 1e-300)

    # ----------------------------------------------------------------- operators
    def apply(self, k: int, x: np.ndarray) -> np.ndarray:
        """A_k x on level k's dense (nodes, dim) array, zero on its non-unknowns."""
        level = self.levels[k]
        y = np.zeros(level.nodes * self.dim)
        x = np.ascontiguousarray(x).reshape(-1)
        apply_point_tangent(self.dim, level.quadrature, x, y, *self._grid(level))
        x = x.reshape(level.nodes, self.dim)
        y = y.reshape(level.nodes, self.dim)
        if k == 0:
            y[self.unknown_node, self.unknown_comp] += (
                self.fixed @ x[self.unknown_node, self.unknown_comp]
            )
        else:
            y += (level.mass / self.dt)[:, None] * x
        return y * level.free

    def _jacobi(self, k: int, r: np.ndarray) -> np.ndarray:
        return np.einsum("nab,nb->na", self.levels[k].inverse_diagonal, r)

    def _prolong(self, k: int, xc: np.ndarray) -> np.ndarray:
        """Level k's correction on level k - 1's nodes."""
        coarse, fine = self.levels[k], self.levels[k - 1]
        x = xc.reshape(*coarse.shape, self.dim)
        for axis, P in enumerate(coarse.prolong_axes):
            x = np.moveaxis(np.tensordot(P, x, axes=([1], [axis])), 0, axis)
        return x.reshape(fine.nodes, self.dim) * fine.free

    def _restrict_values(self, k: int, xf: np.ndarray) -> np.ndarray:
        """P^T of level k - 1's (nodes, dim) array, on level k."""
        coarse, fine = self.levels[k], self.levels[k - 1]
        x = xf.reshape(*fine.shape, self.dim)
        for axis, P in enumerate(coarse.prolong_axes):
            x = np.moveaxis(np.tensordot(P.T, x, axes=([1], [axis])), 0, axis)
        return x.reshape(coarse.nodes, self.dim)

    def _smooth(self, k: int, b: np.ndarray, x: np.ndarray | None, degree: int) -> np.ndarray:
        """Chebyshev on D^-1 A over [SMOOTHED_FRACTION lambda_max, lambda_max] from x (None:
        0)."""
        level = self.levels[k]
        hi = level.lambda_max
        lo = SMOOTHED_FRACTION * hi
        theta, delta = 0.5 * (hi + lo), 0.5 * (hi - lo)
        sigma = theta / delta
        rho = 1.0 / sigma
        r = b.copy() if x is None else b - self.apply(k, x)
        x = np.zeros_like(b) if x is None else x.copy()
        d = self._jacobi(k, r) / theta
        for i in range(degree):
            x += d
            if i == degree - 1:
                break
            r -= self.apply(k, d)
            rho_next = 1.0 / (2.0 * sigma - rho)
            d = rho_next * rho * d + (2.0 * rho_next / delta) * self._jacobi(k, r)
            rho = rho_next
        return x

    def vcycle(self, k: int, b: np.ndarray) -> np.ndarray:
        if k == len(self.levels) - 1:
            if self.coarsest is None:
                return self._smooth(k, b, None, COARSEST_DEGREE)
            rows, factor = self.coarsest
            x = np.zeros(b.size)
            x[rows] = scipy.linalg.cho_solve(factor, b.reshape(-1)[rows])
            return x.reshape(b.shape)
        x = self._smooth(k, b, None, SMOOTHING_DEGREE)
        r = b - self.apply(k, x)
        rc = self._restrict_values(k + 1, r) * self.levels[k + 1].free
        x += self._prolong(k + 1, self.vcycle(k + 1, rc))
        return self._smooth(k, b, x, SMOOTHING_DEGREE)

    # ----------------------------------------------------------------- on the unknowns
    def dense(self, v: np.ndarray) -> np.ndarray:
        x = np.zeros((self.levels[0].nodes, self.dim))
        x[self.unknown_node, self.unknown_comp] = v
        return x

    def sparse(self, x: np.ndarray) -> np.ndarray:
        return x[self.unknown_node, self.unknown_comp]

    def solve(self, b: np.ndarray, rtol: float, limit: int) -> tuple[np.ndarray, int, float]:
        """CG on A x = b (the unknowns' vector) from 0, preconditioned by one V-cycle:
        (x, iterations, relative residual)."""
        r = self.dense(b)
        x = np.zeros_like(r)
        norm_b = np.linalg.norm(r)
        if norm_b == 0.0:
            return self.sparse(x), 0, 0.0
        z = self.vcycle(0, r)
        p = z.copy()
        rz = float(np.sum(r * z))
        for it in range(1, limit + 1):
            Ap = self.apply(0, p)
            alpha = rz / float(np.sum(p * Ap))
            x += alpha * p
            r -= alpha * Ap
            res = np.linalg.norm(r) / norm_b
            if res <= rtol:
                return self.sparse(x), it, res
            z = self.vcycle(0, r)
            rz, rz_old = float(np.sum(r * z)), rz
            p = z + (rz / rz_old) * p
        raise MatrixFreeError(
            f"conjugate gradients with the multigrid reached the relative residual {res:.2e} "
            f"in {limit} iterations, not {rtol:g}"
        )


def merged_quadrature(finer: Level, dim: int) -> np.ndarray:
    """The quadrature points of ``finer`` merged cell by cell (cells of its spacing): volumes
    and masses summed, the moduli and the position averaged by volume (by mass where no
    point of the cell has a tangent)."""
    q = finer.quadrature
    V, mass = q[:, dim], q[:, dim + 3]
    cells = np.floor(q[:, :dim] / finer.h).astype(np.int64)
    _, cell = np.unique(cells, axis=0, return_inverse=True)
    cell = cell.reshape(-1)
    n = int(cell.max()) + 1 if len(cell) else 0
    V_cell = np.bincount(cell, V, n)
    m_cell = np.bincount(cell, mass, n)
    weight = np.where(V_cell[cell] > 0.0, V, mass)
    w_cell = np.bincount(cell, weight, n)
    merged = np.empty((n, dim + 4))
    for c in range(dim):
        merged[:, c] = np.bincount(cell, weight * q[:, c], n) / w_cell
    for c in (1, 2):  # the moduli, by volume
        merged[:, dim + c] = np.bincount(cell, V * q[:, dim + c], n) / np.maximum(V_cell, 1e-300)
    merged[:, dim] = V_cell
    merged[:, dim + 3] = m_cell
    return merged


def _masked_inverse(diag: np.ndarray, free: np.ndarray) -> np.ndarray:
    """The inverse of each node's block over its unknown components, zero elsewhere."""
    mask = free[:, :, None] & free[:, None, :]
    eye = np.broadcast_to(np.eye(diag.shape[1], dtype=bool), diag.shape)
    safe = np.where(mask, diag, 0.0) + np.where(eye & ~mask, 1.0, 0.0)
    bad = np.abs(np.linalg.det(safe)) == 0.0
    safe[bad] = np.eye(diag.shape[1])
    return np.linalg.inv(safe) * mask


_BLAS: ThreadpoolController | None = None


def one_blas_thread() -> object:
    """A context in which numpy's and scipy's BLAS run on one thread. The cycle's dense work is
    small (the coarsest Cholesky, some thousand unknowns; the prolongation's products), and
    OpenBLAS's threads spin for a core: where the other core is busy (Taichi's threads, another
    run, a test worker) a 2-thread call took 75x longer than on one thread."""
    global _BLAS
    if _BLAS is None:
        _BLAS = ThreadpoolController()
    return _BLAS.limit(limits=1, user_api="blas")


class MatrixFreeSolver:
    """The implicit step's linear solves for one step without assembled tangent rows (module
    docstring): the interface of solver/linear_solve.py's LinearSolver, the matrix argument
    unused (the multigrid holds the points' tangent last taken)."""

    how = "matrix_free"

    def __init__(self, st: State, sys_: GridSystem, rtol: float = LINEAR_RTOL) -> None:
        self.rtol = rtol
        self.stats = SolveStats()
        self.multigrid = GridMultigrid(st, sys_.dof_node, sys_.fixed_matrix)

    @classmethod
    def for_step(cls, previous: object, st: State, sys_: GridSystem) -> "MatrixFreeSolver":
        """The solver of a new step's system, its counts going on from ``previous``'s where
        that was one (the run records them)."""
        solver = cls(st, sys_)
        if isinstance(previous, cls):
            solver.stats = previous.stats
        return solver

    def set_tangent(self) -> None:
        """Take the points' moduli the force pass just kept."""
        with one_blas_thread():
            self.multigrid.set_tangent()
        self.stats.factorizations += 1

    def solve(
        self, A: None, b: np.ndarray, refresh: bool = False, keys: np.ndarray | None = None
    ) -> np.ndarray:
        """LinearSolver.solve's call; ``refresh`` and ``keys`` unused (a cycle a tangent)."""
        self.stats.solves += 1
        with one_blas_thread():
            x, iterations, _ = self.multigrid.solve(b, self.rtol, CG_MAX_ITERATIONS)
        self.stats.cg_iterations += iterations
        return x
