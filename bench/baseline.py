"""The floor of an MPM step: a minimal elastic MLS-MPM (Hu et al. 2018) of a given size.

Quadratic B-splines, APIC transfer, a compressible neo-Hookean stress, no heat, no surface
tension, no plasticity, no walls beyond clamping to the grid. The speed benchmark runs it on the
same points, grid and layout as a real case: whatever our step costs beyond this is the price of
the physics and of uGIMP.
"""

import numpy as np

from taichi_sls.backend import ti


@ti.data_oriented
class MinimalMPM:
    def __init__(self, x: np.ndarray, nx: int, ny: int, h: float, dt: float) -> None:
        n = len(x)
        self.n, self.nx, self.ny = n, nx, ny
        self.h, self.inv_h, self.dt = h, 1.0 / h, dt
        self.vol = (0.5 * h) ** 2
        self.rho = 1000.0
        E, nu = 1e5, 0.3
        self.mu, self.lam = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
        self.x = ti.Vector.field(2, float, n)
        self.v = ti.Vector.field(2, float, n)
        self.C = ti.Matrix.field(2, 2, float, n)
        self.F = ti.Matrix.field(2, 2, float, n)
        self.gm = ti.field(float, (nx, ny))
        self.gv = ti.Vector.field(2, float, (nx, ny))
        # the points sit in the scene's array frame, shifted by 2 cells like the real grid
        self.x.from_numpy(x + 2 * h)
        self._init()

    def nbytes(self) -> int:
        return self.n * 8 * (2 + 2 + 4 + 4) + self.nx * self.ny * 8 * 3

    @ti.kernel
    def _init(self):
        for p in range(self.n):
            self.F[p] = ti.Matrix.identity(float, 2)

    @ti.func
    def _step(self):
        dt, h, inv_h = self.dt, self.h, self.inv_h
        m_p = self.rho * self.vol
        for I in ti.grouped(ti.ndrange(self.nx, self.ny)):
            self.gm[I] = 0.0
            self.gv[I] = ti.Vector.zero(float, 2)
        for p in range(self.n):
            base = ti.cast(self.x[p] * inv_h - 0.5, ti.i32)
            base = ti.max(ti.min(base, ti.Vector([self.nx - 3, self.ny - 3])), 0)
            fx = self.x[p] * inv_h - ti.cast(base, float)
            w = [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1) ** 2, 0.5 * (fx - 0.5) ** 2]
            F = self.F[p]
            J = F.determinant()
            tau = self.mu * (F @ F.transpose() - ti.Matrix.identity(float, 2)) + self.lam * ti.log(
                J
            ) * ti.Matrix.identity(float, 2)
            stress = -dt * self.vol * 4 * inv_h * inv_h * tau
            affine = stress + m_p * self.C[p]
            for i, j in ti.static(ti.ndrange(3, 3)):
                off = ti.Vector([i, j])
                dpos = (ti.cast(off, float) - fx) * h
                wt = w[i][0] * w[j][1]
                self.gm[base + off] += wt * m_p
                self.gv[base + off] += wt * (m_p * self.v[p] + affine @ dpos)
        for I in ti.grouped(ti.ndrange(self.nx, self.ny)):
            if self.gm[I] > 0:
                self.gv[I] /= self.gm[I]
        for p in range(self.n):
            base = ti.cast(self.x[p] * inv_h - 0.5, ti.i32)
            base = ti.max(ti.min(base, ti.Vector([self.nx - 3, self.ny - 3])), 0)
            fx = self.x[p] * inv_h - ti.cast(base, float)
            w = [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1) ** 2, 0.5 * (fx - 0.5) ** 2]
            new_v = ti.Vector.zero(float, 2)
            new_C = ti.Matrix.zero(float, 2, 2)
            for i, j in ti.static(ti.ndrange(3, 3)):
                off = ti.Vector([i, j])
                dpos = ti.cast(off, float) - fx
                g_v = self.gv[base + off]
                wt = w[i][0] * w[j][1]
                new_v += wt * g_v
                new_C += 4 * inv_h * wt * g_v.outer_product(dpos)
            self.v[p], self.C[p] = new_v, new_C
            self.x[p] += dt * new_v
            self.F[p] = (ti.Matrix.identity(float, 2) + dt * new_C) @ self.F[p]

    @ti.kernel
    def advance_serial(self, n: ti.i32):
        ti.loop_config(serialize=True)
        for _ in range(n):
            self._step()

    @ti.kernel
    def advance_one(self):
        self._step()

    def advance(self, n: int, parallel: bool) -> None:
        if parallel:
            for _ in range(n):
                self.advance_one()
        else:
            self.advance_serial(n)
