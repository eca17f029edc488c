"""A simulation: Taichi set-up, time step, stepping, monitors and snapshots of one case."""

from __future__ import annotations

import math
import os
import time
from pathlib import Path

import numpy as np
import taichi as ti

from .case import Case, CaseError
from .materials import KELVIN, stability_limits
from .monitor import body_centroids_x, neck_measures, point_monitors
from .scene import Scene, build_scene
from .state import State
from .step import advance, level_set_only


class SimulationError(RuntimeError):
    """The guard tripped: the state is no longer physical. The message says what and where."""


def init_taichi(arch: str = "cpu", precision: str = "f64", optimize: bool = False) -> None:
    """(Re)initialise Taichi. Re-initialising frees every field, so one Simulation is live at a
    time. ``optimize=False`` skips Taichi's advanced IR optimisation: the fused step compiles in
    5-10 s instead of about 100 s and runs about 1.5x slower (914 against ~650 steps/s on the
    paper's fine case, 2-core CPU)."""
    ti.init(
        arch=ti.cpu if arch == "cpu" else ti.gpu,
        default_fp=ti.f64 if precision == "f64" else ti.f32,
        offline_cache=True,
        advanced_optimization=optimize,
        log_level=ti.ERROR,
    )


def time_step_limits(case: Case) -> dict[str, float]:
    """Stability limits (s) of every material on this grid, the physics switched on only."""
    h = case.grid.spacing_um * 1e-6
    ph = case.physics
    out: dict[str, float] = {}
    for m in case.materials.values():
        lim = stability_limits(m, h)
        keep = {
            "elastic": ph.mechanics,
            "thermal": ph.thermal,
            "surface_tension": ph.surface_tension and ph.mechanics,
        }
        for k, v in lim.items():
            if keep.get(k, False):
                out[k] = min(out.get(k, math.inf), v)
    return out


def resolve_dt(case: Case) -> tuple[float, dict[str, float]]:
    limits = time_step_limits(case)
    bound = min(limits.values()) if limits else case.time.end_s
    if case.time.dt_s == "auto":
        return case.time.safety * bound, limits
    dt = float(case.time.dt_s)
    if dt > bound and not case.time.allow_unstable_dt:
        which = min(limits, key=limits.get)
        raise CaseError(
            f"time.dt_s = {dt:g}: above the {which} stability limit {bound:.3g} s on this grid "
            f"(limits: {', '.join(f'{k} {v:.3g} s' for k, v in limits.items())}); use a smaller "
            f'dt, "auto", or time.allow_unstable_dt = true'
        )
    return dt, limits


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
    if not case.physics.thermal:
        return 1
    t = case.time
    lim = limits.get("thermal", math.inf)
    return _every(
        "time.heat_every", t.heat_every, t.heat_step_fraction, lim, dt, t.allow_unstable_dt
    )


def resolve_curvature_every(case: Case, dt: float, limits: dict[str, float]) -> int:
    """Steps between level-set and curvature rebuilds; "auto" keeps the curvature's age at
    ``curvature_step_fraction`` of the capillary limit (paper's fine grid: every 2 steps)."""
    if "surface_tension" not in limits:
        return 1
    s = case.surface_tension
    lim = limits["surface_tension"]
    allow = case.time.allow_unstable_dt
    key = "surface_tension.curvature_every"
    return _every(key, s.curvature_every, s.curvature_step_fraction, lim, dt, allow)


class Simulation:
    def __init__(self, case: Case, *, init: bool = True, scene: Scene | None = None) -> None:
        """``scene``: the points to use instead of seeding the case's bodies (the speed
        benchmark passes them shuffled)."""
        if init:
            init_taichi(case.solver.arch, case.solver.precision, case.solver.optimize)
        self.case = case
        self.dt, self.dt_limits = resolve_dt(case)
        self.heat_every = resolve_heat_every(case, self.dt, self.dt_limits)
        self.curvature_every = resolve_curvature_every(case, self.dt, self.dt_limits)
        self.scene: Scene = build_scene(case) if scene is None else scene
        self.state = State(case, self.scene, self.heat_every, self.curvature_every)
        self.state.dt[None] = self.dt
        # the energy balance holds to round-off: ~1e-12 in f64, ~1e-6 in f32
        self.energy_tol = 1e-6 if case.solver.precision == "f64" else 1e-3
        self.steps = 0
        t0 = time.perf_counter()
        advance(self.state, 0)  # compiles the step kernel
        self.compile_s = time.perf_counter() - t0
        self._x_mass = self.state.mass.to_numpy()
        # conduction obeys a maximum principle: no point may cool below the coldest start or wall
        walls = [w.temperature_C for w in vars(case.boundary).values() if w.thermal == "fixed"]
        coldest = min([float(self.scene.T0_C.min()), *walls])
        self._T_floor = coldest + KELVIN if case.physics.thermal else -math.inf
        self._centroid_pair = len(case.bodies) >= 2
        self._H0: float | None = None  # enthalpy at step 0, for the energy-balance check
        self._e_static: float | None = None  # the step-independent part of _energy_bound

    @property
    def t(self) -> float:
        return float(self.state.t[None])

    def advance(self, n: int) -> None:
        """Advance n steps."""
        if n <= 0:
            return
        if self.case.verification.kind == "steffen":
            for _ in range(n):  # the manufactured body force changes every step
                self._manufactured_impulse()
                advance(self.state, 1)
        else:
            advance(self.state, n)
        self.steps += n

    def _manufactured_impulse(self) -> None:
        """v += b(X, t) dt on body 0: the body force of references.steffen_body_force at the
        start of the step (the explicit step takes its forces at t_n, eq. 13)."""
        from .references import steffen_body_force

        c = self.case
        b0 = c.bodies[0]
        m = c.materials[b0.material]
        sel = self.scene.body == 0
        X = self.state.x0.to_numpy()[sel, 0]
        v = self.state.v.to_numpy()
        L, A = b0.max_um[0] * 1e-6, c.verification.displacement_amplitude_um * 1e-6
        b = steffen_body_force(X, self.t, L, A, m.youngs_solid_Pa, m.density_kg_m3)
        v[sel, 0] += b * self.dt
        self.state.v.from_numpy(v)

    # ------------------------------------------------------------------ monitors
    def phi(self) -> np.ndarray:
        """Level set on the nodes (m) of the current points (the step's own may be up to
        curvature_every - 1 steps old)."""
        level_set_only(self.state)
        return self.state.phi.to_numpy()

    def contact_line_m(self) -> tuple[float, float]:
        """(contact line, neck span) in metres; see :mod:`taichi_sls.monitor`."""
        if not self._centroid_pair:
            return float("nan"), float("nan")
        x = self.state.x.to_numpy()
        cx = body_centroids_x(x, self.scene.body, self._x_mass)
        lo, hi = sorted(cx[:2])
        return neck_measures(self.phi(), self.state.h, self.state.off, lo, hi)

    def monitors(self) -> dict[str, float]:
        """Monitored quantities (SI, temperatures in C, lengths in um); runs the guard."""
        st = self.state
        out = {"t_s": self.t, "step": float(self.steps)}
        pm = point_monitors(st)
        internal = {k: pm.pop(k) for k in list(pm) if k.startswith("_")}
        out.update(pm)
        out["T_peak_C"] = float(st.T_peak[None] - KELVIN)
        out["laser_energy_J_per_m"] = float(st.laser_energy[None])
        out["heat_out_J_per_m"] = float(st.heat_out[None])
        cl, span = self.contact_line_m()
        out["contact_line_um"] = cl * 1e6
        out["neck_span_um"] = span * 1e6
        if self.steps == 0 and self._H0 is None:
            self._H0 = out["enthalpy_J_per_m"]
        self._guard(out, internal)
        return out

    # guard thresholds: a Jacobian beyond this is no longer a small-strain continuum, a point
    # moving more than this fraction of a cell per step has outrun the grid (the motion limit)
    J_ABSURD = 20.0
    MOTION_CELLS = 0.5
    T_ABSURD_K = 1e4

    def _energy_error(self, mon: dict[str, float]) -> float:
        """(laser - heat out - enthalpy rise) / (initial enthalpy + laser): 0 up to round-off."""
        if self._H0 is None:
            return 0.0
        rise = mon["enthalpy_J_per_m"] - self._H0
        net = mon["laser_energy_J_per_m"] - mon["heat_out_J_per_m"]
        return (net - rise) / (abs(self._H0) + mon["laser_energy_J_per_m"])

    def _energy_bound(self) -> float:
        """Every energy a run can turn into motion: initial kinetic energy, surface energy of the
        bodies' outlines, potential energy across the domain, laser energy so far (J/m)."""
        if self._e_static is None:
            c = self.case
            perim = sum(
                2 * math.pi * b.radius_um
                if b.shape == "disc"
                else 2 * (b.max_um[0] - b.min_um[0] + b.max_um[1] - b.min_um[1])
                for b in c.bodies
            )
            gamma = max(m.surface_tension_N_m for m in c.materials.values())
            g = math.hypot(*c.physics.gravity_m_s2)
            M = float(self._x_mass.sum())
            v0 = self.state.v.to_numpy()
            ke0 = 0.5 * float((self._x_mass * (v0**2).sum(axis=1)).sum())
            self._e_static = ke0 + gamma * perim * 1e-6 + M * g * self.scene.height
        return self._e_static + float(self.state.laser_energy[None])

    def _where(self, values: np.ndarray) -> str:
        """Location of the point where ``values`` is worst (NaN first)."""
        bad = np.where(np.isfinite(values), values, np.inf)
        i = int(np.argmax(bad))
        x = self.state.x.to_numpy()[i] * 1e6
        return f"point {i} (body {int(self.scene.body[i])}) at x = {x[0]:.2f}, y = {x[1]:.2f} um"

    def _guard(self, mon: dict[str, float], internal: dict[str, float]) -> None:
        """Stop with one message naming the quantity, step, time, place and likely cause."""
        st = self.state
        when = f"at step {self.steps}, t = {self.t:.6g} s"
        hint = f"time step {self.dt:.3g} s against the limits " + ", ".join(
            f"{k} {v:.3g} s" for k, v in self.dt_limits.items()
        )
        problem = None
        finite = all(math.isfinite(v) for k, v in mon.items() if not k.endswith("_um"))
        if internal["_bad"] == 1.0 or not finite:
            x = st.x.to_numpy()
            score = (~np.isfinite(x.sum(axis=1) + st.T.to_numpy() + st.J.to_numpy())).astype(float)
            problem = (f"NaN or infinity in the point state, first at {self._where(score)}", hint)
        elif internal["_bad"] == 2.0:
            x = st.x.to_numpy()
            r = np.abs(x - np.array([self.scene.width, self.scene.height]) / 2).max(axis=1)
            problem = (f"a point left the grid: {self._where(r)}", hint)
        elif mon["J_min"] <= 0.0:
            problem = (
                f"Jacobian J = {mon['J_min']:.3g} <= 0 (inverted point) at "
                f"{self._where(-st.J.to_numpy())}",
                f"strains of order one (a material too soft for the surface tension or load: "
                f"the small-strain model breaks down), or the {hint}",
            )
        elif internal["_J_max"] > self.J_ABSURD:
            problem = (
                f"Jacobian J = {internal['_J_max']:.3g} > {self.J_ABSURD} (a point swelled "
                f"absurdly) at {self._where(st.J.to_numpy())}",
                hint,
            )
        elif internal["_v_max"] * self.dt > self.MOTION_CELLS * st.h:
            problem = (
                f"a point moves {internal['_v_max'] * self.dt / st.h:.2f} cells per step "
                f"(|v| = {internal['_v_max']:.3g} m/s) at "
                f"{self._where(np.linalg.norm(st.v.to_numpy(), axis=1))}",
                f"the motion limit; {hint}",
            )
        elif internal["_T_min"] < self._T_floor - 1.0 or mon["T_max_C"] + KELVIN > self.T_ABSURD_K:
            T = st.T.to_numpy()
            worst = np.maximum(self._T_floor - T, T - self.T_ABSURD_K)
            problem = (
                f"temperature {T[np.argmax(worst)] - KELVIN:.1f} C outside the physical range "
                f"[{self._T_floor - KELVIN:.1f} C (coldest start or wall), "
                f"{self.T_ABSURD_K - KELVIN:.0f} C] at {self._where(worst)}",
                f"the thermal limit; {hint}",
            )
        elif abs(self._energy_error(mon)) > self.energy_tol:
            problem = (
                f"energy balance broken: laser - heat out - enthalpy rise = "
                f"{self._energy_error(mon):.3g} of the energy scale",
                f"the thermal limit; {hint}",
            )
        elif mon["kinetic_energy_J_per_m"] > 10.0 * self._energy_bound():
            problem = (
                f"kinetic energy {mon['kinetic_energy_J_per_m']:.3g} J/m exceeds ten times every "
                f"source of energy ({self._energy_bound():.3g} J/m)",
                hint,
            )
        if problem is not None:
            raise SimulationError(f"{problem[0]} {when}; likely cause: {problem[1]}")

    # ------------------------------------------------------------------ checkpoints
    _POINT_FIELDS = ("x", "x0", "v", "C", "F", "eps", "eps_pl", "alpha", "e_iso", "de_iso")
    _POINT_FIELDS += ("sigma", "J")
    _POINT_FIELDS += ("H", "T", "xi")
    _SCALARS = ("t", "dt", "laser_energy", "heat_out", "T_peak")
    # curvature is kept between rebuilds (surface_tension.curvature_every): part of the state
    _GRID_FIELDS = ("kappa", "kvalid")

    def save_checkpoint(self, path: Path, extra: dict | None = None) -> None:
        """The full state (points and scalars; the grid is rebuilt every step), written
        atomically. ``extra`` (numbers) is stored alongside, e.g. the frame index."""
        st = self.state
        data = {f"p_{k}": getattr(st, k).to_numpy() for k in self._POINT_FIELDS}
        data.update({f"s_{k}": np.array(getattr(st, k)[None]) for k in self._SCALARS})
        data.update({f"g_{k}": getattr(st, k).to_numpy() for k in self._GRID_FIELDS})
        data["steps"] = np.array(self.steps)
        data["case_name"] = np.array(self.case.case.name)
        for k, v in (extra or {}).items():
            data[f"x_{k}"] = np.array(v)
        path = Path(path)
        tmp = path.with_name(path.name + ".tmp.npz")
        np.savez(tmp, **data)
        os.replace(tmp, path)

    def load_checkpoint(self, path: Path) -> dict:
        """Restore a state saved by :meth:`save_checkpoint`; returns its ``extra``."""
        try:
            z = np.load(path)
        except (OSError, ValueError) as e:
            raise CaseError(f"--resume {path}: not a readable checkpoint ({e})") from None
        st = self.state
        n = z["p_x"].shape[0]
        if n != st.n_points or str(z["case_name"]) != self.case.case.name:
            raise CaseError(
                f"--resume {path}: checkpoint of case {str(z['case_name'])!r} with {n} points "
                f"does not match case {self.case.case.name!r} with {st.n_points} points"
            )
        for k in self._POINT_FIELDS:
            getattr(st, k).from_numpy(z[f"p_{k}"])
        for k in self._SCALARS:
            getattr(st, k)[None] = float(z[f"s_{k}"])
        for k in self._GRID_FIELDS:
            getattr(st, k).from_numpy(z[f"g_{k}"])
        self.dt = float(z["s_dt"])
        self.steps = int(z["steps"])
        st.step[None] = self.steps
        return {k[2:]: z[k].item() for k in z.files if k.startswith("x_")}

    def snapshot(self) -> dict[str, np.ndarray]:
        st = self.state
        x = st.x.to_numpy()
        return {
            "x_um": x * 1e6,
            "T_C": st.T.to_numpy() - KELVIN,
            "displacement_um": np.linalg.norm(x - st.x0.to_numpy(), axis=1) * 1e6,
            "plastic_strain": st.alpha.to_numpy(),
            "liquid_fraction": 1.0 - st.xi.to_numpy(),
        }
