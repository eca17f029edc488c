"""Products of small local matrices as run-time loops.

Taichi's ``@`` unrolls a product at Python level: a 3x3 product is 27 multiply-adds that its
front end builds node by node at every call site, and the finite-strain update holds nine of
them, expanded again in each kernel that updates stress (a third of the front end's work on a
warm start, docs/record/compile.md). A run-time loop is built once per call site; each entry sums
its terms in the same order as Taichi's ``@``.
"""

from taichi_sls.backend import ti


class _Constant:
    """A constant float matrix (or vector) by its shape, as a Python list that ``ti.Matrix``
    takes: ``ti.Matrix(ZERO_MATRIX[3, 3])`` is ``ti.Matrix(ZERO_MATRIX[3, 3])``, whose element-
    by-element expansion the front end pays for at every call site (the constant is one
    node)."""

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


# cyclic Jacobi sweeps of symmetric_eigen: each squares the off-diagonal's relative size, so a
# strained b (off-diagonals ~1e-2 of its diagonal) is diagonal to round-off after four
JACOBI_SWEEPS = 6
# an off-diagonal below this fraction of its two diagonal entries is zero to round-off (f64)
JACOBI_NEGLIGIBLE = 1e-18


@ti.func
def symmetric_eigen(a):
    """Eigenvalues (a vector, in no order) and eigenvectors (the columns of a rotation) of the
    symmetric 3x3 ``a`` by cyclic Jacobi rotations. Unlike ``ti.sym_eig`` (Cardano's closed form,
    whose eigenvalues of an elastic stretch b ~ I lose the small strain b - I to cancellation:
    log(b) off by 25-100 % at |b - I| = 1e-5..1e-2, so a finite-strain stress that jumps as the
    velocity changes by round-off, and Newton stalls), each rotation is exact to round-off
    relative to the entries it zeroes, whatever the eigenvalues' gaps."""
    v = ti.Matrix(IDENTITY[3])
    for _ in range(JACOBI_SWEEPS):
        rotated = 0
        for r in range(3):  # the pairs (0, 1), (0, 2), (1, 2)
            p = r // 2
            q = 1 + r - p
            apq = a[p, q]
            if ti.abs(apq) > JACOBI_NEGLIGIBLE * (ti.abs(a[p, p]) + ti.abs(a[q, q])):
                rotated = 1
                tau = a[q, q] - a[p, p]
                t = 2.0 * apq / (ti.abs(tau) + ti.sqrt(tau * tau + 4.0 * apq * apq))
                if tau < 0.0:
                    t = -t
                c = 1.0 / ti.sqrt(1.0 + t * t)
                s = t * c
                for k in range(3):  # a G and v G, G the rotation in the (p, q) plane
                    akp, akq = a[k, p], a[k, q]
                    a[k, p], a[k, q] = c * akp - s * akq, s * akp + c * akq
                    vkp, vkq = v[k, p], v[k, q]
                    v[k, p], v[k, q] = c * vkp - s * vkq, s * vkp + c * vkq
                for k in range(3):  # G^T (a G)
                    apk, aqk = a[p, k], a[q, k]
                    a[p, k], a[q, k] = c * apk - s * aqk, s * apk + c * aqk
        if rotated == 0:
            break
    return ti.Vector([a[0, 0], a[1, 1], a[2, 2]]), v
