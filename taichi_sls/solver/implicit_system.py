"""The implicit step's linear system on the grid (solver/implicit.py): its unknowns, the grid
velocity components that are free, numbered node by node in index order, and the rows of its
matrix gathered from the WIDTH^dim node rows the kernels scatter into (physics/stiffness.py),
laid out as a CSR matrix."""

import enum
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from taichi_sls.backend import ti

from ..physics.stiffness import REACH, WIDTH, mirrored_slot, stencil_offset


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
def tangent_entry(K: ti.template(), I, o, r, a, b, dim: ti.template()):
    """Entry (a, b) of slot r (offset o) of node I's row of the symmetric tangent, whose points
    wrote its upper triangle alone (physics/stiffness.py)."""
    J, q, flipped = mirrored_slot(I, o, r, dim)
    value = 0.0
    if flipped or (a > b and (q == REACH).all()):  # below the diagonal
        value = K[J, q, b, a]
    else:
        value = K[J, q, a, b]
    return value


@ti.func
def dof_index(st: ti.template(), dof_node: ti.template(), k):
    """The node of unknown k (its component: ``dof_node[k, dim]``)."""
    return ti.Vector([dof_node[k, a] for a in ti.static(range(st.cfg.dim))])


KEY_BITS = 20  # GridSystem.keys: the bits of a node index along one axis


def unknown_keys(nodes: np.ndarray, component: np.ndarray | None = None) -> np.ndarray:
    """Each unknown (node ``nodes[k]``, its component ``component[k]``) as one integer,
    ascending as the unknowns are numbered (node index order, the last axis fastest, then the
    component): the same unknown has the same key in every step of a run (LinearSolver.solve).
    2^KEY_BITS nodes an axis at most."""
    dim = nodes.shape[1]
    key = np.zeros(len(nodes), dtype=np.int64)
    for a in range(dim):
        key = (key << KEY_BITS) + nodes[:, a]
    return key if component is None else key * dim + component


class Part(enum.IntEnum):
    """What :func:`gather` reads: the fixed matrix with its columns, the right-hand side and
    the first iterate; the points' tangent and the internal force; the internal force alone."""

    FIXED = 0
    TANGENT = 1
    FORCE = 2
    RHS = 3  # the right-hand side and the first iterate alone (the matrix-free step's)


@ti.kernel
def gather(
    st: ti.template(),
    dof_node: ti.types.ndarray(),
    cols: ti.types.ndarray(),
    vals: ti.types.ndarray(),
    vec: ti.types.ndarray(),
    guess: ti.types.ndarray(),
    part: ti.i32,
):
    """Row k of the fixed matrix or of the tangent (the WIDTH^dim x dim slots of node-component
    k; cols -1 where the neighbour's component is not an unknown, the entry 0 where either
    component is not free: an unknown the envelope pins) and a vector, as ``part``
    (:class:`Part`) says: FIXED the columns, the right-hand side m v^n / dt + f into vec and v^n
    into guess; TANGENT and FORCE the internal force into vec; RHS the right-hand side and v^n
    alone. One kernel for the four (a template per part would compile four)."""
    nd = ti.static(st.nodes)
    for k in range(vec.shape[0]):
        I = dof_index(st, dof_node, k)
        a = dof_node[k, st.cfg.dim]
        if part == Part.FIXED or part == Part.TANGENT:
            for r in range(WIDTH**st.cfg.dim):  # the row's nodes, the last axis fastest
                o, J, inside = row_neighbour(st.implicit.dof, I, r)
                for b in ti.static(range(st.cfg.dim)):
                    slot = r * st.cfg.dim + b
                    c = -1
                    if inside:
                        c = st.implicit.dof[J][b]
                    value = 0.0
                    if c >= 0:
                        # an unknown the step pins (solver/envelope.py) is coupled to nothing
                        if st.implicit.free[I][a] != 0 and st.implicit.free[J][b] != 0:
                            if part == Part.FIXED:
                                if a == b:  # a scalar times the identity (ImplicitFields)
                                    value = st.implicit.fixed[I, o]
                            elif ti.static(not st.cfg.matrix_free):
                                K = ti.static(st.implicit.tangent)
                                value = tangent_entry(K, I, o, r, a, b, st.cfg.dim)
                    vals[k, slot] = value
                    if part == Part.FIXED:
                        cols[k, slot] = c
        free = ti.cast(st.implicit.free[I][a], float)  # 0: pinned, no force, at rest
        if part == Part.FIXED or part == Part.RHS:
            vec[k] = (nd.mass[I] * nd.v_old[I][a] / st.scalars.dt[None] + nd.force[I][a]) * free
            guess[k] = nd.v[I][a]
        else:
            vec[k] = st.implicit.internal[I][a] * free


@ti.kernel
def fixed_product(
    st: ti.template(),
    dof_node: ti.types.ndarray(),
    x: ti.types.ndarray(),
    y: ti.types.ndarray(),
    diagonal: ti.i32,
):
    """y = F x over the unknowns, F the fixed part's rows as the grid holds them (a scalar per
    neighbour times the identity), without gathering them; ``diagonal``: y = F's diagonal."""
    for k in range(y.shape[0]):
        I = dof_index(st, dof_node, k)
        a = dof_node[k, st.cfg.dim]
        total = 0.0
        if diagonal:
            total = st.implicit.fixed[I, ti.Vector([REACH] * st.cfg.dim)]
        else:
            for r in range(WIDTH**st.cfg.dim):
                o, J, inside = row_neighbour(st.implicit.dof, I, r)
                if inside:
                    c = st.implicit.dof[J][a]
                    if c >= 0:
                        total += st.implicit.fixed[I, o] * x[c]
        y[k] = total


class FixedRows:
    """The fixed part as an operator on the unknowns (``F @ x``, ``F.diagonal()``), read from
    the grid's rows where they are (the matrix-free step: no CSR copy on the host)."""

    def __init__(self, st, dof_node: np.ndarray) -> None:
        self.st, self.dof_node = st, dof_node

    def __matmul__(self, x: np.ndarray) -> np.ndarray:
        y = np.empty(len(self.dof_node))
        fixed_product(self.st, self.dof_node, np.ascontiguousarray(x), y, 0)
        return y

    def diagonal(self) -> np.ndarray:
        y = np.empty(len(self.dof_node))
        fixed_product(self.st, self.dof_node, y, y, 1)
        return y


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
    rows: FixedRows | None = None  # the fixed part on the grid (matrix-free: nothing gathered)

    @property
    def n(self) -> int:
        return len(self.rhs)

    @cached_property
    def fixed_matrix(self) -> "sp.csr_matrix | FixedRows":
        """The fixed part alone, which every residual evaluation multiplies."""
        return self.rows if self.rows is not None else self.matrix(self.fixed)

    def matrix(self, values: np.ndarray) -> sp.csr_matrix:
        A = sp.csr_matrix((values, self.indices, self.indptr), shape=(self.n, self.n))
        A.has_sorted_indices = True
        return A

    @cached_property
    def entry_rows(self) -> np.ndarray:
        """The row of each stored entry."""
        return np.repeat(np.arange(self.n), np.diff(self.indptr))

    @property
    def diagonal(self) -> np.ndarray:
        """Where the stored entries hold the diagonal."""
        return np.flatnonzero(self.entry_rows == self.indices)

    def second_differences(self) -> np.ndarray:
        """On the stored entries: the sum of w w^T, w = (1, -2, 1), over the triples of
        unknowns (i - e, i, i + e) of one component along each axis. Zero on any linear
        velocity field; positive on a node that moves against its neighbours. All three lie
        within REACH of each other, so the matrix's pattern holds every entry."""
        dim = self.dof_node.shape[1] - 1
        node, comp = self.dof_node[:, :dim].astype(np.int64), self.dof_node[:, dim]
        node = node - node.min(axis=0) + 1  # a ring of non-unknowns around them
        unknown = np.full((*(node.max(axis=0) + 2), dim), -1, dtype=np.int64)
        unknown[(*node.T, comp)] = np.arange(self.n)
        rows, cols, vals = [], [], []
        weights = np.array([1.0, -2.0, 1.0])
        for axis in range(dim):
            step = np.eye(dim, dtype=np.int64)[axis]
            below = unknown[(*(node - step).T, comp)]
            above = unknown[(*(node + step).T, comp)]
            ok = (below >= 0) & (above >= 0)
            triple = (below[ok], np.flatnonzero(ok), above[ok])
            for a in range(3):
                for b in range(3):
                    rows.append(triple[a])
                    cols.append(triple[b])
                    vals.append(np.full(ok.sum(), weights[a] * weights[b]))
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        keys = self.entry_rows * self.n + self.indices
        where = np.searchsorted(keys, rows * self.n + cols)
        values = np.zeros(len(self.indices))
        np.add.at(values, where, np.concatenate(vals))
        return values

    @cached_property
    def keys(self) -> np.ndarray:
        """Each unknown as one integer (:func:`unknown_keys`)."""
        dim = self.dof_node.shape[1] - 1
        return unknown_keys(self.dof_node[:, :dim], self.dof_node[:, dim])

    def rigid_body_modes(self) -> np.ndarray:
        """The grid velocities of rigid motions at the unknowns, one column each: dim
        translations and dim (dim - 1) / 2 rotations about the unknowns' centre, in cells (the
        near-null modes of the elastic tangent, for smoothed aggregation)."""
        dim = self.dof_node.shape[1] - 1
        x = self.dof_node[:, :dim].astype(float)
        x -= x.mean(axis=0)
        comp = self.dof_node[:, dim]
        modes = [(comp == a).astype(float) for a in range(dim)]
        for a, b in ((0, 1), (1, 2), (2, 0))[: 1 if dim == 2 else 3]:
            # rotation in the a-b plane: u_a = -x_b, u_b = x_a
            modes.append(np.where(comp == a, -x[:, b], 0.0) + np.where(comp == b, x[:, a], 0.0))
        return np.stack(modes, axis=1)

    def add_to_fixed(self, values: np.ndarray) -> None:
        """Add values on the stored entries to the fixed part (before any residual)."""
        self.fixed = self.fixed + values
        self.__dict__.pop("fixed_matrix", None)
