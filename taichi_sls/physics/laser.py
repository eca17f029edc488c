"""The Gaussian laser of eq. 31 (docs/model.md reading: power per unit volume, Beer-Lambert decay
with depth below the top of the powder).

Each beam is one element of a struct field whose members are in SI (the case's ``_um`` keys in
metres): ``on_s``, ``off_s``, ``x_start_m``, ``speed_m_s``, ``x_end_m``, ``top_m``,
``spot_radius_m``, ``penetration_depth_m``, ``amplitude_W_m3`` (2 A P / (pi r0^2 eta) times the
depth factor, times rho for the printed per-mass reading) and ``depth_sign`` (+1 decay, -1 the
printed sign)."""

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
    "depth_sign",
)


def laser_struct():
    """The struct type of one beam (built after ti.init)."""
    return ti.types.struct(**{k: float for k in LASER_MEMBERS})


@ti.func
def laser_source(lasers: ti.template(), n_lasers: ti.template(), xp, t, dt):
    """Mean power per unit volume at xp over [t, t + dt], summed over the beams. Each beam's
    on-time within the step is exact (a heat step may span many mechanical steps and a switch-on
    or -off), its position taken at the middle of that time."""
    s = 0.0
    for k in range(n_lasers):
        las = lasers[k]
        on = las.on_s
        x0 = las.x_start_m
        speed = las.speed_m_s
        x_end = las.x_end_m
        t0 = ti.max(t, on)
        t1 = ti.min(t + dt, las.off_s)
        # the beam is off while its centre x0 + speed (t - on) lies beyond x_end
        if speed > 0.0:
            t1 = ti.min(t1, on + (x_end - x0) / speed)
        elif speed < 0.0:
            t0 = ti.max(t0, on + (x_end - x0) / speed)
        elif x0 > x_end:
            t1 = t0
        if t1 > t0:
            xl = x0 + speed * (0.5 * (t0 + t1) - on)
            r0 = las.spot_radius_m
            eta = las.penetration_depth_m
            depth = ti.max(las.top_m - xp[1], 0.0)
            dx = xl - xp[0]
            s += (
                las.amplitude_W_m3
                * ((t1 - t0) / dt)
                * ti.exp(-2.0 * dx * dx / (r0 * r0))
                * ti.exp(-las.depth_sign * depth / eta)
            )
    return s
