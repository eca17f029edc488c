"""The blocks layout: every CPU core, no contended atomics.

The grid's cells are tiled by square blocks of ``SIDE`` cells, coloured in four by the parity of
their block coordinates, and the points are kept sorted by block. A scatter (P2G) then runs four
passes, one per colour; in each pass the blocks of that colour are shared out among the threads
and every block's points are scattered by one thread, in order, with plain adds: two blocks of
one colour lie a whole block apart, wider than a point's stencil reaches, so no two threads ever
write one node. Gathers (G2P) run over all blocks at once, and what points add to the run's
totals (laser energy, heat through the walls, peak temperature, the active region) goes into
per-block accumulators, summed in block order at the end of the step. So the result does not
depend on the number of threads at all.

A point may drift ``MARGIN`` cells out of its block before the colouring could fail; the step
flags it, and the simulation sorts the points again before the next step.
"""

from __future__ import annotations

import numpy as np

from taichi_sls.backend import ti

SIDE = 12  # cells per block side
MARGIN = 3  # cells a point may leave its block by (the stencils reach 3 nodes: SIDE > 2 MARGIN + 4)
COLOURS = 4
# Taichi's CPU range-for hands each thread tasks of at least 512 iterations, so a loop over a
# few hundred blocks would run on one thread: each block's loop index is spread over SPREAD
# iterations (one does the work) so that every loop over blocks has this many.
LOOP_ITERATIONS = 8192


def block_of(x: np.ndarray, h: float, off: int, n_bx: int, n_by: int) -> np.ndarray:
    """Block index of points at positions x (m): cells counted from the array's origin; a point
    beyond the grid counts in the edge block (the guard names it at the next check)."""
    cell = np.floor(x / h).astype(np.int64) + off
    b = np.clip(cell // SIDE, 0, [n_bx - 1, n_by - 1])
    return (b[:, 1] * n_bx + b[:, 0]).astype(np.int64)


@ti.data_oriented
class BlockPlan:
    """The blocks of a grid of ``nx x ny`` nodes and, per block, its points (a range of the
    sorted points) and accumulators."""

    def __init__(self, nx: int, ny: int, h: float, off: int) -> None:
        self.h, self.off = h, off
        self.n_bx = -(-(nx - 1) // SIDE)
        self.n_by = -(-(ny - 1) // SIDE)
        self.n_blocks = self.n_bx * self.n_by
        per_colour = -(-self.n_bx // 2) * -(-self.n_by // 2)
        self.start = ti.field(ti.i32, self.n_blocks)
        self.count = ti.field(ti.i32, self.n_blocks)
        self.by_colour = ti.field(ti.i32, (COLOURS, per_colour))
        self.n_colour = [0] * COLOURS
        lists: list[list[int]] = [[] for _ in range(COLOURS)]
        for b in range(self.n_blocks):
            bx, by = b % self.n_bx, b // self.n_bx
            lists[(bx % 2) + 2 * (by % 2)].append(b)
        table = np.zeros((COLOURS, per_colour), dtype=np.int32)
        for c, ls in enumerate(lists):
            table[c, : len(ls)] = ls
            self.n_colour[c] = len(ls)
        self.by_colour.from_numpy(table)
        self.spread = -(-LOOP_ITERATIONS // max(1, min(self.n_colour)))
        self.colour_sizes = ti.field(ti.i32, COLOURS)
        self.colour_sizes.from_numpy(np.array(self.n_colour, dtype=np.int32))
        # per-block accumulators of the step (block-owned: plain adds)
        self.laser_energy = ti.field(float, self.n_blocks)
        self.heat_out = ti.field(float, self.n_blocks)
        self.T_peak = ti.field(float, self.n_blocks)
        self.box = ti.Vector.field(4, ti.i32, self.n_blocks)
        self.needs_sort = ti.field(ti.i32, ())
        self.sorts = 0  # how often the points were sorted again during the run
        self.box.fill(0)
        self.box.from_numpy(np.tile(np.array([nx, ny, 0, 0], dtype=np.int32), (self.n_blocks, 1)))
        self.clear_sums()

    def clear_sums(self) -> None:
        """No step's energy or peak in the per-block accumulators (at the start, and where a
        state is put back: a refused step's sums would reach the totals at the next reduction)."""
        self.laser_energy.fill(0.0)
        self.heat_out.fill(0.0)
        self.T_peak.fill(-1e30)

    def order(self, x: np.ndarray) -> np.ndarray:
        """The permutation that sorts points at x by block (stable: cell order kept within)."""
        return np.argsort(block_of(x, self.h, self.off, self.n_bx, self.n_by), kind="stable")

    def set_ranges(self, x_sorted: np.ndarray) -> None:
        """Each block's range of the sorted points."""
        b = block_of(x_sorted, self.h, self.off, self.n_bx, self.n_by)
        count = np.bincount(b, minlength=self.n_blocks).astype(np.int32)
        start = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(np.int32)
        self.start.from_numpy(start)
        self.count.from_numpy(count)
        if self.needs_sort[None]:
            self.sorts += 1
        self.needs_sort[None] = 0
