"""Surface tension: level set, least-squares curvature, CSF force (paper eqs. 19-24).

The method, and why (MODEL.md, last section):

1. **Level set from the points** (eq. 21): phi_raw(x_i) = min_p |x_i - x_p| - r_p, scattered by
   each point onto the 5x5 nodes around it (O(points) work). It is a distance outside the body
   but a plateau near -r_p inside, where eq. 24 would divide by a vanishing gradient.
2. **Redistancing** (``surface_tension.level_set = "redistanced"``, default): the zero contour of
   phi_raw is traced by marching squares (linear interpolation on cell edges, saddles resolved
   by the cell-centre value) and every node within ``band_cells`` of it gets the signed distance
   to the nearest contour segment. ``"raw"`` keeps eq. 21 as printed.
3. **Curvature** (eqs. 22-24): the quadratic of eq. 23 is fitted by least squares to the nine
   phi values around a node (the 6x9 fit matrix is computed once) and eq. 24 gives the node's
   curvature. With a signed distance, a node at distance phi from the interface sees the
   curvature of the parallel curve; kappa_node / (1 - phi kappa_node) projects it back to the
   interface (exact for a circle), so all band nodes carry the interface's curvature.
   Nodes where the fit is not a distance (a neighbour outside the band, |grad phi| < 1/2) get the
   mean of the valid curvatures around them (extension), or none.
4. **Smoothing**: a level set built from points is rough at their spacing and curvature
   amplifies that by (R/h)^2. Two smoothings, both case options: ``level_set_smoothing_passes``
   binomial passes over phi before the fit (a Gaussian blur; a circle stays a circle, shrunk by
   sigma^2 / 2R), and ``smoothing_passes`` mass-weighted 3x3 averages of kappa over the interface
   nodes after it (unbiased for constant curvature). |kappa| is then capped at
   ``curvature_cap_h / h`` (the grid resolves no radius below a couple of cells). Measured on
   discs seeded with 2x2 points per cell (tests/test_surface.py) with the defaults (8 and 16
   passes): mean error +1.7 % / -3 %, RMS 4 % / 9 % at R/h = 10 / 20, against -42 % / -97 % mean
   and 270 % / 600 % RMS for eq. 21 redistanced without smoothing.
5. **CSF force** (eq. 19): f_i = V_c gamma kappa_i grad m_i / [m] * m_i / <m> with [m] = rho V_c
   and <m> = [m] / 2 (MODEL.md), grad m_i from eq. 20 with the uGIMP gradient at node positions.
   The ghost nodes beyond the walls enter grad m only.
"""

import taichi as ti

from .state import active


@ti.func
def scatter_level_set(st: ti.template(), p, base):
    """Eq. 21 onto the 5x5 nodes around point p (base: its 3x3 stencil origin)."""
    xp = st.x[p]
    for a, b in ti.static(ti.ndrange(5, 5)):
        I = base + ti.Vector([a - 1, b - 1])
        xi = ti.cast(I - st.off, float) * st.h
        ti.atomic_min(st.phi_raw[I], (xi - xp).norm() - st.r_p)


@ti.func
def _crossing(pa, pb, fa, fb):
    return pa + (fa / (fa - fb)) * (pb - pa)


@ti.func
def contour_segments(st: ti.template()):
    """Marching squares on phi_raw: up to two segments per cell, in metres."""
    for i, j in ti.ndrange(*active(st, 1)):
        f = ti.Vector(
            [st.phi_raw[i, j], st.phi_raw[i + 1, j], st.phi_raw[i + 1, j + 1], st.phi_raw[i, j + 1]]
        )
        inside = ti.Vector([0, 0, 0, 0])
        n_in = 0
        for k in ti.static(range(4)):
            if f[k] < 0.0:
                inside[k] = 1
                n_in += 1
        count = 0
        seg = ti.Vector.zero(float, 8)
        if n_in > 0 and n_in < 4:
            x0 = ti.cast(ti.Vector([i, j]) - st.off, float) * st.h
            h = st.h
            corner = [
                x0,
                x0 + ti.Vector([h, 0.0]),
                x0 + ti.Vector([h, h]),
                x0 + ti.Vector([0.0, h]),
            ]
            # crossing on edge k (corner k -> corner k+1), if any
            cross = ti.Matrix.zero(float, 4, 2)
            has = ti.Vector([0, 0, 0, 0])
            for k in ti.static(range(4)):
                k1 = ti.static((k + 1) % 4)
                if inside[k] != inside[k1]:
                    c = _crossing(corner[k], corner[k1], f[k], f[k1])
                    cross[k, 0] = c[0]
                    cross[k, 1] = c[1]
                    has[k] = 1
            if n_in == 2 and inside[0] == inside[2]:
                # saddle: cut off the corners whose sign differs from the cell centre
                centre_in = 1 if f.sum() < 0.0 else 0
                for k in ti.static(range(4)):
                    km = ti.static((k + 3) % 4)  # edges adjacent to corner k: km and k
                    if inside[k] != centre_in:
                        seg[4 * count + 0] = cross[km, 0]
                        seg[4 * count + 1] = cross[km, 1]
                        seg[4 * count + 2] = cross[k, 0]
                        seg[4 * count + 3] = cross[k, 1]
                        count += 1
            else:
                n = 0
                for k in ti.static(range(4)):
                    if has[k] == 1:
                        seg[2 * n + 0] = cross[k, 0]
                        seg[2 * n + 1] = cross[k, 1]
                        n += 1
                count = 1
        st.seg[i, j] = seg
        st.nseg[i, j] = count


@ti.func
def _seg_dist2(x, a, b):
    ab = b - a
    L2 = ab.dot(ab)
    t = 0.0
    if L2 > 0.0:
        t = ti.min(1.0, ti.max(0.0, (x - a).dot(ab) / L2))
    d = x - (a + t * ab)
    return d.dot(d)


@ti.func
def redistance(st: ti.template()):
    """Signed distance to the contour segments for every node within the band."""
    nb = ti.static(st.band)
    for i, j in ti.ndrange(*active(st)):
        f = st.phi_raw[i, j]
        out = f
        if ti.static(st.redistance):
            sgn = 1.0 if f >= 0.0 else -1.0
            out = sgn * st.phi_cap
            if f < st.phi_cap:
                x = ti.cast(ti.Vector([i, j]) - st.off, float) * st.h
                d2 = st.phi_cap * st.phi_cap
                for ci in range(ti.max(i - nb, 0), ti.min(i + nb, st.nx - 1)):
                    for cj in range(ti.max(j - nb, 0), ti.min(j + nb, st.ny - 1)):
                        for s in range(st.nseg[ci, cj]):
                            sg = st.seg[ci, cj]
                            a = ti.Vector([sg[4 * s], sg[4 * s + 1]])
                            b = ti.Vector([sg[4 * s + 2], sg[4 * s + 3]])
                            d2 = ti.min(d2, _seg_dist2(x, a, b))
                out = sgn * ti.sqrt(d2)
        st.phi[i, j] = out


@ti.func
def blur_level_set(st: ti.template()):
    """phis = phi after ``level_set_smoothing_passes`` binomial [1 2 1]/4 passes along x then y
    (a Gaussian of variance passes * h^2 / 2 per axis): removes the points' staircase before
    eq. 24 amplifies it. For a disc it moves the interface inward by about that variance / (2R).
    phi itself stays unsmoothed for the contact line."""
    for I in ti.grouped(ti.ndrange(*active(st))):
        st.phis[I] = st.phi[I]
    # passes unrolled only where each loop must stay a top-level parallel loop: unrolled, the
    # serial step kernel grows by two loops a pass and Taichi's optimiser slows down with it
    if ti.static(st.parallel):
        for _ in ti.static(range(st.blur_passes)):
            _blur_pass(st)
    else:
        for _ in range(st.blur_passes):
            _blur_pass(st)


@ti.func
def _blur_pass(st: ti.template()):
    for i, j in ti.ndrange(*active(st)):
        v = st.phis[i, j]
        if i > 0 and i < st.nx - 1:
            v = 0.25 * (st.phis[i - 1, j] + st.phis[i + 1, j]) + 0.5 * v
        st.ktmp[i, j] = v
    for i, j in ti.ndrange(*active(st)):
        v = st.ktmp[i, j]
        if j > 0 and j < st.ny - 1:
            v = 0.25 * (st.ktmp[i, j - 1] + st.ktmp[i, j + 1]) + 0.5 * v
        st.phis[i, j] = v


@ti.func
def curvature(st: ti.template()):
    """Eqs. 22-24 at every node whose 3x3 neighbourhood lies in the band (kvalid bit 0)."""
    h = st.h
    for i, j in ti.ndrange(*active(st)):
        k = 0.0
        ok = 0
        if i > 0 and j > 0 and i < st.nx - 1 and j < st.ny - 1:
            f9 = ti.Vector.zero(float, 9)
            inband = 1
            for a, b in ti.static(ti.ndrange(3, 3)):
                v = st.phis[i + a - 1, j + b - 1]
                f9[3 * a + b] = v
                if ti.abs(v) >= st.phi_cap:
                    inband = 0
            if inband == 1:
                c = st.fit[None] @ f9
                px, py = c[1] / h, c[2] / h
                pxx, pyy, pxy = 2.0 * c[3] / (h * h), 2.0 * c[4] / (h * h), c[5] / (h * h)
                g2 = px * px + py * py
                g = ti.sqrt(g2)
                gmin = 0.5 if ti.static(st.redistance) else 1e-12
                if g > gmin:
                    kn = (pxx * py * py - 2.0 * px * py * pxy + pyy * px * px) / (g2 * g)
                    if ti.static(st.redistance):
                        den = 1.0 - st.phis[i, j] * kn
                        if den > 0.25:
                            k = kn / den
                            ok = 1
                    else:
                        k = kn
                        ok = 1
        st.kappa[i, j] = k
        st.kvalid[i, j] = ok


def _node_stencil_1d(h: float, lp: float) -> tuple[list[float], list[float]]:
    """uGIMP weight and derivative of node i' seen from node i = i' + (1 - a) (a = 0, 1, 2)."""
    # xi = x_i - x_i' = (1 - a) h: the left neighbour (a = 0) sits at xi = +h, where
    # dS/dxi = -1/(2h); so grad m is the central difference (m_right - m_left) / 2h, y-smoothed
    s0, s1 = 1.0 - lp / (2.0 * h), lp / (4.0 * h)
    d1 = 1.0 / (2.0 * h)
    return [s1, s0, s1], [-d1, 0.0, d1]


@ti.func
def mass_gradient(st: ti.template()):
    """Eq. 20 with the uGIMP gradient at node positions; marks interface nodes (kvalid bit 1)."""
    S, dS = ti.static(_node_stencil_1d(st.h, st.lp))
    for i, j in ti.ndrange(*active(st)):
        g = ti.Vector.zero(float, 2)
        if i > 0 and j > 0 and i < st.nx - 1 and j < st.ny - 1:
            for a, b in ti.static(ti.ndrange(3, 3)):
                m = st.gm[i + a - 1, j + b - 1]
                g += m * ti.Vector([dS[a] * S[b], S[a] * dS[b]])
        st.gradm[i, j] = g
        iface = 0
        if st.gm[i, j] > st.mass_cut and g.norm() * st.h > 1e-6 * st.rho_ref * st.cell_volume:
            iface = 2
        st.kvalid[i, j] = (st.kvalid[i, j] & 1) | iface


@ti.func
def extend_and_smooth(st: ti.template()):
    """Give interface nodes without a valid curvature the mean of valid neighbours, then
    ``smoothing_passes`` mass-weighted 3x3 averages over interface nodes, then the cap.

    The passes only change interface nodes and only read interface neighbours: they run over a
    list of those nodes (a few hundred of the paper grid's 1457), alternating between ktmp and
    kappa (Jacobi sweeps, so the list's order does not matter)."""
    st.n_iface[None] = 0
    for i, j in ti.ndrange(*active(st)):
        k = st.kappa[i, j]
        if st.kvalid[i, j] & 2 and i > 0 and j > 0 and i < st.nx - 1 and j < st.ny - 1:
            if st.kvalid[i, j] == 2:
                s = 0.0
                n = 0
                for a, b in ti.static(ti.ndrange(3, 3)):
                    if st.kvalid[i + a - 1, j + b - 1] & 1:
                        s += st.kappa[i + a - 1, j + b - 1]
                        n += 1
                k = s / n if n > 0 else 0.0
            st.iface[ti.atomic_add(st.n_iface[None], 1)] = ti.Vector([i, j])
        st.ktmp[i, j] = k
    if ti.static(st.parallel):
        for q in ti.static(range(st.smooth_passes)):
            _smooth_pass(st, q % 2 == 1)
    else:
        for q in range(st.smooth_passes):
            _smooth_pass(st, q % 2 == 1)
    if ti.static(st.smooth_passes % 2 == 1):  # the last pass wrote kappa
        for q in range(st.n_iface[None]):
            I = st.iface[q]
            st.ktmp[I] = st.kappa[I]
    for i, j in ti.ndrange(*active(st)):
        k = st.ktmp[i, j]
        if ti.static(st.kappa_cap > 0.0):
            k = ti.min(st.kappa_cap, ti.max(-st.kappa_cap, k))
        st.kappa[i, j] = k


@ti.func
def _smooth_pass(st: ti.template(), back):
    """One mass-weighted 3x3 average over the interface nodes: ktmp -> kappa, or back."""
    for q in range(st.n_iface[None]):
        I = st.iface[q]
        s = 0.0
        w = 0.0
        for a, b in ti.static(ti.ndrange(3, 3)):
            J = I + ti.Vector([a - 1, b - 1])
            if st.kvalid[J] & 2:
                m = st.gm[J]
                s += m * (st.kappa[J] if back else st.ktmp[J])
                w += m
        if back:
            st.ktmp[I] = s / w
        else:
            st.kappa[I] = s / w


@ti.func
def csf_force(st: ti.template()):
    """Eq. 19 with [m] = rho V_c and <m> = rho V_c / 2 (MODEL.md).

    Surface tension on a closed surface has no resultant, but the discrete CSF force keeps a
    small one from the curvature's noise (0.3 % of |f| on a disc of points, enough to set it
    drifting). With ``zero_net_force`` the resultant is removed in proportion to node mass."""
    # f_i = V_c gamma kappa grad(c) w(c), c = m_i / (rho V_c): eq. 19 is w = 2c. With a colour
    # threshold c0 > 0, w = 2 max(c - c0, 0) / (1 - c0)^2 keeps the force across an interface
    # (the integral of w dc over [0, 1] is 1) but gives none to nodes that only a few stray
    # points touch: the CSF acceleration does not fall with node mass, and a lone point in a
    # concave pocket was flung out of the box.
    c0 = ti.static(st.csf_c0)
    full = st.rho_ref * st.cell_volume
    coef = st.gamma / (st.rho_ref * (1.0 - c0) * (1.0 - c0))
    if ti.static(st.zero_net_force):
        st.red_f[None] = ti.Vector.zero(float, 3)
    for i, j in ti.ndrange(*active(st)):
        if st.kvalid[i, j] & 2:
            wc = 2.0 * ti.max(st.gm[i, j] / full - c0, 0.0)
            f = coef * st.kappa[i, j] * wc * st.gradm[i, j]
            st.gf[i, j] += f
            if ti.static(st.zero_net_force):
                st.red_f[None] += ti.Vector([f[0], f[1], st.gm[i, j]])
    if ti.static(st.zero_net_force):
        for i, j in ti.ndrange(*active(st)):
            if st.kvalid[i, j] & 2:
                r = st.red_f[None]
                st.gf[i, j] -= st.gm[i, j] / r[2] * ti.Vector([r[0], r[1]])


@ti.func
def level_set(st: ti.template()):
    """phi on the nodes from the points' scatter already in phi_raw (stages 2 above)."""
    contour_segments(st)
    redistance(st)


@ti.func
def surface_geometry(st: ti.template()):
    """Level set, curvature and interface nodes; the CSF force (``csf_force``) follows."""
    level_set(st)
    blur_level_set(st)
    curvature(st)
    mass_gradient(st)
    extend_and_smooth(st)
