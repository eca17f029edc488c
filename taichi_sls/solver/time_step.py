"""The time step and the two clocks (heat, curvature) from the stability limits (eqs. 46-48)."""

from __future__ import annotations

import math

from ..config import Case, CaseError
from .params import stability_limits


def time_step_limits(case: Case) -> dict[str, float]:
    """Stability limits (s) of every material on this grid, the physics switched on only."""
    h = case.grid.spacing_um * 1e-6
    ph = case.physics
    keep = {
        "elastic": ph.mechanics,
        "thermal": ph.thermal,
        "surface_tension": ph.surface_tension and ph.mechanics,
        "viscous": ph.mechanics,
    }
    # inertia scaling lengthens the limits set by inertia: waves and capillary oscillation by
    # sqrt(s), the viscous diffusion of momentum (rho h^2 / c eta) by s
    s = case.solver.mass_scale
    scale = {"elastic": math.sqrt(s), "surface_tension": math.sqrt(s), "thermal": 1.0}
    scale["viscous"] = s
    out: dict[str, float] = {}
    for m in case.materials.values():
        for k, v in stability_limits(m, h, case.domain.dim).items():
            if keep.get(k, False):
                out[k] = min(out.get(k, math.inf), v * scale[k])
    return out


def resolve_dt(case: Case) -> tuple[float, dict[str, float]]:
    """(dt, limits): "auto" is ``time.safety`` times the smallest limit, and no more than the
    heat step (``time.heat_step_fraction`` of the thermal limit: with the inertia scaled the
    thermal limit can be the smallest, and a heat step near it overshoots); a fixed dt above the
    smallest limit is refused unless ``time.allow_unstable_dt``."""
    limits = time_step_limits(case)
    if case.implicit_mechanics() and case.time.integrator == "implicit":
        return _implicit_dt(case, limits)  # hybrid: dt_s is its explicit phase's step
    bound = min(limits.values()) if limits else case.time.end_s
    if case.time.dt_s == "auto":
        dt = case.time.safety * bound
        if "thermal" in limits:
            dt = min(dt, case.time.heat_step_fraction * limits["thermal"])
        return dt, limits
    dt = float(case.time.dt_s)
    if dt > bound and not case.time.allow_unstable_dt:
        which = min(limits, key=limits.get)
        raise CaseError(
            f"time.dt_s = {dt:g}: above the {which} stability limit {bound:.3g} s on this grid "
            f"(limits: {', '.join(f'{k} {v:.3g} s' for k, v in limits.items())}); use a smaller "
            f'dt, "auto", or time.allow_unstable_dt = true'
        )
    return dt, limits


def _implicit_dt(case: Case, explicit: dict[str, float]) -> tuple[float, dict[str, float]]:
    """The implicit step, which no limit bounds (the heat takes substeps,
    :func:`resolve_heat_substeps`): "auto" is ``time.implicit_step_factor`` times the explicit
    "auto" step."""
    t = case.time
    if t.dt_s == "auto":
        return t.implicit_step_factor * t.safety * min(explicit.values(), default=t.end_s), {}
    return float(t.dt_s), {}


def heat_step_max(case: Case) -> float:
    """The longest heat step (s): ``heat_step_fraction`` of the thermal limit (inf without
    heat)."""
    return case.time.heat_step_fraction * time_step_limits(case).get("thermal", math.inf)


def substeps_within(dt: float, longest: float) -> int:
    """The fewest substeps of dt that are each at most ``longest``."""
    return max(1, math.ceil(dt / longest - 1e-9))


def resolve_heat_substeps(case: Case, dt: float) -> int:
    """Heat substeps per implicit step: the fewest whose step is at most :func:`heat_step_max`
    (0 without heat)."""
    longest = heat_step_max(case)
    if math.isinf(longest):
        return 0
    if case.implicit_heat():  # one backward-Euler step
        return 1
    return substeps_within(dt, longest)


def _every(
    key: str, value: int | str, fraction: float, limit: float, dt: float, allow: bool
) -> int:
    if value == "auto":
        return max(1, min(10000, int(fraction * limit / dt)))
    n = int(value)
    if n * dt > limit and not allow:
        raise CaseError(
            f"{key} = {n}: {n} steps of {dt:.3g} s exceed the stability limit {limit:.3g} s; "
            'use a smaller value or "auto"'
        )
    return n


def resolve_heat_every(case: Case, dt: float, limits: dict[str, float]) -> int:
    """Mechanical steps per heat step. Conduction is explicit with a limit ~100x the elastic
    one (paper's fine grid: 9.8e-6 s against 1.3e-7 s), so the heat update runs on its own,
    slower clock; "auto" keeps its step at ``heat_step_fraction`` of the thermal limit."""
    if not case.physics.thermal or case.implicit_mechanics():
        return 1
    t = case.time
    lim = limits.get("thermal", math.inf)
    return _every(
        "time.heat_every", t.heat_every, t.heat_step_fraction, lim, dt, t.allow_unstable_dt
    )


def resolve_curvature_every(case: Case, dt: float, limits: dict[str, float]) -> int:
    """Steps between level-set and curvature rebuilds; "auto" keeps the curvature's age at
    ``curvature_step_fraction`` of the capillary limit (paper's fine grid: every 2 steps)."""
    if "surface_tension" not in limits or case.surface_tension.method != "csf":
        return 1
    s = case.surface_tension
    lim = limits["surface_tension"]
    allow = case.time.allow_unstable_dt
    key = "surface_tension.curvature_every"
    return _every(key, s.curvature_every, s.curvature_step_fraction, lim, dt, allow)
