"""Initial fields and loads of the verification kinds, handed to the solver through the
``scene`` and ``before_step`` hooks of :class:`~taichi_sls.solver.simulation.Simulation`:
the bar's first axial mode, the manufactured solution's initial velocity and body force, the
Gaussian temperature."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...solver.scene import Scene, build_scene
from .. import references as ref
from .spec import VerificationCase


def scene(vc: VerificationCase) -> Scene:
    """The case's points with the kind's initial velocity or temperature."""
    case, v = vc.case, vc.spec
    sc = build_scene(case)
    x = sc.x
    if v.kind in ("bar", "steffen"):
        b0 = case.bodies[0]
        m = case.materials[b0.material]
        L = b0.max_um[0] * 1e-6
        sel = sc.body == 0
        if v.kind == "bar":
            sc.v0[sel, 0] = ref.bar_velocity(
                x[sel, 0], 0.0, L, m.youngs_solid_Pa, m.density_kg_m3, v.velocity_amplitude_m_s
            )
        else:
            A = v.displacement_amplitude_um * 1e-6
            sc.v0[sel, 0] = ref.steffen_velocity(
                x[sel, 0], 0.0, L, A, m.youngs_solid_Pa, m.density_kg_m3
            )
    elif v.kind == "gaussian":
        r2 = ((x * 1e6 - np.asarray(v.center_um)) ** 2).sum(axis=1)
        sc.T0_C += v.rise_C * np.exp(-r2 / (2.0 * v.sigma_um**2))
    return sc


def before_step(vc: VerificationCase) -> Callable | None:
    """The kind's load applied before every step, or None."""
    if vc.spec.kind != "steffen":
        return None
    case = vc.case
    b0 = case.bodies[0]
    m = case.materials[b0.material]
    L, A = b0.max_um[0] * 1e-6, vc.spec.displacement_amplitude_um * 1e-6

    def manufactured_impulse(sim) -> None:
        """v += b(X, t) dt on body 0: the body force of references.steffen_body_force at the
        start of the step (the explicit step takes its forces at t_n, eq. 13)."""
        pt = sim.state.points
        sel = sim.scene.body == 0
        X = pt.x0.to_numpy()[sel, 0]
        v = pt.v.to_numpy()
        b = ref.steffen_body_force(X, sim.t, L, A, m.youngs_solid_Pa, m.density_kg_m3)
        v[sel, 0] += b * sim.dt
        pt.v.from_numpy(v)

    return manufactured_impulse


def simulation(vc: VerificationCase):
    """A Simulation of the verification case with its initial fields and load."""
    from ...solver.simulation import Simulation

    return Simulation(vc.case, scene=scene(vc), before_step=before_step(vc))
