"""The heat of the implicit step (solver/implicit.py): explicit substeps, or one backward-Euler
step (``time.heat_integrator``).

Substeps: the explicit step's heat stages (eqs. 28-33) over dt_heat = dt / substeps, each at most
``heat_step_fraction`` of the heat's stability limit, on the points where the step starts.

Backward Euler: the explicit heat step moves the node temperatures by dT_i = dt Q_i / c_i with
the heat rate Q_i = S_i - (K T)_i at the step's start (eq. 29: K_ij = sum_p V_p k_p grad N_ip .
grad N_jp; S_i the laser of eqs. 30-31). This one takes the conduction at the step's end:

    (C / dt + K_ff) dT_f = Q_f^n

over the free nodes (a heat capacity and no fixed temperature; a fixed wall's nodes keep
theirs), and every node's rate becomes Q_i = Q_i^n - (K dT)_i. From there the explicit stages go
on unchanged: dT_i = dt Q_i / c_i, the points' enthalpy (eqs. 32-33), the heat into the fixed
nodes counted as heat out. Since sum_i K_ij = 0, sum_i Q_i = sum_i S_i whatever dT the linear
solver returned: the energy balance holds to round-off at any solve tolerance. The capacities
(the apparent dH/dT, so with the latent heat) and the conductivities are those of the step's
start, so the step is linear, unconditionally stable and first order in time; ``time.adaptive``
bounds the temperature change per step through the melting and freezing ranges, where the
capacity varies.
"""

import numpy as np
import scipy.sparse as sp

from taichi_sls.backend import ti

from ..config import Case
from ..physics.codes import HeatNode
from ..physics.grid import active
from ..physics.stiffness import (
    REACH,
    WIDTH,
    clear_row,
    mirrored_slot,
    scatter_point_conductance,
)
from ..physics.thermal import fixed_temperature, point_conductivity
from . import struct_copy
from .fields import State
from .implicit_system import row_neighbour, unknown_keys
from .linear_solve import LinearSolver, linear_solver, nested_ordering
from .loops import in_order, point_loop, point_stencil
from .step import (
    clear_grid,
    g2p_point_heat,
    grid_temperature_stage,
    grid_update,
    heat_flux,
    p2g,
)
from .time_step import substeps_within

# the explicit step's heat stages up to the nodes' heat rate
RATE_STAGES = (clear_grid, p2g, grid_temperature_stage, heat_flux)
SUBSTEP_STAGES = (*RATE_STAGES, grid_update)
# the relative residual of the linear solve: its error moves heat between nodes, never creates it
HEAT_RTOL = 1e-10


@ti.func
def _heat_body(st: ti.template(), p, blk, heat: ti.template(), geom: ti.template()):
    base, w, dw = point_stencil(st.cfg, st.points, p)
    g2p_point_heat(st, p, blk, base, w, dw, st.scalars.dt[None], heat)


@ti.func
def substep(st: ti.template()):
    """One explicit heat substep over dt_heat."""
    for stage in ti.static(SUBSTEP_STAGES):
        stage(st, True, False)
    point_loop(st, _heat_body, True, False, False)


@ti.func
def _conductance_body(st: ti.template(), p, blk, heat: ti.template(), geom: ti.template()):
    pt = ti.static(st.points)
    base, w, dw = point_stencil(st.cfg, pt, p)
    k = point_conductivity(st.materials[pt.material[p]], pt.solid_fraction[p])
    Vk = pt.volume0[p] * pt.J[p] * k
    scatter_point_conductance(st.cfg, st.implicit.conductance, base, w, dw, Vk)


@ti.func
def rates_and_conductance(st: ti.template()):
    """The heat rate Q^n, each node's kind and the conduction matrix K."""
    for stage in ti.static(RATE_STAGES):
        stage(st, True, False)
    nd = ti.static(st.nodes)
    for I in ti.grouped(ti.ndrange(*active(st.box))):
        clear_row(st.implicit.conductance, I, st.cfg.dim, True)
        kind = HeatNode.EMPTY
        if nd.heat_capacity[I] > 0.0:
            kind = HeatNode.FREE
            fixed, Tw = fixed_temperature(st.cfg, I)
            if fixed:
                kind = HeatNode.FIXED
        st.implicit.heat_node[I] = kind
    point_loop(st, _conductance_body, True, False, True)


@ti.func
def finish(st: ti.template()):
    """The explicit stages after the heat rate: node increments, the points' enthalpy."""
    grid_update(st, True, False)
    point_loop(st, _heat_body, True, False, False)


@ti.func
def _neighbour_unknown(st: ti.template(), I, r):
    """Slot r of node I's row (the WIDTH^dim nodes around it, the last axis fastest): the
    neighbour's unknown (-1: outside the grid or not free) and its conductance, which the points
    wrote in the upper half of the symmetric rows alone (physics/stiffness.py)."""
    o, J, inside = row_neighbour(st.implicit.heat_dof, I, r)
    c = -1
    k = 0.0
    if inside:
        c = st.implicit.heat_dof[J]
        if c >= 0:
            M, q, flipped = mirrored_slot(I, o, r, st.cfg.dim)  # scalar rows: nothing to flip
            k = st.implicit.conductance[M, q]
    return o, c, k


@ti.kernel
def rows_or_flow(
    st: ti.template(),
    nodes: ti.types.ndarray(),
    cols: ti.types.ndarray(),
    vals: ti.types.ndarray(),
    vec: ti.types.ndarray(),
    gather: ti.i32,
):
    """``gather``: row k of C / dt + K_ff for the free node ``nodes[k]``, its slots' columns
    (-1: none) and values, and Q^n into vec. Else, with the solution dT in vec: Q_i -= (K dT)_i
    at every node with a heat capacity, the fixed ones too (their heat out). One kernel for
    both (a kernel's compilation costs tens of ms whatever its size)."""
    nd = ti.static(st.nodes)
    dt = st.scalars.dt_heat[None]
    for k in range(nodes.shape[0] * gather):
        I = ti.Vector([nodes[k, a] for a in ti.static(range(st.cfg.dim))])
        for r in range(WIDTH**st.cfg.dim):
            o, c, conductance = _neighbour_unknown(st, I, r)
            value = 0.0
            if c >= 0:
                value = conductance
                if (o == REACH).all():
                    value += nd.heat_capacity[I] / dt
            vals[k, r] = value
            cols[k, r] = c
        vec[k] = nd.heat_rate[I]
    for I in ti.grouped(st.implicit.heat_node):
        if not gather and st.implicit.heat_node[I] != HeatNode.EMPTY:
            flow = 0.0
            for r in range(WIDTH**st.cfg.dim):
                o, c, conductance = _neighbour_unknown(st, I, r)
                if c >= 0:
                    flow += conductance * vec[c]
            st.nodes.heat_rate[I] -= flow


class StepHeat:
    """The heat of one implicit step (module docstring): ``substeps`` explicit ones of
    dt_heat, or (``cfg.heat_implicit``) one backward-Euler step of dt."""

    def __init__(self, case: Case, st: State, substeps: int) -> None:
        self.case = case
        self.st = st
        self.substeps = substeps  # 0: no heat
        self.linear: LinearSolver | None = None

    def set_step(self, dt: float, longest: float) -> None:
        """A step of dt: dt_heat = dt (backward Euler), or the fewest substeps of at most
        ``longest``."""
        if self.substeps == 0:
            return
        if not self.st.cfg.heat_implicit:
            self.substeps = substeps_within(dt, longest)
        self.st.scalars.dt_heat[None] = dt / self.substeps

    def advance(self) -> None:
        """The step's heat, from the clock at the step's start (left there)."""
        st = self.st
        if self.substeps == 0:
            return
        if st.cfg.heat_implicit:
            self._backward_euler()
            return
        t0 = float(st.scalars.t[None])
        dt_heat = float(st.scalars.dt_heat[None])
        for k in range(self.substeps):
            st.scalars.t[None] = t0 + k * dt_heat
            in_order(st, substep)
        st.scalars.t[None] = t0

    def _backward_euler(self) -> None:
        st = self.st
        in_order(st, rates_and_conductance)
        kind = struct_copy.to_numpy(st.implicit.numbering, ("heat_node",))["heat_node"]
        free = kind == HeatNode.FREE
        unknown = np.full(kind.shape, -1, dtype=np.int32)
        n = int(free.sum())
        unknown[free] = np.arange(n, dtype=np.int32)
        struct_copy.from_numpy(st.implicit.numbering, {"heat_dof": unknown})
        if n:
            nodes = np.ascontiguousarray(np.argwhere(free).astype(np.int32))
            slots = WIDTH**st.cfg.dim
            cols = np.empty((n, slots), dtype=np.int32)
            vals, rhs = np.empty((n, slots)), np.empty(n)
            rows_or_flow(st, nodes, cols, vals, rhs, True)
            stored = cols >= 0  # columns ascend: unknowns and slots both run in index order
            A = sp.csr_matrix(
                (vals[stored], cols[stored], np.concatenate([[0], np.cumsum(stored.sum(1))])),
                shape=(n, n),
            )
            A.has_sorted_indices = True
            how = linear_solver(self.case, n, assembled=True)
            if self.linear is None or self.linear.how != how:
                self.linear = LinearSolver.for_case(self.case, how, HEAT_RTOL)
            keys = unknown_keys(nodes)
            if how == "direct" and nested_ordering(self.case):
                self.linear.nodes = keys
            kept = self.case.time.refactorize == "when_slow"
            dT = self.linear.solve(A, rhs, keys=keys if kept else None)
            rows_or_flow(st, nodes, cols, vals, np.ascontiguousarray(dT, dtype=np.float64), False)
        in_order(st, finish)
