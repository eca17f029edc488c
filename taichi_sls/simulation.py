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
from .monitor import body_centroids_x, contact_line, point_monitors
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


class Simulation:
    def __init__(self, case: Case, *, init: bool = True) -> None:
        if init:
            init_taichi(case.solver.arch, case.solver.precision, case.solver.optimize)
        self.case = case
        self.dt, self.dt_limits = resolve_dt(case)
        self.scene: Scene = build_scene(case)
        self.state = State(case, self.scene)
        self.state.dt[None] = self.dt
        self.gpu = case.solver.arch == "gpu"
        self.steps = 0
        t0 = time.perf_counter()
        advance(self.state, 0, self.gpu)  # compiles the step kernel
        self.compile_s = time.perf_counter() - t0
        self._x_mass = self.state.mass.to_numpy()
        self._centroid_pair = len(case.bodies) >= 2

    @property
    def t(self) -> float:
        return float(self.state.t[None])

    def advance(self, n: int) -> None:
        """Advance n steps."""
        if n > 0:
            advance(self.state, n, self.gpu)
            self.steps += n

    # ------------------------------------------------------------------ monitors
    def phi(self) -> np.ndarray:
        """Level set on the nodes (m), recomputed unless the last step made it."""
        if not self.state.surface or self.steps == 0:
            level_set_only(self.state)
        return self.state.phi.to_numpy()

    def contact_line_m(self) -> tuple[float, float]:
        """(contact line, neck span) in metres; see :mod:`taichi_sls.monitor`."""
        if not self._centroid_pair:
            return float("nan"), float("nan")
        x = self.state.x.to_numpy()
        cx = body_centroids_x(x, self.scene.body, self._x_mass)
        lo, hi = sorted(cx[:2])
        phi = self.phi()
        h, off = self.state.h, self.state.off
        return contact_line(phi, h, off, lo, hi), contact_line(phi, h, off, lo, hi, span=True)

    def monitors(self) -> dict[str, float]:
        st = self.state
        out = {"t_s": self.t, "step": float(self.steps)}
        pm = point_monitors(st)
        bad = pm.pop("_bad")
        out.update(pm)
        out["T_peak_C"] = float(st.T_peak[None] - KELVIN)
        out["laser_energy_J_per_m"] = float(st.laser_energy[None])
        out["heat_out_J_per_m"] = float(st.heat_out[None])
        cl, span = self.contact_line_m()
        out["contact_line_um"] = cl * 1e6
        out["neck_span_um"] = span * 1e6
        self._guard(out, bad)
        return out

    def _guard(self, mon: dict[str, float], bad: float) -> None:
        where = f"at step {self.steps}, t = {self.t:.6g} s"
        hint = f"time step {self.dt:.3g} s against the limits " + ", ".join(
            f"{k} {v:.3g} s" for k, v in self.dt_limits.items()
        )
        if bad == 1.0 or not all(math.isfinite(v) for k, v in mon.items() if not k.endswith("_um")):
            raise SimulationError(
                f"NaN or infinity in the point state {where}; likely cause: {hint}"
            )
        if bad == 2.0:
            raise SimulationError(f"a point left the grid {where}; likely cause: {hint}")
        if mon["J_min"] <= 0.0:
            raise SimulationError(
                f"Jacobian J = {mon['J_min']:.3g} <= 0 (inverted point) {where}; likely cause: "
                f"{hint}"
            )

    # ------------------------------------------------------------------ checkpoints
    _POINT_FIELDS = ("x", "x0", "v", "C", "F", "eps", "eps_pl", "alpha", "e_iso", "sigma", "J")
    _POINT_FIELDS += ("H", "T", "xi")
    _SCALARS = ("t", "dt", "laser_energy", "heat_out", "T_peak")

    def save_checkpoint(self, path: Path, extra: dict | None = None) -> None:
        """The full state (points and scalars; the grid is rebuilt every step), written
        atomically. ``extra`` (numbers) is stored alongside, e.g. the frame index."""
        st = self.state
        data = {f"p_{k}": getattr(st, k).to_numpy() for k in self._POINT_FIELDS}
        data.update({f"s_{k}": np.array(getattr(st, k)[None]) for k in self._SCALARS})
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
        self.dt = float(z["s_dt"])
        self.steps = int(z["steps"])
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
