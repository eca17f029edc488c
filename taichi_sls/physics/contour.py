"""Marching squares in one cell: the outline of a node field where it crosses zero, shared by the
CSF level set (its redistancing) and the surface-energy force (its outline)."""

from taichi_sls.backend import ti

from .small_matrix import ZERO_MATRIX, ZERO_VECTOR


@ti.func
def _crossing(pa, pb, fa, fb):
    return pa + (fa / (fa - fb)) * (pb - pa)


@ti.func
def _corner(x0, h, k):
    """Corner k of the cell, counter-clockwise from x0 (the lower left)."""
    return x0 + h * ti.Vector([ti.cast(k == 1 or k == 2, float), ti.cast(k >= 2, float)])


@ti.func
def cell_segments(f, x0, h):
    """f = (f00, f10, f11, f01) counter-clockwise from the lower-left corner x0 of a cell of side
    h, inside where f < 0 (linear along the edges). Returns (count, ends): up to two segments,
    ends = (ax, ay, bx, by) for each; a saddle is resolved by the mean of the four corners.
    The corners and edges are visited by run-time loops: one copy of each body (the front
    end's cost, docs/record/compile.md)."""
    inside = ti.Vector([0, 0, 0, 0])
    n_in = 0
    for k in range(4):
        if f[k] < 0.0:
            inside[k] = 1
            n_in += 1
    count = 0
    ends = ti.Vector(ZERO_VECTOR[8])
    if n_in > 0 and n_in < 4:
        cross = ti.Matrix(ZERO_MATRIX[4, 2])  # crossing on edge k (corner k -> k+1), if any
        for k in range(4):
            k1 = (k + 1) % 4
            if inside[k] != inside[k1]:
                c = _crossing(_corner(x0, h, k), _corner(x0, h, k1), f[k], f[k1])
                cross[k, 0] = c[0]
                cross[k, 1] = c[1]
        saddle = n_in == 2 and inside[0] == inside[2]
        # saddle: cut off the corners whose side differs from the cell centre's
        centre_in = 1 if f.sum() < 0.0 else 0
        n = 0
        for k in range(4):
            if saddle:
                km = (k + 3) % 4  # the edges at corner k: km and k
                if inside[k] != centre_in:
                    ends[4 * count + 0] = cross[km, 0]
                    ends[4 * count + 1] = cross[km, 1]
                    ends[4 * count + 2] = cross[k, 0]
                    ends[4 * count + 3] = cross[k, 1]
                    count += 1
            elif inside[k] != inside[(k + 1) % 4]:
                ends[2 * n + 0] = cross[k, 0]
                ends[2 * n + 1] = cross[k, 1]
                n += 1
        if not saddle:
            count = 1
    return count, ends
