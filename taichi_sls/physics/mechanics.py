"""MPM mechanics: particle-to-grid, grid update, grid-to-particle (paper eqs. 10-18).

Transfers (``solver.transfer``, :class:`~taichi_sls.physics.codes.Transfer`):
- FLIP: eq. 14 as printed, v_p += sum N_i (v_i^{n+1} - v_i^n);
- PIC_FLIP: r * FLIP + (1 - r) * PIC;
- APIC: affine PIC (Jiang et al. 2015) with the uGIMP inertia D_p = sum N_ip (x_i - x_p)^2,
  which is diagonal and position dependent for GIMP (between h^2/8 and h^2/4).
Positions follow eq. 15 (the PIC grid velocity) in every variant.

Inertia (``solver.mass_scale`` s): the grid mass, and so the momentum and every acceleration
of the momentum equation, is s times the points' mass; gravity's weight, the heat capacity and
the thermal field keep the physical mass. The grid mass still serves as the colour of the
surface methods through ``rho_ref`` = s rho.

Update (``solver.update``): USL moves the points with the grid velocity v^{n+1} = v^n + dt f/m
as eqs. 14-17 print it; MUSL (modified USL, Sulsky et al. 1995; Bardenhagen 2002) first updates
the point velocities, maps their momenta back to the grid, and moves the points and computes L with
that remapped velocity. On a node that a point barely touches, f/m is the stress term divided by a
tiny mass and USL's velocity there is unbounded (a point that strays from the body is flung away);
the remapped velocity is a weighted mean of point velocities and stays bounded. The remap also
damps: a square of Maxwell fluid rounds off more slowly (tests/physics/test_mechanics.py), and it
did not cure the fine-grid scan case's stray point (a filament climbing the left wall), so USL
stays the default.

Dilatation (``solver.dilatation``): "point" takes each point's own tr(L) (eq. 18); "cell" the
divergence at the centre of its cell for every point of the cell, and the mean stress's force
through the same gradient (physics/dilatation.py).

``cfg`` is the step's compile-time configuration (grid geometry, switches); ``pt`` the points and
``nd`` the nodes (struct fields, solver/fields.py).
"""

from taichi_sls.backend import ti

from .codes import Transfer, WallMechanical
from .dilatation import cell_pressure_force, cell_velocity_gradient
from .grid import node_x, scatter_add
from .shape import STENCIL_SHAPE, node_weight
from .small_matrix import IDENTITY, ZERO_MATRIX, ZERO_VECTOR


@ti.func
def inertia(cfg: ti.template(), m):
    """The mass the momentum equation sees: m times ``mass_scale`` (inertia scaling, for slow
    viscous or quasi-static flow; 1: the physical mass)."""
    out = m
    if ti.static(cfg.mass_scale != 1.0):
        out = m * cfg.mass_scale
    return out


@ti.func
def p2g_mechanics(cfg: ti.template(), pt: ti.template(), nd: ti.template(), p, base, w, dw):
    """Mass, momentum, internal force -V_p sigma_p grad N (eq. 11) and body force (eq. 12).
    The grid's mass is the inertia: ``mass_scale`` times the point's (its weight stays)."""
    xp = pt.x[p]
    mp = pt.mass[p]
    mi = inertia(cfg, mp)
    vp = pt.v[p]
    Vp = pt.volume0[p] * pt.J[p]
    sig = ti.Matrix(ZERO_MATRIX[cfg.dim, cfg.dim])
    if ti.static(not cfg.implicit):  # implicit: the internal force of the new stress instead
        for a, b in ti.static(ti.ndrange(cfg.dim, cfg.dim)):
            sig[a, b] = pt.stress[p][a, b]
        if ti.static(cfg.solvent):
            sig += pt.viscous_stress[p]  # the melt's solvent viscosity: force only
        if ti.static(cfg.cell_dilatation):  # the mean stress through the cell's gradient
            sig = cell_pressure_force(cfg, nd, nd.pressure_force, xp, Vp, sig)
    g = ti.Vector(cfg.gravity, dt=float)
    for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[cfg.dim])):
        N, gN = node_weight(w, dw, o)
        I = base + o
        mv = vp
        if ti.static(cfg.transfer == Transfer.APIC):
            mv += pt.C[p] @ (node_x(cfg, I) - xp)
        scatter_add(cfg, nd.mass, I, N * mi)
        scatter_add(cfg, nd.momentum, I, N * mi * mv)
        f = ti.Vector(ZERO_VECTOR[cfg.dim])
        if ti.static(not cfg.implicit):
            f = -Vp * (sig @ gN)
        if ti.static(cfg.has_gravity):
            f += N * mp * g
        scatter_add(cfg, nd.force, I, f)


@ti.func
def apply_walls(cfg: ti.template(), I, v):
    """Rigid walls on the node lines x = 0, x = W, y = 0, y = H (3D: z = 0, z = D) and beyond
    (ghost nodes)."""
    lo = cfg.off
    hi = ti.Vector(cfg.wall_index)
    for d in ti.static(range(cfg.dim)):
        kind_lo = ti.static(cfg.wall_mechanical[2 * d])
        kind_hi = ti.static(cfg.wall_mechanical[2 * d + 1])
        if I[d] <= lo:
            if ti.static(kind_lo == WallMechanical.SLIP):
                v[d] = 0.0
            elif ti.static(kind_lo == WallMechanical.STICK):
                v = ti.Vector(ZERO_VECTOR[cfg.dim])
            elif ti.static(kind_lo == WallMechanical.MIRROR):
                if I[d] == lo:  # the ghosts beyond hold the mirror image (physics/mirror.py)
                    v[d] = 0.0
        if I[d] >= hi[d]:
            if ti.static(kind_hi == WallMechanical.SLIP):
                v[d] = 0.0
            elif ti.static(kind_hi == WallMechanical.STICK):
                v = ti.Vector(ZERO_VECTOR[cfg.dim])
            elif ti.static(kind_hi == WallMechanical.MIRROR):
                if I[d] == hi[d]:  # the ghosts beyond hold the mirror image (physics/mirror.py)
                    v[d] = 0.0
    return v


@ti.func
def grid_velocity(cfg: ti.template(), nd: ti.template(), I, dt):
    """v^n = (mv)/m and v^{n+1} = v^n + dt f / m (eqs. 10, 13); nodes below the cut-off rest."""
    m = nd.mass[I]
    vn = ti.Vector(ZERO_VECTOR[cfg.dim])
    v = ti.Vector(ZERO_VECTOR[cfg.dim])
    if m > cfg.mass_cut:
        vn = nd.momentum[I] / m
        v = apply_walls(cfg, I, vn + dt * nd.force[I] / m)
    nd.v_old[I] = vn
    nd.v[I] = v


@ti.func
def g2p_velocity(cfg: ti.template(), pt: ti.template(), nd: ti.template(), p, base, w, dw):
    """The point velocity from the grid (transfer variant; eq. 14 for FLIP)."""
    xp = pt.x[p]
    v_pic = ti.Vector(ZERO_VECTOR[cfg.dim])
    dv = ti.Vector(ZERO_VECTOR[cfg.dim])
    B = ti.Matrix(ZERO_MATRIX[cfg.dim, cfg.dim])
    for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[cfg.dim])):
        N, gN = node_weight(w, dw, o)
        I = base + o
        vi = nd.v[I]
        v_pic += N * vi
        if ti.static(cfg.transfer == Transfer.APIC):
            B += N * vi.outer_product(node_x(cfg, I) - xp)
        else:
            dv += N * (vi - nd.v_old[I])
    if ti.static(cfg.transfer == Transfer.FLIP):
        pt.v[p] += dv
    elif ti.static(cfg.transfer == Transfer.PIC_FLIP):
        r = ti.static(cfg.flip_ratio)
        pt.v[p] = r * (pt.v[p] + dv) + (1.0 - r) * v_pic
    else:
        pt.v[p] = v_pic
        # D_p per axis: sum_a w_a (x_a - x_p)^2 (uGIMP inertia), C = B D^-1
        for d in ti.static(range(cfg.dim)):
            Dd = 0.0
            for a in ti.static(range(3)):
                r = ti.cast(base[d] + a - cfg.off, float) * cfg.h - xp[d]
                Dd += w[a, d] * r * r
            for c in ti.static(range(cfg.dim)):
                B[c, d] /= Dd
        pt.C[p] = B


@ti.func
def interpolate_velocity(cfg: ti.template(), nd: ti.template(), base, w, dw):
    """The grid velocity at a point and its gradient L = sum_i v_i grad N_i (eq. 16)."""
    v_grid = ti.Vector(ZERO_VECTOR[cfg.dim])
    L = ti.Matrix(ZERO_MATRIX[cfg.dim, cfg.dim])
    for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[cfg.dim])):
        N, gN = node_weight(w, dw, o)
        vi = nd.v[base + o]
        v_grid += N * vi
        L += vi.outer_product(gN)
    return v_grid, L


@ti.func
def g2p_kinematics(cfg: ti.template(), pt: ti.template(), nd: ti.template(), p, base, w, dw, dt):
    """Position (eq. 15), velocity gradient, F (eq. 17) and J (eq. 18) from the grid velocity.

    Returns the velocity gradient L for the constitutive update.
    """
    v_grid, L = interpolate_velocity(cfg, nd, base, w, dw)
    if ti.static(cfg.cell_dilatation):  # the cell's dilatation, the point's own shear
        L = cell_velocity_gradient(cfg, nd, pt.x[p], L)
    pt.x[p] += dt * v_grid
    F = (ti.Matrix(IDENTITY[cfg.dim]) + dt * L) @ pt.F[p]
    pt.F[p] = F
    pt.J[p] = F.determinant()
    return L


@ti.func
def p2g_momentum(cfg: ti.template(), pt: ti.template(), nd: ti.template(), p, base, w, dw):
    """MUSL: the updated point momenta back to the grid (affine part included for APIC)."""
    xp = pt.x[p]
    mp = inertia(cfg, pt.mass[p])
    for o in ti.grouped(ti.ndrange(*STENCIL_SHAPE[cfg.dim])):
        N, gN = node_weight(w, dw, o)
        I = base + o
        mv = pt.v[p]
        if ti.static(cfg.transfer == Transfer.APIC):
            mv += pt.C[p] @ (node_x(cfg, I) - xp)
        scatter_add(cfg, nd.momentum, I, N * mp * mv)


@ti.func
def grid_remap_velocity(cfg: ti.template(), nd: ti.template(), I):
    """MUSL: the grid velocity from the remapped momenta, walls applied; empty nodes rest."""
    v = ti.Vector(ZERO_VECTOR[cfg.dim])
    if nd.mass[I] > cfg.mass_cut:
        v = apply_walls(cfg, I, nd.momentum[I] / nd.mass[I])
    nd.v[I] = v
