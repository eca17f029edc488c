"""Products of small local matrices as run-time loops.

Taichi's ``@`` unrolls a product at Python level: a 3x3 product is 27 multiply-adds that its
front end builds node by node at every call site, and the finite-strain update holds nine of
them, expanded again in each kernel that updates stress (a third of the front end's work on a
warm start, docs/compile.md). A run-time loop is built once per call site; each entry sums its
terms in the same order as Taichi's ``@``.
"""

from taichi_sls.backend import ti


class _Constant:
    """A constant float matrix (or vector) by its shape, as a Python list that ``ti.Matrix``
    takes: ``ti.Matrix(ZERO_MATRIX[3, 3])`` is ``ti.Matrix(ZERO_MATRIX[3, 3])``, whose element-
    by-element expansion the front end pays for at every call site (about 1 ms each; the
    constant is one node)."""

    def __init__(self, build) -> None:
        self.build = build

    def __getitem__(self, shape):
        return self.build(*shape) if isinstance(shape, tuple) else self.build(shape)


ZERO_MATRIX = _Constant(lambda n, m: [[0.0] * m for _ in range(n)])
ZERO_VECTOR = _Constant(lambda n: [0.0] * n)
IDENTITY = _Constant(lambda n: [[float(i == j) for j in range(n)] for i in range(n)])


@ti.func
def matmul(a, b):
    """a b of two local matrices (``a @ b``)."""
    c = ti.Matrix(ZERO_MATRIX[a.n, b.m])
    for i, j in ti.ndrange(a.n, b.m):
        s = 0.0
        for k in range(a.m):
            s += a[i, k] * b[k, j]
        c[i, j] = s
    return c


@ti.func
def matmul_bt(a, b):
    """a b^T (``a @ b.transpose()``, the same sums in the same order, without building b^T)."""
    c = ti.Matrix(ZERO_MATRIX[a.n, b.n])
    for i, j in ti.ndrange(a.n, b.n):
        s = 0.0
        for k in range(a.m):
            s += a[i, k] * b[j, k]
        c[i, j] = s
    return c


@ti.func
def conjugate(q, m):
    """q m q^T (a change of frame of the symmetric m; ``q @ m @ q.transpose()``)."""
    return matmul_bt(matmul(q, m), q)
