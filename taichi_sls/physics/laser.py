"""The Gaussian laser of eq. 31 (docs/model.md reading: power per unit volume, Beer-Lambert decay
with depth below the top of the powder).

Each beam is one element of a struct field whose members are in SI (the case's ``_um`` keys in
metres): ``on_s``, ``off_s``, ``x_start_m``, ``speed_m_s``, ``x_end_m``, ``top_m``,
``spot_radius_m``, ``penetration_depth_m``, ``amplitude_W_m3`` (2 A P / (pi r0^2 eta) times the
depth factor, times rho for the printed per-mass reading).

Hatches (``across`` = 1, docs/model.md "Hatches"): the plane is a section across parallel tracks.
Track k runs normal to the plane at x_k = ``x_start_m`` + k ``hatch_m``; its spot crosses the
plane at t_k = ``on_s`` + ``pass_half_s`` + k ``return_s`` at ``speed_m_s`` = v, so the plane sees
the Gaussian in time exp(-2 v^2 (t - t_k)^2 / r0^2) within t_k +- ``pass_half_s``. A step takes
its exact time mean (erf), so the energy a pass delivers does not depend on the step.

3D (docs/model.md, "The laser in 3D"): eq. 31 is a spot in the bed plane (x, z), the Gaussian
exp(-2 r^2 / r0^2) of the distance r from its centre, which moves along x (``along_z`` = 0) or
z (1) at ``speed_m_s``. Track k starts at ``on_s`` + k ``return_s`` at the same start along the
scan, offset k ``hatch_m`` along the other bed axis, and heats until ``off_s``, the next track's
start, or its centre passing the end (``x_end_m`` or ``z_end_m``). Its plane integral is A P
times the depth factor (2D: the central section's A P sqrt(2 / pi) / r0, per unit depth).

Depth: below y_l = ``top_m`` (the scene's top), or with ``local_surface`` = 1 below the local
surface, the highest point top in the point's grid column (physics/beam_surface.py)."""

from taichi_sls.backend import ti

LASER_MEMBERS = (
    "on_s",
    "off_s",
    "x_start_m",
    "speed_m_s",
    "x_end_m",
    "top_m",
    "amplitude_W_m3",
    "spot_radius_m",
    "penetration_depth_m",
    "across",
    "tracks",
    "hatch_m",
    "return_s",
    "pass_half_s",
    "z_start_m",
    "z_end_m",
    "along_z",
    "local_surface",
)

# erf by Abramowitz & Stegun 7.1.26 (absolute error below 1.5e-7): Taichi has none
ERF_P = 0.3275911
ERF_A = (0.254829592, -0.284496736, 1.421413741, -1.453152027, 1.061405429)


def laser_struct():
    """The struct type of one beam (built after ti.init)."""
    return ti.types.struct(**{k: float for k in LASER_MEMBERS})


@ti.func
def erf(x):
    """The error function, Abramowitz & Stegun 7.1.26 (odd; absolute error below 1.5e-7)."""
    z = ti.abs(x)
    u = 1.0 / (1.0 + ERF_P * z)
    poly = u * (ERF_A[0] + u * (ERF_A[1] + u * (ERF_A[2] + u * (ERF_A[3] + u * ERF_A[4]))))
    y = 1.0 - poly * ti.exp(-z * z)
    if x < 0.0:
        y = -y
    return y


@ti.func
def hatch_source(las: ti.template(), xp, t, dt):
    """Mean power per unit volume at xp over [t, t + dt] of a beam whose tracks cross the plane
    (module docstring), without the depth factor."""
    s = 0.0
    r0 = las.spot_radius_m
    a = ti.sqrt(2.0) * las.speed_m_s / r0  # exp(-a^2 (t - t_k)^2)
    half = las.pass_half_s
    for k in range(ti.cast(las.tracks, ti.i32)):
        tc = las.on_s + half + k * las.return_s
        t0 = ti.max(ti.max(t, las.on_s), tc - half)
        t1 = ti.min(ti.min(t + dt, las.off_s), tc + half)
        if t1 > t0:
            dx = las.x_start_m + k * las.hatch_m - xp[0]
            mean = erf(a * (t1 - tc)) - erf(a * (t0 - tc))  # times sqrt(pi) / (2 a dt)
            s += mean * ti.sqrt(ti.math.pi) / (2.0 * a * dt) * ti.exp(-2.0 * dx * dx / (r0 * r0))
    return s


@ti.func
def lit_interval(t, dt, on, off, start, end, speed):
    """The part [t0, t1] of the step [t, t + dt] in which a beam switched on at ``on`` and off
    at ``off`` is lit (empty where t1 <= t0): it is off while its centre start + speed (t - on)
    lies beyond end."""
    t0 = ti.max(t, on)
    t1 = ti.min(t + dt, off)
    if speed > 0.0:
        t1 = ti.min(t1, on + (end - start) / speed)
    elif speed < 0.0:
        t0 = ti.max(t0, on + (end - start) / speed)
    elif start > end:
        t1 = t0
    return t0, t1


@ti.func
def spot_source_3d(las: ti.template(), xp, t, dt):
    """Mean power per unit volume at xp over [t, t + dt] of a 3D beam's tracks in the bed
    (module docstring), without the depth factor; each track's on-time within the step exact,
    its centre taken at the middle of that time."""
    s = 0.0
    r0 = las.spot_radius_m
    speed = las.speed_m_s
    start, end, lateral0 = las.x_start_m, las.x_end_m, las.z_start_m
    along, across = xp[0], xp[2]
    if las.along_z > 0.0:
        start, end, lateral0 = las.z_start_m, las.z_end_m, las.x_start_m
        along, across = xp[2], xp[0]
    n = ti.cast(las.tracks, ti.i32)
    for k in range(n):
        on = las.on_s + k * las.return_s
        t0, t1 = lit_interval(t, dt, on, las.off_s, start, end, speed)
        if k < n - 1:  # until the next track starts
            t1 = ti.min(t1, on + las.return_s)
        if t1 > t0:
            da = start + speed * (0.5 * (t0 + t1) - on) - along
            dl = lateral0 + k * las.hatch_m - across
            s += ((t1 - t0) / dt) * ti.exp(-2.0 * (da * da + dl * dl) / (r0 * r0))
    return s


@ti.func
def laser_source(cfg: ti.template(), lasers: ti.template(), xp, t, dt, column_top):
    """Mean power per unit volume at xp over [t, t + dt], summed over the beams. Each beam's
    on-time within the step is exact (a heat step may span many mechanical steps and a switch-on
    or -off), its position taken at the middle of that time. ``column_top``: the local surface
    above xp (used by beams with ``local_surface``; cfg.local_surface compiles it in)."""
    s = 0.0
    for k in range(cfg.n_lasers):
        las = lasers[k]
        top = las.top_m
        if ti.static(cfg.local_surface):
            if las.local_surface > 0.0:
                top = column_top
        if ti.static(cfg.dim == 3):
            depth = ti.max(top - xp[1], 0.0)
            s += (
                las.amplitude_W_m3
                * spot_source_3d(las, xp, t, dt)
                * ti.exp(-depth / las.penetration_depth_m)
            )
            continue
        if las.across > 0.0:
            depth = ti.max(top - xp[1], 0.0)
            s += (
                las.amplitude_W_m3
                * hatch_source(las, xp, t, dt)
                * ti.exp(-depth / las.penetration_depth_m)
            )
            continue
        on = las.on_s
        x0 = las.x_start_m
        speed = las.speed_m_s
        x_end = las.x_end_m
        t0, t1 = lit_interval(t, dt, on, las.off_s, x0, x_end, speed)
        if t1 > t0:
            xl = x0 + speed * (0.5 * (t0 + t1) - on)
            r0 = las.spot_radius_m
            eta = las.penetration_depth_m
            depth = ti.max(top - xp[1], 0.0)
            dx = xl - xp[0]
            s += (
                las.amplitude_W_m3
                * ((t1 - t0) / dt)
                * ti.exp(-2.0 * dx * dx / (r0 * r0))
                * ti.exp(-depth / eta)
            )
    return s
