"""Neck growth against the pair's angle to the grid: Hopper's fluid pair
(cases/verification/hopper.toml, :func:`~.geometry.hopper_geometry`) joined at its contact by a
fillet (``contact.initial = "fillet"``, as every bed contact starts), turned by an angle about
the neck; its neck r_n / R0 read as the process results read it (``Necks.necks_m`` on the
colour, the section across the centres) at the same times for every angle, and against
Hopper with the clock aligned where r_n / R0 first reaches the case's ``hopper_align``.
``bench/isotropy.py`` runs the table of angles, resolutions and Poisson ratios, and reads a bed
run's contacts by their angle (:func:`contact_growth_by_angle`); tests/studies/
test_neck_isotropy.py holds the rows of docs/record/verification.md ("Neck growth at any
angle")."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...config import deep_update
from .. import references as ref
from .capillarity import eta_newtonian
from .common import material
from .setups import simulation
from .spec import VerificationCase, load


def fillet_pair(
    angle_deg: float, R0_over_h: float, fillet_um: float, sets: dict | None = None
) -> VerificationCase:
    """Hopper's pair at R0/h, joined by fillets of ``fillet_um``, its line of centres at
    ``angle_deg`` to x; ``sets`` (nested case keys) merged last."""
    base = {
        "contact": {"initial": "fillet", "fillet_radius_um": fillet_um, "neck_section": "centres"},
        "grid": {"seeding": "area"},
        "verification": {"hopper_angle_deg": angle_deg},
    }
    return load("hopper", R0_over_h, deep_update(base, sets or {}))


@dataclass(frozen=True)
class NeckHistory:
    """r_n / R0 at ``times`` (s) of one pair, its viscous time eta_N R0 / gamma (s), the wall
    time (s) and the steps taken."""

    angle_deg: float
    times: np.ndarray
    neck: np.ndarray
    viscous_time: float
    wall_s: float
    steps: int


def neck_history(vc: VerificationCase, times: np.ndarray) -> NeckHistory:
    """Run the pair of ``vc`` and read its neck (half the per-contact section over R0) at each
    of ``times`` (s, increasing, the first may be 0)."""
    t0 = time.perf_counter()
    m = material(vc.case)
    R0 = vc.case.bodies[0].radius_um * 1e-6
    sim = simulation(vc)
    steps0 = sim.state.scalars.step[None]
    neck = []
    for t in times:
        sim.advance_to(float(t))
        neck.append(0.5 * sim.necks.necks_m("colour")[0] / R0)
    return NeckHistory(
        angle_deg=float(vc.spec.hopper_angle_deg),
        times=np.asarray(times, dtype=float),
        neck=np.array(neck),
        viscous_time=eta_newtonian(m) * R0 / m.surface_tension_N_m,
        wall_s=time.perf_counter() - t0,
        steps=int(sim.state.scalars.step[None] - steps0),
    )


def hopper_errors(history: NeckHistory, taus: tuple[float, ...], align: float) -> dict:
    """Relative error of r_n / R0 against Hopper at each of ``taus``, the clock aligned where
    r_n / R0 first reaches ``align`` (linear between samples); NaN past the run's end."""
    t, n = history.times, history.neck
    k = int(np.argmax(n >= align))
    if n[k] < align or k == 0:
        raise ValueError(f"the neck never crosses {align} after the start: {n.round(4)}")
    t_align = t[k - 1] + (align - n[k - 1]) * (t[k] - t[k - 1]) / (n[k] - n[k - 1])
    tau = ref.hopper_tau_at_neck(align) + (t - t_align) / history.viscous_time
    return {
        q: float(np.interp(q, tau, n)) / float(ref.hopper_neck_at(q)) - 1.0
        if tau[0] <= q <= tau[-1]
        else float("nan")
        for q in taus
    }


def contact_growth_by_angle(run_dir: Path) -> list[dict]:
    """Each melted contact of a bed run (its ``contacts.csv`` and ``resolved.toml``): the angle
    of its line of centres to the grid, folded into [0, 45] deg (the grid's symmetry), and the
    growth of its neck, final over initial. Contacts that never melted are left out (their necks
    barely move, whatever their angle)."""
    import tomllib

    from ...io.contacts_table import read_contacts

    run_dir = Path(run_dir)
    bodies = tomllib.loads((run_dir / "resolved.toml").read_text())["bodies"]
    centres = np.array([b["center_um"][:2] for b in bodies], dtype=float)
    rows = []
    for c in read_contacts(run_dir / "contacts.csv"):
        if not np.isfinite(c["neck_melt_um"]) or not c["neck_initial_um"] > 0.0:
            continue
        d = centres[c["body_b"]] - centres[c["body_a"]]
        angle = float(np.degrees(np.arctan2(abs(d[1]), abs(d[0]))))  # [0, 90]
        rows.append(
            {
                "body_a": c["body_a"],
                "body_b": c["body_b"],
                "angle_deg": min(angle, 90.0 - angle),
                "growth": c["neck_final_um"] / c["neck_initial_um"],
            }
        )
    return rows


def angle_trend(rows: list[dict]) -> tuple[float, float]:
    """(slope of growth against angle per 45 deg, its standard error) by least squares."""
    a = np.array([r["angle_deg"] for r in rows]) / 45.0
    g = np.array([r["growth"] for r in rows])
    A = np.stack([np.ones_like(a), a], axis=1)
    coef = np.linalg.lstsq(A, g, rcond=None)[0]
    dof = max(len(g) - 2, 1)
    sigma2 = float(np.sum((g - A @ coef) ** 2)) / dof
    cov = sigma2 * np.linalg.inv(A.T @ A)
    return float(coef[1]), float(np.sqrt(cov[1, 1]))
