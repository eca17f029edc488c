"""The implicit step (``time.integrator = "implicit"``): backward Euler for the grid velocities.

One step, over the explicit step's stages (solver/step.py) where they are the same physics:

    heat       explicit substeps of the heat stages, or one backward-Euler heat step
               (solver/implicit_heat.py), on the points where the step starts; the thermal
               strain summed over the step, so that its mechanics sees it
    begin      clear_grid, p2g (mass, momentum, body force; no stress force), surface force at
               x^n; the inertia m_i / dt and the capillary stiffness (physics/stiffness.py); v^n
    Newton     R(v) = (m / dt + dt K^cap) v - (m v^n / dt + f^ext + f^cap) - f^int(v) = 0 over
               the grid velocity components that are free (node mass above the cut-off, walls
               removed): f^int from each point's Perzyna update with L(v) (not kept), the
               tangent from its secant moduli at v^n, factorized once and kept while Newton
               contracts fast (a new one where it does not); a sparse solve per iteration and
               a backtracking line search on |R|; with ``time.implicit_velocity_penalty``
               a penalty on the velocity's second differences in the fixed part, against the
               light nodes' near-null modes
    end        g2p with the converged v (velocity transfer, motion, the stress kept), watch,
               the active region, the clock

The internal force of the new stress is taken on the configuration at t^n, where the shape
functions are evaluated: f_i = -V_p^n sigma^{n+1} grad N_i(x_p^n), linear in the stress, so that
the material tangent is the whole tangent (the first Piola form det(f) sigma f^-T of the step,
f = I + dt L, would add a geometric nonlinearity that the material tangent misses: Newton
stalls and a large step blows up).

Linear solver (``time.linear_solver``, solver/linear_solve.py): an LDL^T factorization up to
``direct_max_unknowns``, else pyamg's smoothed aggregation, either kept as the preconditioner of
conjugate gradients over the next iterations and steps. The matrix is symmetric positive definite
(physics/stiffness.py).
"""

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from taichi_sls.backend import ti

from ..config import Case
from ..physics.codes import SurfaceMethod
from ..physics.constitutive import trial_stress
from ..physics.dilatation import cell_pressure_force, cell_velocity_gradient
from ..physics.grid import active, ramped_gamma
from ..physics.mechanics import apply_walls, interpolate_velocity
from ..physics.shape import STENCIL_SHAPE, node_weight
from ..physics.small_matrix import ZERO_VECTOR
from ..physics.stiffness import (
    WIDTH,
    capillary_tangent,
    clear_row,
    scatter_mass,
    scatter_tangent,
)
from . import checkpoint, struct_copy
from .envelope import Envelope, envelope_pattern, pin
from .fields import State, clear_rows
from .guard import SimulationError
from .implicit_heat import StepHeat
from .implicit_system import FixedRows, GridSystem, Part, dof_index, gather
from .linear_solve import LinearSolveError, LinearSolver, linear_solver, nested_ordering
from .loops import check_block, grow_box, in_order, point_loop, point_stencil
from .multigrid import MatrixFreeSolver
from .step import (
    advance_clock,
    clear_grid,
    g2p_point_mechanics,
    init_box,
    p2g,
    surface_force,
    watch,
)
from .stepper import NO_HOOKS, StepHooks, fixed_steps_to, whole_steps

# the stages of the explicit step that the implicit one runs before its Newton loop
BEFORE = (clear_grid, p2g, surface_force)
LINE_SEARCH_HALVINGS = 8
# Newton keeps its matrix while an iteration cuts the residual to this fraction or less
SLOW_CONTRACTION = 0.5
# the relative residual of a Newton step's linear solve (an inexact Newton direction: the
# iteration itself drives the momentum residual to time.newton_tolerance)
LINEAR_RTOL = 1e-6
# the warm-up step that compiles the kernels, as a fraction of the step (ImplicitStepper.compile)
WARM_UP_FRACTION = 1e-3


class NewtonError(SimulationError):
    """The implicit step did not converge: the message gives the residual and what to try."""


@dataclass
class StepReport:
    """What the last implicit step did: Newton iterations, unknowns, relative residual."""

    iterations: int = 0
    unknowns: int = 0
    residual: float = 0.0
    solver: str = ""


# ----------------------------------------------------------------------------- kernels
def begin(st: State) -> None:
    """Everything of the step before the Newton loop (module docstring)."""
    if st.cfg.sparse_rows:
        clear_rows(st.implicit.fixed)
    in_order(st, _begin)


@ti.func
def _begin(st: ti.template()):
    for stage in ti.static(BEFORE):
        stage(st, False, True)
    nd = ti.static(st.nodes)
    dt = st.scalars.dt[None]
    for I in ti.grouped(ti.ndrange(*active(st.box))):
        if ti.static(not st.cfg.sparse_rows):
            clear_row(st.implicit.fixed, I, st.cfg.dim)
        m = nd.mass[I]
        vn = ti.Vector(ZERO_VECTOR[st.cfg.dim])
        free = ti.Vector.zero(ti.i32, st.cfg.dim)
        if m > st.cfg.mass_cut:
            vn = nd.momentum[I] / m
            free = ti.cast(apply_walls(st.cfg, I, ti.Vector.one(float, st.cfg.dim)), ti.i32)
            scatter_mass(st.cfg, st.implicit.fixed, I, m / dt)
        nd.v_old[I] = vn
        nd.v[I] = vn * ti.cast(free, float)
        st.implicit.free[I] = free
    if ti.static(st.cfg.surface and st.cfg.surface_method == SurfaceMethod.SURFACE_ENERGY):
        # nd.colour is the one the surface force contoured
        capillary_tangent(
            st.cfg, st.box, nd, st.implicit.fixed, dt * ramped_gamma(st.cfg, st.scalars.t[None])
        )


@ti.func
def _point_force(st: ti.template(), p):
    """Point p's internal force of its trial stress at the grid velocity, scattered; returns
    what its tangent needs."""
    pt = ti.static(st.points)
    dt = st.scalars.dt[None]
    base, w, dw = point_stencil(st.cfg, pt, p)
    v_grid, L = interpolate_velocity(st.cfg, st.nodes, base, w, dw)
    if ti.static(st.cfg.cell_dilatation):  # the cell's dilatation, as the explicit step's
        L = cell_velocity_gradient(st.cfg, st.nodes, pt.x[p], L)
    sig, mu_t, K, eta = trial_stress(st.cfg, pt, st.materials, p, L, dt)
    V = pt.volume0[p] * pt.J[p]
    if ti.static(st.cfg.cell_dilatation):  # the mean stress through the cell's gradient
        sig = cell_pressure_force(st.cfg, st.nodes, st.implicit.internal, pt.x[p], V, sig)
    for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[st.cfg.dim])):
        N, gN = node_weight(w, dw, o)
        st.implicit.internal[base + o] += -V * (sig @ gN)
    a_lam = dt * (K - 2.0 * mu_t / 3.0) - 2.0 * eta / 3.0
    a_mu = dt * mu_t + eta
    return base, w, dw, V, a_lam, a_mu


@ti.func
def _force_body(st: ti.template(), p, blk, heat: ti.template(), geom: ti.template()):
    base, w, dw, V, a_lam, a_mu = _point_force(st, p)
    if st.implicit.with_tangent[None]:
        if ti.static(st.cfg.matrix_free):  # kept per point, applied by solver/multigrid.py
            st.implicit.moduli[p] = ti.Vector([V, a_lam, a_mu])
        else:
            xp = st.points.x[p]
            scatter_tangent(st.cfg, st.implicit.tangent, st.nodes, base, w, dw, xp, V, a_lam, a_mu)


@ti.kernel
def internal_force(st: ti.template(), v: ti.types.ndarray(), dof_node: ti.types.ndarray()):
    """The grid velocity from the unknowns v, then f^int(v) and (``implicit.with_tangent``)
    the points' tangent. A flag read at run time, not a template argument: one kernel whose
    front end builds the stress update once, instead of two."""
    if ti.static(st.cfg.parallel):
        _internal_force(st, v, dof_node)
    else:
        ti.loop_config(serialize=True)
        for _ in range(1):
            _internal_force(st, v, dof_node)


@ti.func
def _internal_force(st: ti.template(), v: ti.template(), dof_node: ti.template()):
    nd = ti.static(st.nodes)
    for I in ti.grouped(ti.ndrange(*active(st.box))):
        if ti.static(not st.cfg.sparse_rows and not st.cfg.matrix_free):
            if st.implicit.with_tangent[None]:
                clear_row(st.implicit.tangent, I, st.cfg.dim, True)
        st.implicit.internal[I] = ti.Vector(ZERO_VECTOR[st.cfg.dim])
        nd.v[I] = ti.Vector(ZERO_VECTOR[st.cfg.dim])
    for k in range(v.shape[0]):
        nd.v[dof_index(st, dof_node, k)][dof_node[k, st.cfg.dim]] = v[k]
    point_loop(st, _force_body, False, False, True)


@ti.func
def _end_body(st: ti.template(), p, blk, heat: ti.template(), geom: ti.template()):
    base, w, dw = point_stencil(st.cfg, st.points, p)
    g2p_point_mechanics(st, p, base, w, dw, st.scalars.dt[None], True)
    if ti.static(st.cfg.th_strain):
        st.points.iso_strain_step[p] = 0.0  # the next step sums its substeps' strain afresh
    watch(st, p)
    grow_box(st, blk, p)
    check_block(st, blk, p)


@ti.kernel
def end(st: ti.template()):
    """The converged grid velocity to the points: velocity, motion and the kept stress."""
    point_loop(st, _end_body, True, True, False)  # each point writes its own state only
    advance_clock(st, True, True)


# ----------------------------------------------------------------------------- the step
class ImplicitStepper:
    """Backward-Euler steps of one State (module docstring)."""

    def __init__(self, case: Case, st: State, heat_substeps: int, dt: float | None = None) -> None:
        self.case = case
        self.st = st
        # the fixed step of advance_to (s; default the state's): the whole steps nearest to t
        self.dt = float(st.scalars.dt[None]) if dt is None else dt
        self.heat = StepHeat(case, st, heat_substeps)  # 0 substeps: no heat
        self.tol = case.time.newton_tolerance
        self.max_iterations = case.time.newton_max_iterations
        self.penalty = case.time.implicit_velocity_penalty
        self.last = StepReport()
        self.newton_total = 0
        self.linear: LinearSolver | None = None
        self.envelope = Envelope() if envelope_pattern(case) else None  # solver/envelope.py
        self._slots = WIDTH**st.cfg.dim * st.cfg.dim

    def advance(self, n: int) -> None:
        for _ in range(n):
            self.step()

    @property
    def last_dt(self) -> float:
        return self.dt

    def advance_to(self, t: float, hooks: StepHooks = NO_HOOKS) -> int:
        """The whole steps of dt nearest to t (s) (:mod:`taichi_sls.solver.stepper`)."""
        n = fixed_steps_to(float(self.st.scalars.t[None]), t, self.dt)
        return whole_steps(self.advance, n, hooks)

    def compile(self, stepper: "ImplicitStepper | None" = None) -> None:
        """Compile every kernel of the step (of ``stepper``'s, which wraps this one) by taking
        a step of WARM_UP_FRACTION of dt from the state as it is and putting everything it
        changed back: so that the run's first implicit step, a hybrid's hand-over, does not pay
        for compilation inside its stepping time."""
        st = self.st
        saved = checkpoint.capture(st)
        scalars = struct_copy.to_numpy(st.scalars)
        sort = int(st.blocks.needs_sort[None]) if st.blocks is not None else 0
        st.scalars.dt[None] = WARM_UP_FRACTION * float(scalars["dt"])
        st.scalars.dt_heat[None] = WARM_UP_FRACTION * float(scalars["dt_heat"])
        try:
            (stepper or self).step()
            sys_ = self.prepare()  # the force without the tangent, which the step may not reach
            if sys_.n:
                self.internal(sys_, sys_.v0, tangent=False)
        except SimulationError:
            pass  # compiled as far as it went; the run's own step reports a failure
        checkpoint.restore(st, saved)
        struct_copy.from_numpy(st.scalars, scalars)
        if st.blocks is not None:
            st.blocks.needs_sort[None] = sort
        init_box(st)
        self.last, self.newton_total, self.linear = StepReport(), 0, None
        self.heat.linear = None

    def step(self) -> None:
        sys_ = self.prepare()
        if sys_.n:
            self.newton(sys_)
        else:
            self.last = StepReport()
        end(self.st)

    def prepare(self) -> GridSystem:
        """The step up to its Newton loop: ``begin``, the unknowns, the fixed matrix."""
        st = self.st
        self.heat.advance()
        begin(st)
        free = struct_copy.to_numpy(st.implicit.numbering, ("free",))["free"]
        unknown = free != 0 if self.envelope is None else self.envelope.unknowns(st, free)
        flat = unknown.reshape(-1)
        dof = np.full(flat.shape, -1, dtype=np.int32)
        n = int(flat.sum())
        dof[flat] = np.arange(n, dtype=np.int32)
        struct_copy.from_numpy(st.implicit.numbering, {"dof": dof.reshape(free.shape)})
        dof_node = np.ascontiguousarray(np.argwhere(unknown).astype(np.int32))
        if st.cfg.matrix_free:  # the fixed rows stay on the grid (implicit_system.FixedRows)
            rhs, v0, none = np.empty(n), np.empty(n), np.empty((0, 0))
            if n:
                gather(st, dof_node, none.astype(np.int32), none, rhs, v0, Part.RHS)
            empty = np.empty(0)
            rows = FixedRows(st, dof_node)
            return GridSystem(dof_node, empty, empty, empty, empty, rhs, v0, rows)
        cols = np.empty((n, self._slots), dtype=np.int32)
        fixed = np.empty((n, self._slots))
        rhs, v0 = np.empty(n), np.empty(n)
        if n:
            gather(st, dof_node, cols, fixed, rhs, v0, Part.FIXED)
            pin(fixed, dof_node, free)  # the envelope's unknowns not free in this step
        slots = cols >= 0
        indptr = np.concatenate([[0], np.cumsum(slots.sum(axis=1))])
        return GridSystem(dof_node, slots, cols[slots], indptr, fixed[slots], rhs, v0)

    def internal(
        self, sys_: GridSystem, v: np.ndarray, tangent: bool = True
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """f^int(v) at the unknowns and (``tangent``) the points' tangent on the stored
        entries."""
        st = self.st
        st.implicit.with_tangent[None] = int(tangent)
        if tangent and st.cfg.sparse_rows and not st.cfg.matrix_free:
            clear_rows(st.implicit.tangent)
        if tangent and st.cfg.matrix_free:
            st.implicit.moduli.fill(0.0)  # a point the force pass skips adds no tangent
        internal_force(st, v, sys_.dof_node)
        f_int = np.empty(sys_.n)
        cols = np.empty((1, 1), dtype=np.int32)  # not written
        if not tangent or st.cfg.matrix_free:
            gather(st, sys_.dof_node, cols, np.empty((1, 1)), f_int, f_int, Part.FORCE)
            return f_int, None
        vals = np.empty((sys_.n, self._slots))
        gather(st, sys_.dof_node, cols, vals, f_int, f_int, Part.TANGENT)
        return f_int, vals[sys_.slots]

    @staticmethod
    def residual(sys_: GridSystem, v: np.ndarray, f_int: np.ndarray) -> tuple[np.ndarray, float]:
        """R(v) and the force scale it is measured against (module docstring)."""
        Av = sys_.fixed_matrix @ v
        R = Av - sys_.rhs - f_int
        scale = max(np.linalg.norm(Av) + np.linalg.norm(sys_.rhs) + np.linalg.norm(f_int), 1e-300)
        return R, scale

    def newton(self, sys_: GridSystem) -> np.ndarray:
        """Newton with a backtracking line search from v^n to |R| <= tol x scale; leaves the
        converged velocity on the grid and returns it. The matrix (its tangent) is taken at v^n
        and kept while each iteration cuts the residual by SLOW_CONTRACTION or more at a full
        step, else taken afresh at the new iterate: a tangent that changes little over a step
        then costs one factorization and one point pass of the tangent per step."""
        st = self.st
        how = linear_solver(self.case, sys_.n)
        if how == "matrix_free":
            self.linear = MatrixFreeSolver.for_step(self.linear, st, sys_)
        elif self.linear is None or self.linear.how != how:
            self.linear = LinearSolver.for_case(self.case, how, LINEAR_RTOL)
        if how == "amg":  # smoothed aggregation for elasticity (solver/linear_solve.py)
            self.linear.near_null = sys_.rigid_body_modes()
        if how == "direct" and nested_ordering(self.case):
            self.linear.nodes = sys_.keys // st.cfg.dim
        kept = self.case.time.refactorize == "when_slow"
        v = sys_.v0
        f_int, tangent = self.internal(sys_, v)
        if self.penalty > 0.0 and how != "matrix_free":  # the light nodes' near-null modes
            stiffest = np.abs(sys_.fixed + tangent)[sys_.diagonal].max()
            sys_.add_to_fixed(self.penalty * stiffest * sys_.second_differences())
        A = self._newton_matrix(sys_, tangent)
        R, scale = self.residual(sys_, v, f_int)
        it, fresh = 0, True
        where = f"implicit step {int(st.scalars.step[None])} (t = {st.scalars.t[None]:.4g} s)"
        while not np.linalg.norm(R) <= self.tol * scale:  # NaN too
            if it == self.max_iterations or not np.isfinite(R).all():
                raise NewtonError(
                    f"{where}: Newton did not converge in {it} iterations (residual "
                    f"{np.linalg.norm(R) / scale:.2e} of the force scale, tolerance {self.tol:g}); "
                    "try a smaller time.dt_s or a larger time.newton_max_iterations, or where "
                    "light nodes run away (docs/record/implicit.md) "
                    "time.implicit_velocity_penalty = 1e-6"
                )
            try:
                dv = self.linear.solve(
                    A, -R, refresh=fresh and not kept, keys=sys_.keys if kept else None
                )
            except LinearSolveError as e:  # an adaptive run redoes the step smaller
                raise NewtonError(
                    f"{where}: Newton's linear solve failed: {e}; {e.advice} "
                    "(docs/record/implicit.md)"
                ) from e
            fresh = False
            norm0 = np.linalg.norm(R)
            alpha = 1.0
            for _ in range(LINE_SEARCH_HALVINGS):
                v_try = v + alpha * dv
                f_try, _ = self.internal(sys_, v_try, tangent=False)
                R_try, scale_try = self.residual(sys_, v_try, f_try)
                if np.linalg.norm(R_try) < norm0:
                    break
                alpha *= 0.5
            v, f_int, R, scale = v_try, f_try, R_try, scale_try
            it += 1
            slow = alpha < 1.0 or np.linalg.norm(R) > SLOW_CONTRACTION * norm0
            if slow and not np.linalg.norm(R) <= self.tol * scale:
                f_int, tangent = self.internal(sys_, v)
                A, fresh = self._newton_matrix(sys_, tangent), True
        self.newton_total += it
        self.last = StepReport(it, sys_.n, float(np.linalg.norm(R) / scale), how)
        return v

    def _newton_matrix(self, sys_: GridSystem, tangent: np.ndarray | None) -> sp.csr_matrix | None:
        """The Newton matrix of the tangent just taken: assembled, or (matrix-free) None, the
        multigrid taking the points' moduli instead."""
        if tangent is None:
            self.linear.set_tangent()
            return None
        return sys_.matrix(sys_.fixed + tangent)
