"""Verification against Hopper's coalescence of two equal viscous cylinders (references.hopper):
from two touching discs (the first cusp is under-resolved, so the clocks are aligned where
r_n / R0 first reaches ``hopper_align``), or from the exact outline at ``hopper_tau0`` seeded
as a polygon body. r_n is half the mid-plane's section of the c = 1/2 outline of the colour, the
interface the surface-energy force moves."""

from __future__ import annotations

import math
import time

import numpy as np

from ...config import Case, CaseError
from .. import references as ref
from .capillarity import eta_newtonian
from .common import Result, material, result
from .setups import simulation
from .spec import VerificationCase


def hopper_layout(case: Case) -> tuple[float, float]:
    """(R0, x of the mid-plane) in metres of a Hopper case: from the two discs (or cylinders),
    or from the outline (its area, and the middle of its extent)."""
    R0, centre, _ = hopper_frame(case)
    return R0, centre[0]


def hopper_frame(case: Case) -> tuple[float, np.ndarray, float]:
    """(R0 (m), the neck's centre (m, x-y), the line of centres' angle from x (rad)) of a Hopper
    case: from the two discs or cylinders, or from the outline (R0 from its area, the centre
    the middle of its extent, the angle that of its farthest vertex from the centre)."""
    b = case.bodies
    if b[0].shape in ("disc", "cylinder"):
        a, c = (np.asarray(getattr(x, "center_um", None) or x.axis_um, dtype=float) for x in b[:2])
        d = c - a
        return b[0].radius_um * 1e-6, 0.5e-6 * (a + c), math.atan2(d[1], d[0])
    v = np.asarray(b[0].outline_um(), dtype=float)
    R0 = math.sqrt(abs(ref.polygon_area(v)) / (2.0 * math.pi))
    mid = v.min(axis=0) + v.max(axis=0)
    far = v[np.argmax(np.sum((v - 0.5 * mid) ** 2, axis=1))] - 0.5 * mid
    turn = math.atan2(far[1], far[0])
    turn = 0.0 if abs(math.sin(turn)) < 1e-9 else turn  # along x: the node-line section
    return R0 * 1e-6, 0.5e-6 * mid, turn


def turned_section(c: np.ndarray, h: float, off: int, centre: np.ndarray, turn: float) -> float:
    """Length (m) inside the colour's c = 1/2 outline along the mid-plane through ``centre``
    perpendicular to the line of centres at angle ``turn``: c bilinear between the nodes (as
    the neck sections of solver/neck_section.py read it), sampled every h / 32."""
    from ...solver.monitor import column_material_length
    from ...solver.neck_section import bilinear

    step = h / 32.0
    reach = h * (max(c.shape) + 1)
    t = np.arange(-reach, reach + 0.5 * step, step)
    n = np.array([-math.sin(turn), math.cos(turn)])
    xy = centre[None, :] + t[:, None] * n[None, :]
    cs = bilinear(c, h, off, xy[:, 0], xy[:, 1], outside=0.0)
    return column_material_length(0.5 - cs, step)


def midplane_section(sim, case: Case) -> float:
    """The mid-plane's section (m) of the colour's c = 1/2 outline: on the vertical line for a
    pair along x (marching squares, :func:`colour_section`), on the turned line otherwise; in
    3D the mean over the node layers of the periodic depth (each an x-y section)."""
    _, centre, turn = hopper_frame(case)
    cfg = sim.state.cfg
    if cfg.dim == 3:
        from ...solver.periodic_views import periodic_colour

        periodic_colour(sim.state)
        c = sim.necks.node_arrays()["colour"]
    else:
        c = sim.necks.colour()
    layers = [c] if c.ndim == 2 else [c[:, :, cfg.off + k] for k in range(cfg.ncz)]
    if turn == 0.0:
        return float(np.mean([colour_section(cl, cfg.h, cfg.off, centre[0]) for cl in layers]))
    return float(np.mean([turned_section(cl, cfg.h, cfg.off, centre, turn) for cl in layers]))


def _cell_crossings(f: np.ndarray, x0: tuple[float, float], h: float, x: float) -> list[float]:
    """y where the vertical line at x crosses the marching-squares outline of one cell (as
    physics/contour.py draws it: f = (f00, f10, f11, f01) counter-clockwise, inside f < 0)."""
    inside = [v < 0.0 for v in f]
    n_in = sum(inside)
    if n_in in (0, 4):
        return []
    cx, cy = x0
    corner = [(cx, cy), (cx + h, cy), (cx + h, cy + h), (cx, cy + h)]
    cross = {}
    for k in range(4):
        k1 = (k + 1) % 4
        if inside[k] != inside[k1]:
            t = f[k] / (f[k] - f[k1])
            (ax, ay), (bx, by) = corner[k], corner[k1]
            cross[k] = (ax + t * (bx - ax), ay + t * (by - ay))
    if n_in == 2 and inside[0] == inside[2]:
        centre_in = sum(f) < 0.0
        segs = [(cross[(k + 3) % 4], cross[k]) for k in range(4) if inside[k] != centre_in]
    else:
        ks = sorted(cross)
        segs = [(cross[ks[0]], cross[ks[1]])]
    return [
        ay + (x - ax) / (bx - ax) * (by - ay)
        for (ax, ay), (bx, by) in segs
        if (ax - x) * (bx - x) < 0.0
    ]


def colour_section(c: np.ndarray, h: float, off: int, x: float) -> float:
    """Length (m) of the vertical line at x inside the colour's c = 1/2 outline."""
    from ...solver.monitor import column_material_length

    u = x / h + off
    if abs(u - round(u)) < 1e-9:  # on a node column: c linear between its nodes
        return column_material_length(0.5 - c[int(round(u))], h)
    i = int(np.floor(u))
    ys = []
    for j in range(c.shape[1] - 1):
        f = 0.5 - np.array([c[i, j], c[i + 1, j], c[i + 1, j + 1], c[i, j + 1]])
        ys += _cell_crossings(f, ((i - off) * h, (j - off) * h), h, x)
    ys.sort()
    return float(sum(ys[k + 1] - ys[k] for k in range(0, len(ys) - 1, 2)))


def hopper_neck_history(vc: VerificationCase, tau_end: float, d_tau: float = 0.02) -> tuple:
    """Run a Hopper case; returns (sim, tau, r_n / R0, point area, viscous time, r_n / R0 of the
    per-contact section) sampled every d_tau until the aligned clock reaches tau_end. The
    clock is aligned on the mid-plane's r_n; the last is half of ``Necks.necks_m`` on the
    colour (the section across the centres the process results rest on), read beside it."""
    case, v = vc.case, vc.spec
    m = material(case)
    R0 = hopper_frame(case)[0]
    T = eta_newtonian(m) * R0 / m.surface_tension_N_m
    sim = simulation(vc)
    st = sim.state
    per = max(1, int(round(d_tau * T / sim.dt)))
    ts, rn, area, rc = [], [], [], []

    def sample() -> None:
        ts.append(sim.t)
        rn.append(0.5 * midplane_section(sim, case) / R0)
        necks = sim.necks.necks_m("colour") if case.domain.dim == 2 else []
        rc.append(0.5 * necks[0] / R0 if necks else math.nan)  # one outline body: no contact
        area.append(float((st.points.volume0.to_numpy() * st.points.J.to_numpy()).sum()))

    sample()
    t_align = 0.0 if v.hopper_tau0 > 0 else None
    tau_align = v.hopper_tau0 if v.hopper_tau0 > 0 else ref.hopper_tau_at_neck(v.hopper_align)
    while True:
        sim.advance_to(sim.t + per * sim.dt)  # whole steps; an adaptive one lands there
        sample()
        if t_align is None and rn[-1] >= v.hopper_align:
            a, b = rn[-2], rn[-1]
            t_align = ts[-2] + (v.hopper_align - a) * (ts[-1] - ts[-2]) / (b - a)
        if t_align is not None and tau_align + (sim.t - t_align) / T >= tau_end:
            break
        if sim.t > case.time.end_s:
            raise CaseError(
                f"verification.kind = 'hopper': tau {tau_end} not reached by time.end_s = "
                f"{case.time.end_s} (r_n / R0 = {rn[-1]:.3f})"
            )
    tau = tau_align + (np.array(ts) - t_align) / T
    return sim, tau, np.array(rn), np.array(area), T, np.array(rc)


def run_hopper(vc: VerificationCase) -> Result:
    """Hopper's coalescence: r_n / R0 on the colour interface against the exact neck at each of
    ``hopper_taus`` (relative errors ``neck_tau<tau>`` on the mid-plane, ``neck_centres_tau<tau>``
    on the per-contact section of ``Necks.necks_m``) and the largest relative change of the
    points' area over the run."""
    t0 = time.perf_counter()
    taus = sorted(vc.spec.hopper_taus)
    sim, tau, rn, area, T, rc = hopper_neck_history(vc, taus[-1])
    errors = {}
    for tq in taus:
        errors[f"neck_tau{tq:g}"] = float(np.interp(tq, tau, rn)) / ref.hopper_neck_at(tq) - 1.0
    for tq in taus if np.isfinite(rc).all() else ():
        exact = ref.hopper_neck_at(tq)
        errors[f"neck_centres_tau{tq:g}"] = float(np.interp(tq, tau, rc)) / exact - 1.0
    dev = area / area[0] - 1.0
    errors["area"] = float(dev[np.argmax(np.abs(dev))])
    info = {f"neck_sim_tau{tq:g}": float(np.interp(tq, tau, rn)) for tq in taus}
    return result(
        vc.case, sim, errors, t0, tau_at_start=float(tau[0]), neck_start=float(rn[0]), **info
    )
