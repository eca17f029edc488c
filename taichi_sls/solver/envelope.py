"""The unknowns of a step's Newton system kept across steps (``time.direct_pattern =
"envelope"``), so that the direct factorization's analysis (its elimination order and symbolic
factor, about half the cost of a new 3D factorization) is done again only when the material
leaves the envelope, not at every step.

A step's unknowns are the free velocity components of the nodes whose mass passes the cut
(solver/implicit.py). As the material flows, a few nodes cross the cut at nearly every step,
and each new set of unknowns is a new pattern to analyse. The envelope's unknowns are those of
the step's nodes and of the nodes whose mass passes ENVELOPE_MASS_FRACTION of the cut, the
next to cross it (their components that no wall holds). An unknown of the envelope that is not
free in this step is pinned: its row and column hold the identity, scaled to the step's
diagonal, and nothing else (solver/implicit_system.gather leaves its couplings, right-hand side
and force at zero), so Newton's iterates are the step's own in exact arithmetic, zero on the
pinned. The gathered pattern (a row's full reach among the unknowns) then stays while the
step's free unknowns lie inside the envelope, and the factorization only refreshes its numbers.
"""

import numpy as np

from taichi_sls.backend import ti

from ..config import Case
from ..physics.mechanics import apply_walls
from ..physics.stiffness import WIDTH
from . import struct_copy
from .fields import State

# a node joins the envelope at this fraction of the mass cut: on machine_layer3d's hold 9-10 %
# more nodes than the step's, which its free unknowns stayed inside for 7 steps and more
# (docs/record/implicit.md)
ENVELOPE_MASS_FRACTION = 0.1


def envelope_pattern(case: Case) -> bool:
    """Whether the implicit mechanics number their unknowns over an envelope kept across steps
    (``time.direct_pattern``; "auto": in 3D; the module docstring). Not with a kept
    factorization (``time.refactorize = "when_slow"``, which maps unknowns across steps
    itself), the matrix-free step (no factorization) or the velocity penalty."""
    t = case.time
    if t.refactorize == "when_slow" or t.linear_solver == "matrix_free":
        return False
    if t.implicit_velocity_penalty > 0.0:  # its second differences would couple the pinned
        return False
    return t.direct_pattern == "envelope" or (t.direct_pattern == "auto" and case.domain.dim == 3)


@ti.kernel
def _wall_free(st: ti.template(), out: ti.types.ndarray()):
    """1 where no wall holds a node's velocity component (physics/mechanics.apply_walls)."""
    for I in ti.grouped(st.implicit.free):
        v = apply_walls(st.cfg, I, ti.Vector.one(float, st.cfg.dim))
        for a in ti.static(range(st.cfg.dim)):
            out[I, a] = ti.cast(v[a], ti.i32)


class Envelope:
    """The envelope's nodes (module docstring), rebuilt by :meth:`unknowns` when a step's free
    unknowns leave them."""

    def __init__(self) -> None:
        self.nodes: np.ndarray | None = None  # (grid) bool
        self._wall_free: np.ndarray | None = None  # (grid, dim) bool

    def unknowns(self, st: State, free: np.ndarray) -> np.ndarray:
        """The step's unknowns (grid, dim) bool, given its free components ``free`` (grid,
        dim): the envelope's, a new envelope from the node masses of ``st`` where a free
        component lies outside it."""
        if self._wall_free is None:
            held = np.empty(free.shape, dtype=np.int32)
            _wall_free(st, held)
            self._wall_free = held != 0
        free_nodes = (free != 0).any(axis=-1)
        if self.nodes is None or np.any(free_nodes & ~self.nodes):
            mass = struct_copy.to_numpy(st.nodes, ("mass",))["mass"]
            self.nodes = (mass > ENVELOPE_MASS_FRACTION * st.cfg.mass_cut) | free_nodes
        return self.nodes[..., None] & self._wall_free


def pin(fixed: np.ndarray, dof_node: np.ndarray, free: np.ndarray) -> None:
    """The fixed rows (unknowns, WIDTH^dim x dim slots) of the unknowns ``dof_node`` that are
    not ``free`` (grid, dim) in this step: the identity, scaled to the mean diagonal of the
    free ones (the gather left their other entries at zero)."""
    dim = dof_node.shape[1] - 1
    comp = dof_node[:, dim]
    pinned = free[(*dof_node[:, :dim].T, comp)] == 0
    if not pinned.any():
        return
    diagonal = (WIDTH**dim // 2) * dim + comp  # the own node's slot of each row's component
    rows = np.arange(len(dof_node))
    fixed[rows[pinned], diagonal[pinned]] = np.abs(fixed[rows[~pinned], diagonal[~pinned]]).mean()
