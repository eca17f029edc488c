"""Marching squares in one cell: the outline of a node field where it crosses zero, shared by the
CSF level set (its redistancing) and the surface-energy force (its outline)."""

from taichi_sls.backend import ti


@ti.func
def _crossing(pa, pb, fa, fb):
    return pa + (fa / (fa - fb)) * (pb - pa)


@ti.func
def cell_segments(f, x0, h):
    """f = (f00, f10, f11, f01) counter-clockwise from the lower-left corner x0 of a cell of side
    h, inside where f < 0 (linear along the edges). Returns (count, ends): up to two segments,
    ends = (ax, ay, bx, by) for each; a saddle is resolved by the mean of the four corners."""
    inside = ti.Vector([0, 0, 0, 0])
    n_in = 0
    for k in ti.static(range(4)):
        if f[k] < 0.0:
            inside[k] = 1
            n_in += 1
    count = 0
    ends = ti.Vector.zero(float, 8)
    if n_in > 0 and n_in < 4:
        corner = [
            x0,
            x0 + ti.Vector([h, 0.0]),
            x0 + ti.Vector([h, h]),
            x0 + ti.Vector([0.0, h]),
        ]
        cross = ti.Matrix.zero(float, 4, 2)  # crossing on edge k (corner k -> k+1), if any
        for k in ti.static(range(4)):
            k1 = ti.static((k + 1) % 4)
            if inside[k] != inside[k1]:
                c = _crossing(corner[k], corner[k1], f[k], f[k1])
                cross[k, 0] = c[0]
                cross[k, 1] = c[1]
        if n_in == 2 and inside[0] == inside[2]:
            # saddle: cut off the corners whose side differs from the cell centre's
            centre_in = 1 if f.sum() < 0.0 else 0
            for k in ti.static(range(4)):
                km = ti.static((k + 3) % 4)  # the edges at corner k: km and k
                if inside[k] != centre_in:
                    ends[4 * count + 0] = cross[km, 0]
                    ends[4 * count + 1] = cross[km, 1]
                    ends[4 * count + 2] = cross[k, 0]
                    ends[4 * count + 3] = cross[k, 1]
                    count += 1
        else:
            n = 0
            for k in ti.static(range(4)):
                k1 = ti.static((k + 1) % 4)
                if inside[k] != inside[k1]:
                    ends[2 * n + 0] = cross[k, 0]
                    ends[2 * n + 1] = cross[k, 1]
                    n += 1
            count = 1
    return count, ends
