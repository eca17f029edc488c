"""MPM mechanics: particle-to-grid, grid update, grid-to-particle (paper eqs. 10-18).

Transfers (case option ``solver.transfer``):
- ``flip``: eq. 14 as printed, v_p += sum N_i (v_i^{n+1} - v_i^n);
- ``pic_flip``: r * FLIP + (1 - r) * PIC;
- ``apic``: affine PIC (Jiang et al. 2015) with the uGIMP inertia D_p = sum N_ip (x_i - x_p)^2,
  which is diagonal and position dependent for GIMP (between h^2/8 and h^2/4).
Positions follow eq. 15 (the PIC grid velocity) in every variant.

Update (``solver.update``): ``usl`` moves the points with the grid velocity v^{n+1} = v^n + dt f/m
as eqs. 14-17 print it; ``musl`` (modified USL, Sulsky et al. 1995; Bardenhagen 2002) first updates
the point velocities, maps their momenta back to the grid, and moves the points and computes L with
that remapped velocity. On a node that a point barely touches, f/m is the stress term divided by a
tiny mass and USL's velocity there is unbounded (a point that strays from the body is flung away);
the remapped velocity is a weighted mean of point velocities and stays bounded. The remap also
damps: a square of Maxwell fluid rounds off more slowly (corner excess 0.19 -> 0.12 in 300 us
against 0.08 with USL, tests/test_surface.py), and it did not cure the fine-grid scan case's stray
point (a filament climbing the left wall), so USL stays the default.
"""

import taichi as ti

from .shape import STENCIL, node_weight


@ti.func
def node_x(st: ti.template(), idx):
    return ti.cast(idx - st.off, float) * st.h


@ti.func
def p2g_mechanics(st: ti.template(), p, base, w, dw):
    """Mass, momentum, internal force -V_p sigma_p grad N (eq. 11) and body force (eq. 12)."""
    xp = st.x[p]
    mp = st.mass[p]
    vp = st.v[p]
    Vp = st.vol0[p] * st.J[p]
    sig = ti.Matrix.zero(float, st.dim, st.dim)
    for a, b in ti.static(ti.ndrange(st.dim, st.dim)):
        sig[a, b] = st.sigma[p][a, b]
    g = ti.Vector(st.gravity, dt=float)
    for o in ti.static(ti.grouped(STENCIL)):
        N, gN = node_weight(w, dw, o)
        I = base + o
        mv = vp
        if ti.static(st.transfer == 2):
            mv += st.C[p] @ (node_x(st, I) - xp)
        st.gm[I] += N * mp
        st.gmv[I] += N * mp * mv
        f = -Vp * (sig @ gN)
        if ti.static(st.has_gravity):
            f += N * mp * g
        st.gf[I] += f


@ti.func
def apply_walls(st: ti.template(), I, v):
    """Rigid walls on the node lines x = 0, x = W, y = 0, y = H and beyond (ghost nodes)."""
    lo = st.off
    hi = ti.Vector([st.off + st.ncx, st.off + st.ncy])
    for d in ti.static(range(2)):
        kind_lo = ti.static(st.wall_mech[2 * d])
        kind_hi = ti.static(st.wall_mech[2 * d + 1])
        if I[d] <= lo:
            if ti.static(kind_lo == 0):
                v[d] = 0.0
            elif ti.static(kind_lo == 1):
                v = ti.Vector.zero(float, st.dim)
        if I[d] >= hi[d]:
            if ti.static(kind_hi == 0):
                v[d] = 0.0
            elif ti.static(kind_hi == 1):
                v = ti.Vector.zero(float, st.dim)
    return v


@ti.func
def grid_velocity(st: ti.template(), I, dt):
    """v^n = (mv)/m and v^{n+1} = v^n + dt f / m (eqs. 10, 13); nodes below the cut-off rest."""
    m = st.gm[I]
    vn = ti.Vector.zero(float, st.dim)
    v = ti.Vector.zero(float, st.dim)
    if m > st.mass_cut:
        vn = st.gmv[I] / m
        v = apply_walls(st, I, vn + dt * st.gf[I] / m)
    st.gvn[I] = vn
    st.gv[I] = v


@ti.func
def g2p_velocity(st: ti.template(), p, base, w, dw):
    """The point velocity from the grid (transfer variant; eq. 14 for FLIP)."""
    xp = st.x[p]
    v_pic = ti.Vector.zero(float, st.dim)
    dv = ti.Vector.zero(float, st.dim)
    B = ti.Matrix.zero(float, st.dim, st.dim)
    for o in ti.static(ti.grouped(STENCIL)):
        N, gN = node_weight(w, dw, o)
        I = base + o
        vi = st.gv[I]
        v_pic += N * vi
        if ti.static(st.transfer == 2):
            B += N * vi.outer_product(node_x(st, I) - xp)
        else:
            dv += N * (vi - st.gvn[I])
    if ti.static(st.transfer == 0):
        st.v[p] += dv
    elif ti.static(st.transfer == 1):
        r = ti.static(st.flip_ratio)
        st.v[p] = r * (st.v[p] + dv) + (1.0 - r) * v_pic
    else:
        st.v[p] = v_pic
        # D_p per axis: sum_a w_a (x_a - x_p)^2 (uGIMP inertia), C = B D^-1
        for d in ti.static(range(st.dim)):
            Dd = 0.0
            for a in ti.static(range(3)):
                r = ti.cast(base[d] + a - st.off, float) * st.h - xp[d]
                Dd += w[a, d] * r * r
            for c in ti.static(range(st.dim)):
                B[c, d] /= Dd
        st.C[p] = B


@ti.func
def g2p_kinematics(st: ti.template(), p, base, w, dw, dt):
    """Position (eq. 15), velocity gradient, F (eq. 17) and J (eq. 18) from the grid velocity.

    Returns the velocity gradient L for the constitutive update.
    """
    v_grid = ti.Vector.zero(float, st.dim)
    L = ti.Matrix.zero(float, st.dim, st.dim)
    for o in ti.static(ti.grouped(STENCIL)):
        N, gN = node_weight(w, dw, o)
        vi = st.gv[base + o]
        v_grid += N * vi
        L += vi.outer_product(gN)
    st.x[p] += dt * v_grid
    F = (ti.Matrix.identity(float, st.dim) + dt * L) @ st.F[p]
    st.F[p] = F
    st.J[p] = F.determinant()
    return L


@ti.func
def p2g_momentum(st: ti.template(), p, base, w, dw):
    """MUSL: the updated point momenta back to the grid (affine part included for APIC)."""
    xp = st.x[p]
    mp = st.mass[p]
    for o in ti.static(ti.grouped(STENCIL)):
        N, gN = node_weight(w, dw, o)
        I = base + o
        mv = st.v[p]
        if ti.static(st.transfer == 2):
            mv += st.C[p] @ (node_x(st, I) - xp)
        st.gmv[I] += N * mp * mv


@ti.func
def grid_remap_velocity(st: ti.template(), I):
    """MUSL: the grid velocity from the remapped momenta, walls applied; empty nodes rest."""
    v = ti.Vector.zero(float, st.dim)
    if st.gm[I] > st.mass_cut:
        v = apply_walls(st, I, st.gmv[I] / st.gm[I])
    st.gv[I] = v
