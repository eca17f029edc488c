"""A simulation: Taichi set-up, time step, stepping, monitors and snapshots of one case."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from taichi_sls.backend import ti

from .. import taichi_patches
from ..config import Case
from ..physics.materials import KELVIN
from . import checkpoint, compile_clock, struct_copy
from .adaptive import AdaptiveStepper
from .blocks import BlockPlan
from .contacts import touching
from .extrapolation import ExtrapolatedStepper
from .fields import State
from .guard import Guard, temperature_floor_K
from .handover import Handover, HybridStepper, explicit_view
from .implicit import ImplicitStepper
from .linear_solve import direct_backend
from .monitor import point_monitors
from .necks import HOST_POINT_MEMBERS, Necks, point_arrays
from .params import imposed_table, laser_arrays, material_arrays
from .scene import Scene, build_scene
from .step import init_box
from .step_config import Layout, choose_layout, step_config
from .stepper import ExplicitStepper, StepHooks, Stepper
from .time_step import (
    heat_step_max,
    resolve_curvature_every,
    resolve_dt,
    resolve_heat_every,
    resolve_heat_substeps,
    time_step_limits,
)

OFFLINE_CACHE_BYTES = 2**30  # ~5 MB a case's kernels


def init_taichi(
    arch: str = "cpu",
    precision: str = "f64",
    optimize: bool = False,
    fast_math: bool = True,
    threads: int = 0,
) -> None:
    """(Re)initialise Taichi. Re-initialising frees every field, so one Simulation is live at a
    time. ``optimize=False`` skips Taichi's advanced IR optimisation: the fused step compiles many
    times faster and runs somewhat slower (docs/record/compile.md). ``fast_math=False``: strict
    IEEE arithmetic (the compiler may not reorder sums), so that a change of code structure that
    keeps every formula keeps every result bit for bit."""
    taichi_patches.install(ti)  # Taichi's front end memoized (taichi_patches/front_end.py)
    ti.init(
        arch=ti.cpu if arch == "cpu" else ti.gpu,
        default_fp=ti.f64 if precision == "f64" else ti.f32,
        offline_cache=True,
        # Taichi's default keeps 100 MB and drops the least recently used quarter: a "warm" start
        # after a few cases and the suite would compile a part of its kernels again
        # (docs/record/compile.md)
        offline_cache_max_size_of_files=OFFLINE_CACHE_BYTES,
        unrolling_limit=0,  # struct_copy unrolls over a struct's members on purpose: no warning
        advanced_optimization=optimize,
        fast_math=fast_math,
        log_level=ti.ERROR,
        **({"cpu_max_num_threads": threads} if threads else {}),
    )


class Simulation:
    """One case on the device: ``advance_to(t)`` steps, ``monitors()`` reads (and guards) the
    state, ``necks`` measures the interface and the necks, ``snapshot()`` gives the points for
    output.

    ``scene``: the points to use instead of seeding the case's bodies (studies set initial
    fields through it; the speed benchmark passes them shuffled). ``before_step``: called with
    the simulation before every step (a study's time-dependent load); stepping then goes one
    step per kernel call."""

    def __init__(
        self,
        case: Case,
        *,
        init: bool = True,
        scene: Scene | None = None,
        before_step: Callable[[Simulation], None] | None = None,
    ) -> None:
        clock0 = compile_clock.reading()
        if init:
            sv = case.solver
            init_taichi(sv.arch, sv.precision, sv.optimize, sv.fast_math, sv.threads)
        self.case = case
        self.before_step = before_step
        self.dt, self.dt_limits = resolve_dt(case)
        direct_backend(case)  # refuses a direct solver that cannot run here, before compiling
        self.heat_every = resolve_heat_every(case, self.dt, self.dt_limits)
        self.curvature_every = resolve_curvature_every(case, self.dt, self.dt_limits)
        self.scene: Scene = build_scene(case) if scene is None else scene
        self.blocks: BlockPlan | None = None
        if choose_layout(case, self.scene.n_points) == Layout.BLOCKS:
            h, off = self.scene.h, self.scene.off
            self.blocks = BlockPlan(self.scene.nx, self.scene.ny, h, off)
            self.scene = self.scene.reordered(self.blocks.order(self.scene.x))
            self.blocks.set_ranges(self.scene.x)
        # the implicit step's heat substeps (0: no heat, or the explicit step)
        implicit = case.implicit_mechanics()
        self.heat_substeps = resolve_heat_substeps(case, self.dt) if implicit else 0
        dt_heat = self.dt / max(self.heat_substeps, 1)
        cfg = step_config(
            case,
            self.scene,
            self.heat_every,
            self.curvature_every,
            self.dt,
            time_step_limits(case).get("thermal", math.inf)
            if implicit
            else self.dt_limits.get("thermal", math.inf),
            dt_heat,
        )
        mats = material_arrays(case, self.scene.material_names)
        self.state = State(
            cfg, self.scene, mats, laser_arrays(case), self.blocks, imposed_table(case)
        )
        self.state.scalars.dt[None] = self.dt
        init_box(self.state)
        self.steps = 0
        self.implicit = self.adaptive = self.handover = None
        hybrid = case.time.integrator == "hybrid"
        if cfg.implicit:
            self.state.scalars.dt_heat[None] = dt_heat
            self.implicit = ImplicitStepper(case, self.state, self.heat_substeps, self.dt)
            if case.time.implicit_scheme == "extrapolated":
                self.implicit = ExtrapolatedStepper(self.implicit)
            if case.step_adapts():  # hybrid: from implicit_step_factor x its dt
                dt0 = self.dt * (case.time.implicit_step_factor if hybrid else 1.0)
                longest = heat_step_max(case)
                floor = self.dt if hybrid else None
                self.adaptive = AdaptiveStepper(
                    case, self.state, self.implicit, dt0, longest, floor
                )
        if hybrid:
            view = explicit_view(case, self.state, self.scene, self.dt)
            self.handover = Handover(case, view, self.adaptive, self.dt, self.kinetic_ratio)
        # the one stepper that advance_to drives (solver/stepper.py)
        self.stepper: Stepper = (
            HybridStepper(self.handover)
            if hybrid
            else self.adaptive or self.implicit or ExplicitStepper(self.state, self.dt)
        )
        self.stepper.compile()
        # every kernel compiled in the constructor (the field layout's included); later ones
        # (settle, hand-over) count in run_case's summary through the same clock
        self.compile_s = compile_clock.since(clock0)["compile_s"]
        # the contacts, found once on the seeded points, and their neck measures
        sc = self.scene
        self.contacts = touching(sc.x, sc.body, sc.h / case.grid.points_per_cell)
        self.necks = Necks(case, self.state, self.contacts)
        # each point's index in the order the run started with: the blocks layout sorts the
        # points again as they flow, and a checkpoint keeps that order
        self.point_order = np.arange(self.scene.n_points)
        # the energy balance holds to round-off: ~1e-12 in f64, ~1e-6 in f32
        self.guard = Guard(
            self.state,
            self.dt,
            self.dt_limits,
            T_floor_K=temperature_floor_K(case, cfg.dim, float(self.scene.T0_C.min())),
            energy_tol=1e-6 if case.solver.precision == "f64" else 1e-3,
        )
        self._H0: float | None = None  # enthalpy at step 0, for the energy-balance check
        self._e_static: float | None = None  # the step-independent part of energy_bound

    def point_arrays(self, keys: tuple[str, ...] = HOST_POINT_MEMBERS) -> dict[str, np.ndarray]:
        """The points' members the host reads (default HOST_POINT_MEMBERS), by one kernel."""
        return point_arrays(self.state, keys)

    @property
    def t(self) -> float:
        return float(self.state.scalars.t[None])

    @property
    def explicit_state(self) -> State:
        """The state as the explicit step sees it (hybrid: its own view of the fields)."""
        return self.state if self.handover is None else self.handover.view

    @property
    def explicit_now(self) -> bool:
        """Whether the next step is explicit."""
        return self.implicit is None or (self.handover is not None and self.handover.explicit)

    @property
    def step_dt(self) -> float:
        """The last step taken (s): ``dt`` but with ``time.adaptive`` or after a hand-over."""
        return self.stepper.last_dt

    def advance_to(self, t: float, stop: Callable[[], bool] | None = None) -> None:
        """Advance until the clock reaches t (s): adaptive steps that land on it, or the whole
        fixed steps nearest to it (hybrid, explicit after a hand-back: those that reach it).
        The one stepping verb: the case's stepper (solver/stepper.py) takes the steps.
        ``stop``: asked after each adaptive step (StepHooks.stop); True ends short of t."""
        before = None if self.before_step is None else lambda: self.before_step(self)
        after = None if self.blocks is None else self._after_step
        self.steps += self.stepper.advance_to(t, StepHooks(before, after, stop))

    def restart_clock(self) -> None:
        """t = 0 at the state reached (contact.settle): the step count, the points' start
        positions and the integrator's phase begin again here (the heat clock keeps its phase:
        an explicit heat step's strain increment may be under way)."""
        self.state.scalars.t[None] = 0.0
        self.steps = 0
        struct_copy.from_numpy(self.state.points, {"x0": self.point_arrays(("x",))["x"]})
        if self.adaptive is not None:
            self.adaptive.dt = self.adaptive.first_dt
        if self.handover is not None:
            self.handover.start_again(0.0)

    def kinetic_ratio(self, kinetic_energy: float | None = None) -> float:
        """The kinetic energy (times the inertia scale; default: the points' now) over the
        surface energy."""
        if kinetic_energy is None:
            kinetic_energy = point_monitors(self.state)[0]["kinetic_energy_J_per_m"]
        return self.case.solver.mass_scale * kinetic_energy / self.surface_energy()

    def _after_step(self) -> None:
        if self.blocks.needs_sort[None]:  # a point drifted out of its block: sort them again
            self.sort_points()

    def sort_points(self) -> None:
        """Blocks layout: the points sorted by block again (every per-point array and the
        scene's), and the blocks' ranges."""
        x = self.point_arrays()["x"]
        order = self.blocks.order(x)
        self._permute(order)
        self.blocks.set_ranges(x[order])

    def _permute(self, order: np.ndarray) -> None:
        """Every per-point array, the scene's and the host copies, in the order ``order``."""
        pt = self.state.points
        struct_copy.from_numpy(pt, {k: v[order] for k, v in struct_copy.to_numpy(pt).items()})
        self.scene = self.scene.reordered(order)
        self.state.scene = self.scene
        self.necks.reorder(order)
        self.point_order = self.point_order[order]

    # ------------------------------------------------------------------ monitors

    def monitors(self, guard: bool = True) -> dict[str, float]:
        """Monitored quantities (SI, temperatures in C, lengths in um); runs the guard unless
        ``guard`` is false (the last state of a failed run)."""
        st = self.state
        out = {"t_s": self.t, "step": float(self.steps), "dt_s": self.step_dt}
        public, internal = point_monitors(st)
        out.update(public)
        out["T_peak_C"] = float(st.scalars.T_peak[None] - KELVIN)
        out["laser_energy_J_per_m"] = float(st.scalars.laser_energy[None])
        out["heat_out_J_per_m"] = float(st.scalars.heat_out[None])
        # inertia against the surface energy: small when the flow is quasi-static (the rule of
        # solver.mass_scale and of the settled state of time.stop = "solidified")
        out["kinetic_ratio"] = self.kinetic_ratio(out["kinetic_energy_J_per_m"])
        cl, span = self.necks.contact_line_m()
        out["contact_line_um"] = cl * 1e6
        out["neck_span_um"] = span * 1e6
        if self.necks.neck_measure() == "colour":  # the paper's measure (Fig. 4) beside it
            out["contact_line_level_set_um"] = self.necks.contact_line_m("level_set")[0] * 1e6
        if self.steps == 0 and self._H0 is None:
            self._H0 = out["enthalpy_J_per_m"]
        if guard:
            self.guard.dt = self.step_dt
            self.guard.check(
                out, internal, self.steps, self.t, self.energy_error(out), self.energy_bound()
            )
        return out

    def energy_error(self, mon: dict[str, float]) -> float:
        """(laser - heat out - enthalpy rise) / (initial enthalpy + laser): 0 up to round-off."""
        if self._H0 is None:
            return 0.0
        rise = mon["enthalpy_J_per_m"] - self._H0
        net = mon["laser_energy_J_per_m"] - mon["heat_out_J_per_m"]
        return (net - rise) / (abs(self._H0) + mon["laser_energy_J_per_m"])

    def surface_energy(self) -> float:
        """gamma times the bodies' outline as seeded (J/m; 3D: surface, J): kinetic ratio scale."""
        gamma = max(m.surface_tension_N_m for m in self.case.materials.values())
        return max(gamma * self.case.outline_um() * 1e-6 ** (self.state.cfg.dim - 1), 1e-30)

    def energy_bound(self) -> float:
        """Every energy a run can turn into motion: initial kinetic energy, surface energy of the
        bodies' outlines, potential energy across the domain, laser energy so far (J/m)."""
        if self._e_static is None:
            c = self.case
            gamma = max(m.surface_tension_N_m for m in c.materials.values())
            g, M = math.hypot(*c.physics.gravity_m_s2), float(self.necks.mass.sum())
            v0 = self.point_arrays()["v"]
            ke0 = 0.5 * float((self.necks.mass * (v0**2).sum(axis=1)).sum())
            surface = gamma * c.outline_um() * 1e-6 ** (c.domain.dim - 1)
            self._e_static = ke0 + surface + M * g * self.scene.height
        return self._e_static + float(self.state.scalars.laser_energy[None])

    # ------------------------------------------------------------------ state
    def save_checkpoint(self, path: Path, extra: dict | None = None) -> None:
        """The full state, written atomically; ``extra`` (numbers) alongside, e.g. the frame,
        and the integrator's own state (the adaptive step's next size; the hybrid's phase)."""
        extra = {**(extra or {}), **self._integrator_state()}
        checkpoint.save(self.state, path, self.steps, self.case.case.name, extra, self.point_order)

    def _integrator_state(self) -> dict[str, float]:
        out = {}
        if self.adaptive is not None:
            out["adaptive_dt"] = self.adaptive.dt
        if self.handover is not None:
            h = self.handover
            out.update(
                hybrid_explicit=float(h.explicit), hybrid_at_s=h.at_s, hybrid_handbacks=h.handbacks
            )
        return out

    def load_checkpoint(self, path: Path) -> dict:
        """Restore a state saved by :meth:`save_checkpoint`; returns its ``extra``. A run whose
        points were sorted again comes back in its sorted order: the arrays a checkpoint does
        not hold (mass, volume, material, the scene's) are put in that order first."""
        saved = checkpoint.point_order(path, self.scene.n_points)
        if saved is not None and not np.array_equal(saved, self.point_order):
            self._permute(np.argsort(self.point_order)[saved])
        self.steps, extra = checkpoint.load(self.state, path, self.case.case.name)
        init_box(self.state)
        if self.adaptive is not None and "adaptive_dt" in extra:
            self.adaptive.dt = float(extra.pop("adaptive_dt"))
        if self.handover is None:
            if self.adaptive is None:
                self.dt = self.stepper.dt = float(self.state.scalars.dt[None])
            # else dt stays the run's first step: the frame times are its multiples (the
            # checkpoint's dt is the last adaptive step; taken as dt it moved every later frame)
            return extra
        h = self.handover  # the hybrid's dt stays its explicit step
        if "hybrid_explicit" in extra:
            h.explicit = bool(extra.pop("hybrid_explicit"))
            h.at_s = float(extra.pop("hybrid_at_s"))
            h.handbacks = int(extra.pop("hybrid_handbacks"))
        if h.explicit:  # a stretch of explicit steps: its check starts again from here
            self.state.scalars.dt[None] = self.dt
            h.restart_stretch(self.t)
        return extra

    def snapshot(self, full: bool = False) -> dict[str, np.ndarray]:
        """The points for output: position (um), T_C, displacement magnitude (um), equivalent
        plastic strain, liquid fraction; ``full`` adds what the VTU holds besides (read only
        then: the stress alone is 9 numbers a point): body_id, velocity_m_s (N, 2),
        displacement_vector_um (N, 2), stress_Pa (N, 3, 3; the material's Cauchy stress, not
        the melt's solvent stress, which is a force term only) and J."""
        # the checkpoint's members: one copy kernel for both (each compiles once per process)
        pt = struct_copy.to_numpy(self.state.points, checkpoint.POINT_MEMBERS)
        x = pt["x"]
        u = x - pt["x0"]
        snap = {
            "x_um": x * 1e6,
            "T_C": pt["T"] - KELVIN,
            "displacement_um": np.linalg.norm(u, axis=1) * 1e6,
            "plastic_strain": pt["equivalent_plastic_strain"],
            "liquid_fraction": 1.0 - pt["solid_fraction"],
        }
        if full:  # the scene's body index follows the points when the blocks layout sorts them
            snap["body_id"] = np.asarray(self.scene.body, dtype=np.int32)
            snap["velocity_m_s"] = pt["v"]
            snap["displacement_vector_um"] = u * 1e6
            snap["stress_Pa"] = pt["stress"]
            snap["J"] = pt["J"]
        return snap
