"""Products of small local matrices as run-time loops.

Taichi's ``@`` unrolls a product at Python level: a 3x3 product is 27 multiply-adds that its
front end builds node by node at every call site, and the finite-strain update holds nine of
them, expanded again in each kernel that updates stress (a third of the front end's work on a
warm start, docs/compile.md). A run-time loop is built once per call site; each entry sums its
terms in the same order as Taichi's ``@``.
"""

from taichi_sls.backend import ti


@ti.func
def matmul(a, b):
    """a b of two local matrices (``a @ b``)."""
    c = ti.Matrix.zero(float, a.n, b.m)
    for i, j in ti.ndrange(a.n, b.m):
        s = 0.0
        for k in range(a.m):
            s += a[i, k] * b[k, j]
        c[i, j] = s
    return c


@ti.func
def conjugate(q, m):
    """q m q^T (a change of frame of the symmetric m; ``q @ m @ q.transpose()``)."""
    return matmul(matmul(q, m), q.transpose())
