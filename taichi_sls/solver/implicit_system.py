"""The implicit step's linear system on the grid (solver/implicit.py): its unknowns, the grid
velocity components that are free, numbered node by node in index order, and the rows of its
matrix gathered from the WIDTH^dim node rows the kernels scatter into (physics/stiffness.py),
laid out as a CSR matrix."""

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp
import taichi as ti

from ..physics.stiffness import REACH, WIDTH, stencil_offset


@ti.func
def row_neighbour(grid: ti.template(), I, r):
    """Slot r of node I's row (the WIDTH^dim nodes around it, the last axis fastest) on the
    nodes of field ``grid``: the neighbour's offset in the row, its node and whether it lies in
    the grid."""
    o = stencil_offset(r, ti.static(len(grid.shape)), WIDTH)
    J = I + o - REACH
    inside = (J >= 0).all() and (J < ti.Vector(ti.static(grid.shape))).all()
    return o, J, inside


@ti.func
def dof_index(st: ti.template(), dof_node: ti.template(), k):
    """The node of unknown k (its component: ``dof_node[k, dim]``)."""
    return ti.Vector([dof_node[k, a] for a in ti.static(range(st.cfg.dim))])


@ti.kernel
def gather_force(st: ti.template(), dof_node: ti.types.ndarray(), vec: ti.types.ndarray()):
    """The internal force at the unknowns."""
    for k in range(vec.shape[0]):
        vec[k] = st.implicit.internal[dof_index(st, dof_node, k)][dof_node[k, st.cfg.dim]]


@ti.kernel
def gather(
    st: ti.template(),
    K: ti.template(),
    dof_node: ti.types.ndarray(),
    cols: ti.types.ndarray(),
    vals: ti.types.ndarray(),
    vec: ti.types.ndarray(),
    guess: ti.types.ndarray(),
    fixed: ti.template(),
):
    """Row k of matrix K (the WIDTH^dim x dim slots of node-component k; cols -1 where the
    neighbour's component is not an unknown) and, ``fixed``: the columns, the right-hand side
    m v^n / dt + f into vec and v^n into guess; else: the internal force into vec."""
    nd = ti.static(st.nodes)
    for k in range(vals.shape[0]):
        I = dof_index(st, dof_node, k)
        a = dof_node[k, st.cfg.dim]
        for r in range(WIDTH**st.cfg.dim):  # the row's nodes, the last axis fastest
            o, J, inside = row_neighbour(st.implicit.dof, I, r)
            for b in ti.static(range(st.cfg.dim)):
                slot = r * st.cfg.dim + b
                c = -1
                if inside:
                    c = st.implicit.dof[J][b]
                value = 0.0
                if c >= 0:
                    value = K[I, o, a, b]
                vals[k, slot] = value
                if ti.static(fixed):
                    cols[k, slot] = c
        if ti.static(fixed):
            vec[k] = nd.mass[I] * nd.v_old[I][a] / st.scalars.dt[None] + nd.force[I][a]
            guess[k] = nd.v[I][a]
        else:
            vec[k] = st.implicit.internal[I][a]


@dataclass
class GridSystem:
    """One step's unknowns and the fixed part of its matrix. Unknown k is velocity component
    ``dof_node[k, dim]`` of node ``dof_node[k, :dim]``; ``slots`` picks the stored entries of the
    WIDTH^dim x dim slots of each row (the neighbours' components that are unknowns too), which
    ``indices`` and ``indptr`` lay out as a CSR matrix (columns sorted: unknowns are numbered
    node by node in index order, and the slots run the same way)."""

    dof_node: np.ndarray
    slots: np.ndarray
    indices: np.ndarray
    indptr: np.ndarray
    fixed: np.ndarray  # inertia and capillary stiffness, on the stored entries
    rhs: np.ndarray  # m v^n / dt + f^ext + f^cap
    v0: np.ndarray  # v^n (walls applied): Newton's first iterate

    @property
    def n(self) -> int:
        return len(self.rhs)

    @cached_property
    def fixed_matrix(self) -> sp.csr_matrix:
        """The fixed part alone, which every residual evaluation multiplies."""
        return self.matrix(self.fixed)

    def matrix(self, values: np.ndarray) -> sp.csr_matrix:
        A = sp.csr_matrix((values, self.indices, self.indptr), shape=(self.n, self.n))
        A.has_sorted_indices = True
        return A
