"""Marching tetrahedra in one cube: the surface of a node field where it crosses zero, as
triangles, for the surface-energy force in 3D (physics/surface_energy.py).

The cube is cut into six tetrahedra around its diagonal from corner (0, 0, 0) to (1, 1, 1)
(Kuhn's triangulation: tetrahedron t walks from one end of the diagonal to the other along the
axes in the order of the t-th permutation). Translated cubes share their faces' diagonals, so
the surface is closed across cells, and a field linear on each tetrahedron has one sheet per
tetrahedron: no ambiguous case to resolve (marching squares' saddle). A tetrahedron with one or
three corners inside gives one triangle, with two a quadrilateral cut into two triangles.

Kuhn's triangulation is not symmetric under a reflection: the cube with an odd index along an
axis is therefore cut as its mirror image in that axis (:func:`cell_tet_corner`). Two cubes
that share a face still cut it along one diagonal (the reflection in x leaves the diagonal of an
x face as it was), and the surface of a field symmetric about a node plane is then symmetric
too: the cube i and its mirror image 2 P - 1 - i have opposite parities. A mirror wall
(physics/mirror.py) needs it, and a symmetric scene keeps its symmetry.
"""

from taichi_sls.backend import ti

from .small_matrix import ZERO_MATRIX


@ti.func
def tet_corner(t, k):
    """Offset (0 or 1 per axis) of corner k = 0..3 of tetrahedron t = 0..5 of the unit cube:
    the axes taken in the order (a, b, c), a = t // 2 and b, c the other two, swapped if t is
    odd; corner k has moved along the first k of them."""
    a = t // 2
    b = (a + 1 + t % 2) % 3
    c = 3 - a - b
    o = ti.Vector([0, 0, 0])
    if k >= 1:
        o[a] = 1
    if k >= 2:
        o[b] = 1
    if k >= 3:
        o[c] = 1
    return o


@ti.func
def cell_tet_corner(I, t, k):
    """As :func:`tet_corner` in the cube of lower corner I: reflected along each axis where
    I is odd."""
    o = tet_corner(t, k)
    for d in ti.static(range(3)):
        if I[d] % 2 == 1:
            o[d] = 1 - o[d]
    return o


@ti.func
def _crossing(pa, pb, fa, fb):
    return pa + (fa / (fa - fb)) * (pb - pa)


@ti.func
def tet_triangles(f, p):
    """f: the field at the four corners (inside where f < 0), p (4 x 3): their positions.
    Returns (count, tri): up to two triangles, rows 3 q .. 3 q + 2 of tri (6 x 3) the corners
    of triangle q, each on an edge from a corner inside to one outside."""
    order = ti.Vector([0, 1, 2, 3])
    n_in = 0
    for k in range(4):
        if f[k] < 0.0:
            order[n_in] = k
            n_in += 1
    m = n_in
    for k in range(4):
        if f[k] >= 0.0:
            order[m] = k
            m += 1
    count = 0
    tri = ti.Matrix(ZERO_MATRIX[6, 3])
    if n_in == 1 or n_in == 3:
        # the lone corner (inside if n_in = 1, outside if 3) against the other three
        lone = order[0] if n_in == 1 else order[3]
        q = 0
        for k in range(4):
            if k != lone:
                x = _crossing(_row(p, lone), _row(p, k), f[lone], f[k])
                for d in range(3):
                    tri[q, d] = x[d]
                q += 1
        count = 1
    elif n_in == 2:
        a, b, c, d = order[0], order[1], order[2], order[3]
        # the quadrilateral ac, ad, bd, bc (in order around it), cut along ac-bd
        x_ac = _crossing(_row(p, a), _row(p, c), f[a], f[c])
        x_ad = _crossing(_row(p, a), _row(p, d), f[a], f[d])
        x_bd = _crossing(_row(p, b), _row(p, d), f[b], f[d])
        x_bc = _crossing(_row(p, b), _row(p, c), f[b], f[c])
        for e in range(3):
            tri[0, e] = x_ac[e]
            tri[1, e] = x_ad[e]
            tri[2, e] = x_bd[e]
            tri[3, e] = x_ac[e]
            tri[4, e] = x_bd[e]
            tri[5, e] = x_bc[e]
        count = 2
    return count, tri


@ti.func
def _row(p, k):
    return ti.Vector([p[k, 0], p[k, 1], p[k, 2]])
