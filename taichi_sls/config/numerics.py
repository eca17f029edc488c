"""The ``[time]`` and ``[solver]`` tables: time step, clocks and stop rule; transfers, layouts,
precision and the constitutive integration."""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import BeforeValidator, Field

from .model import Model


def _auto_or_positive(v: Any) -> float | str:
    if v == "auto" and isinstance(v, str):
        return v
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ValueError('expected a positive number or "auto"')
    if not v > 0:
        raise ValueError("must be > 0")
    return float(v)


def _auto_or_count(v: Any) -> int | str:
    if v == "auto" and isinstance(v, str):
        return v
    if isinstance(v, bool) or not isinstance(v, int) or v < 1:
        raise ValueError('expected an integer >= 1 or "auto"')
    return v


# validated before the union sees them, so that the message says what is allowed
AutoPositive = Annotated[float | str, BeforeValidator(_auto_or_positive)]
AutoCount = Annotated[int | str, BeforeValidator(_auto_or_count)]


class Time(Model):
    dt_s: AutoPositive = Field(
        "auto", description='time step (s), or "auto" from the stability limits'
    )
    end_s: float = Field(1e-3, gt=0, description='simulated end time (s) of stop = "end"')
    stop: Literal["end", "solidified"] = Field(
        "end",
        description="end: run to end_s; solidified: once every laser is off, run until every "
        "point is solid (T <= T_c; with crystallization_range_C or crystallization_kinetics, "
        "crystallised) and the kinetic "
        "energy has fallen below settled_kinetic_fraction of the surface energy, or to max_s "
        "(then marked max_time)",
    )
    max_s: float = Field(
        0.5, gt=0, description='simulated time at which a stop = "solidified" run gives up (s)'
    )
    settled_kinetic_fraction: float = Field(
        1e-4,
        gt=0,
        description="settled: kinetic energy (with the inertia scale) below this fraction of "
        "gamma times the bodies' perimeter",
    )
    settled_neck_change: float = Field(
        1e-3,
        gt=0,
        description="settled, for a case no laser heats (solid from the start, so only its "
        "motion can end the run): the kinetic energy has stayed below "
        "settled_kinetic_fraction, and the first contact's neck within this fraction of its "
        "last value, over the three frames before the last (jobs/schedule.py)",
    )
    safety: float = Field(0.4, gt=0, description='fraction of the stability limit for "auto"')
    allow_unstable_dt: bool = Field(False, description="let a fixed dt exceed the stability limit")
    heat_every: AutoCount = Field(
        "auto",
        description="conduction and laser every N mechanical steps, with a heat step of N dt "
        '(the thermal limit is ~100x the elastic one); "auto": the largest N with N dt <= '
        "heat_step_fraction x the thermal limit; 1: every step",
    )
    heat_step_fraction: float = Field(
        0.1,
        gt=0,
        le=1.0,
        description="heat step as a fraction of the thermal stability limit for heat_every = "
        '"auto"',
    )
    integrator: Literal["explicit", "implicit", "hybrid"] = Field(
        "explicit",
        description="explicit: the paper's step (eqs. 10-18), bounded by the elastic, capillary "
        "and viscous limits; implicit: backward Euler for the grid velocities (Newton on the "
        "momentum balance with the Perzyna update's secant tangent, the capillary force "
        "semi-implicit), bounded by the heat step only (docs/record/implicit.md); hybrid: explicit "
        "steps of dt_s through the laser pulse and the melting collapse, then adaptive implicit "
        "ones once every laser is off and the kinetic energy is below "
        "handover_kinetic_fraction of the surface energy (solver/handover.py)",
    )
    implicit_scheme: Literal["backward_euler", "extrapolated"] = Field(
        "backward_euler",
        description="implicit: backward_euler (first order, one Newton solve a step); "
        "extrapolated: each step taken whole and as two halves, the points' mechanics "
        "extrapolated to 2 halves - whole (Richardson: second order and, like backward Euler, "
        "damping stiff modes; three solves a step; solver/extrapolation.py)",
    )
    handover_kinetic_fraction: float = Field(
        1e-5,
        gt=0,
        description="hybrid: the kinetic energy (times solver.mass_scale), as a fraction of gamma "
        "times the bodies' perimeter, below which the implicit step takes over",
    )
    handback_explicit_steps: float = Field(
        20.0,
        ge=1,
        description="hybrid, after the hand-over: when the adaptive step would be shorter than "
        "this many explicit steps (an implicit step there costs a Newton solve for what "
        "explicit steps do far cheaper: contacts snapping shut in a bed), explicit steps take "
        "over again until a stretch of them shows that a step this long meets the controls "
        "(solver/handover.py)",
    )
    implicit_step_factor: float = Field(
        50.0,
        gt=0,
        description='implicit, dt_s = "auto": this many times the explicit "auto" step (100 moves '
        "the paper's collapsing point contact over half a cell in the first step, which the "
        "guard refuses); the heat takes substeps",
    )
    newton_tolerance: float = Field(
        1e-6,
        gt=0,
        lt=1,
        description="implicit: Newton stops when the momentum residual is below this fraction "
        "of the step's force scale (the norms of inertia, internal, capillary and body forces)",
    )
    newton_max_iterations: int = Field(
        40, ge=1, description="implicit: Newton iterations per step before the step is refused"
    )
    implicit_small_mass: float = Field(
        1e-3,
        ge=0,
        lt=1,
        description="implicit: nodes below this fraction of a full cell's mass rest (the "
        "explicit step's cut is solver.small_mass): a node that only the edges of the points' "
        "supports reach has a velocity its equations barely fix, and points nearer to it "
        "inverted or blew up (docs/record/implicit.md)",
    )
    implicit_velocity_penalty: float = Field(
        0.0,
        ge=0,
        lt=1,
        description="implicit: 0, or a penalty on the grid velocity's second differences "
        "(zero on linear velocity fields) of this fraction of the step's largest matrix "
        "diagonal: it stiffens the near-null modes of light nodes, which only their inertia "
        "fixes, against runaway velocities (docs/record/implicit.md); 1e-6 steadies hopper_pa12 at "
        "R0/h = 20 and time.newton_tolerance = 1e-8",
    )
    linear_solver: Literal["auto", "direct", "amg", "matrix_free"] = Field(
        "auto",
        description="implicit: direct (a sparse Cholesky by direct_solver's library; qdldl's "
        "LDL^T where a matrix is not positive definite), amg (conjugate gradients "
        "preconditioned by pyamg's smoothed aggregation), matrix_free (conjugate gradients "
        "on the points' tangent applied through the points, no assembled tangent, "
        "preconditioned by a geometric multigrid on the MPM grid: solver/multigrid.py) or "
        "auto (direct up to direct_max_unknowns grid velocity components, amg above)",
    )
    refactorize: Literal["each_tangent", "when_slow"] = Field(
        "each_tangent",
        description='implicit, linear_solver = "direct": each_tangent (every tangent Newton '
        "takes is factorized afresh and solved with directly, the reference) or when_slow "
        "(the factorization kept from an earlier tangent, of this or an earlier step, "
        "preconditions conjugate gradients on the new one, over the unknowns the two share; "
        "a new factorization only where CG would need more than 20 iterations: "
        "docs/record/implicit.md)",
    )
    direct_ordering: Literal["auto", "amd", "nested_dissection"] = Field(
        "auto",
        description="implicit, the direct solver's elimination order: amd (CHOLMOD's own; "
        "PARDISO's minimum degree), nested_dissection (METIS's: for CHOLMOD through pymetis on "
        "the graph of the grid nodes, solver/ordering.py; PARDISO's own: less fill on 3D "
        "rows) or auto (nested_dissection in 3D, amd in 2D)",
    )
    direct_solver: Literal["auto", "cholmod", "pardiso"] = Field(
        "auto",
        description='implicit, linear_solver = "direct": the Cholesky factorization\'s library: '
        "cholmod (CHOLMOD through cvxopt, on a serial BLAS), pardiso (MKL PARDISO on MKL's "
        "threaded BLAS; needs the mkl package, x86_64: a 3D bed's Newton matrix factorized "
        "5x faster on 2 cores, docs/record/implicit.md) or auto (pardiso in 3D where MKL is "
        "installed, else cholmod)",
    )
    direct_pattern: Literal["auto", "step", "envelope"] = Field(
        "auto",
        description='implicit, linear_solver = "direct", the mechanics: step (each step '
        "factorizes over its own unknowns: a new analysis whenever a node crosses the mass "
        "cut) or envelope (over an envelope of nodes kept across steps, those of a tenth of "
        "the cut and above, the others' rows the identity: the same solution, an analysis only "
        "when the step's unknowns leave it; solver/envelope.py) or auto (envelope in 3D, step "
        "in 2D)",
    )
    direct_max_unknowns: int | None = Field(
        None,
        ge=1,
        description='implicit, linear_solver = "auto": the largest direct solve, in unknowns; '
        "unset: 200000 in 2D, 40000 in 3D (a 3D row holds up to 375 entries, not 75: the "
        "Cholesky factor fills faster, and AMG-CG catches up with it at fewer unknowns; "
        "docs/record/implicit.md)",
    )
    implicit_rows: Literal["auto", "dense", "blocks"] = Field(
        "auto",
        description="implicit, 3D: how the step stores each grid node's matrix rows (10 kB a "
        "node): dense over the grid (the fastest to assemble), or by blocks of 4 x 4 x 4 nodes "
        "allocated where the step writes (the nodes near material: less memory where material "
        "fills little of the box, somewhat slower to assemble; docs/record/implicit.md); auto: "
        "blocks where the dense rows would pass 1 GiB, and with linear_solver = matrix_free "
        "(whose rows are the fixed part's alone). 2D: always dense",
    )
    heat_integrator: Literal["auto", "explicit", "implicit"] = Field(
        "auto",
        description="implicit integrator: the heat in explicit substeps of at most "
        "heat_step_fraction of its stability limit (explicit), or in one backward-Euler step "
        "per step (implicit: conduction at the new temperature, the capacity and conductivity "
        "of the step's start; unconditionally stable, first order; solver/implicit_heat.py); "
        "auto: implicit where the step adapts (adaptive, hybrid), else explicit",
    )
    adaptive: bool = Field(
        False,
        description="implicit: choose each step from the physics (solver/adaptive.py): grow it "
        "while the temperature and the strain change slowly, shrink it through a laser pulse "
        "and the melting and freezing fronts, redo a step that overshoots its controls twice "
        "over or whose Newton fails; dt_s is the first step; the time series logs dt_s",
    )
    dt_min_s: AutoPositive = Field(
        "auto",
        description='adaptive: the smallest step (s); "auto": the first step / 1000, and for '
        "the hybrid its explicit step (below it an explicit step is cheaper, and a jump no "
        "step resolves, such as two melt surfaces snapping into contact, would hold the "
        "implicit step far below it). A step at it is taken whatever its changes; one whose "
        "Newton fails there ends the run with an error",
    )
    dt_max_s: AutoPositive = Field(
        "auto",
        description='adaptive: the largest step (s); "auto": none (the controls, the frames '
        "and the laser switch times bound it)",
    )
    max_temperature_change_K: float = Field(
        5.0,
        gt=0,
        description="adaptive: the largest temperature change of any point in one step (K)",
    )
    max_motion_cells: float = Field(
        0.25,
        gt=0,
        lt=0.5,
        description="adaptive: the farthest any point may move in one step, in cells (the "
        "guard refuses half a cell)",
    )
    max_strain_increment: float = Field(
        0.02,
        gt=0,
        description="adaptive: the largest strain increment of any point in one step (the "
        "measure: strain_control)",
    )
    strain_control: Literal["total", "plastic", "error"] = Field(
        "total",
        description="adaptive: total: the Frobenius norm of f - I, f = F^{n+1} (F^n)^-1 the "
        "step's deformation gradient; plastic: the equivalent plastic (viscous) strain "
        "increment, the only part of the strain whose path a step's size changes: an elastic "
        "jump (two melt surfaces snapping into contact) reaches the same quasi-static state at "
        "any step, and the total measure chased it down to the explicit step "
        "(docs/record/beds.md); error: the plastic strain's local error instead of its "
        "increment (max_strain_error)",
    )
    max_strain_error: float = Field(
        2e-3,
        gt=0,
        description='adaptive, strain_control = "error": the largest local error of a point\'s '
        "equivalent plastic (viscous) strain in one step, estimated as backward Euler's "
        "dt |r^{n+1} - r^n| / 2, r the point's plastic strain rate over a step (the step against "
        "one at the rate the last step took): the steps a viscous flow's accuracy needs, long "
        "where the flow is steady; an elastic jump has no plastic rate (docs/record/implicit.md)",
    )


class Solver(Model):
    transfer: Literal["apic", "flip", "pic_flip"] = Field(
        "pic_flip",
        description="apic; flip as printed (eq. 14); pic_flip: flip_ratio*FLIP + "
        "(1-flip_ratio)*PIC",
    )
    dilatation: Literal["point", "cell"] = Field(
        "point",
        description="the volume change of a point's step: point: each point's own tr(L), the "
        "paper's eq. 18; cell: the divergence at the centre of the point's grid cell of its "
        "corner nodes' velocities, shared by the cell's points, and the mean stress's force "
        "through the same gradient (the Q1P0 element's one volume per cell; the shear stays "
        "the point's own), USL steps, explicit or implicit (no mirror or periodic walls). With "
        "four points per cell each holding its own volume a nearly incompressible flow locks, "
        "more along the grid than across it: a filleted pair's neck grows up to 10 % faster "
        "across the diagonal "
        "(docs/record/verification.md, neck growth at any angle)",
    )
    dilatation_mass_floor: float = Field(
        0.01,
        ge=0,
        le=1,
        description='dilatation = "cell": a node below this fraction of a full cell\'s mass '
        "keeps m_i / floor of the mean stress's force and hands the rest to its neighbours by "
        "mass (momentum kept), as the surface force's floor does: the cell's gradient reaches "
        "corners that a point barely touches. The implicit step floors the gradient itself "
        "(m_i / floor of it, the rest to the cell's corners by mass), so that its tangent "
        "stays symmetric",
    )
    update: Literal["usl", "musl"] = Field(
        "usl",
        description="usl: eqs. 14-17 as printed; musl: move points with the remapped grid "
        "velocity (bounded on nearly empty nodes, but slows capillary flow)",
    )
    flip_ratio: float = Field(
        0.9, ge=0, le=1, description="FLIP share of the pic_flip blend, in [0, 1]"
    )
    blend_per: Literal["time", "step"] = Field(
        "time",
        description="pic_flip: time: flip_ratio holds at a step of flip_ratio_dt_s and any other "
        "step keeps the same PIC damping per unit time (FLIP share flip_ratio^(dt / "
        "flip_ratio_dt_s)), so that its damping does not grow as dt shrinks; step: flip_ratio "
        "at every step whatever dt (the usual blend: its damping per unit time grows as 1/dt, "
        "and the paper case's neck at 1 ms moved 9 % when dt was halved; docs/model.md)",
    )
    flip_ratio_dt_s: float = Field(
        5e-8,
        gt=0,
        description='the step (s) at which flip_ratio holds for blend_per = "time" (the '
        "paper's fine-grid step)",
    )
    arch: Literal["cpu", "gpu"] = Field("cpu", description="Taichi backend")
    layout: Literal["auto", "serial", "parallel", "blocks"] = Field(
        "auto",
        description="serial: many steps per kernel call, loops serialized (one core); "
        "parallel: one call per step, every loop parallel with atomic scatters (GPU); blocks: "
        "one call per step, the points sorted into blocks scattered in four colour passes "
        "without atomics (every CPU core, the same result at any thread count); auto: parallel "
        "on a GPU, blocks on a CPU from 20k points with more than one thread, else serial",
    )
    threads: int = Field(0, ge=0, description="CPU threads Taichi may use (0: every core)")
    active_region: bool = Field(
        True,
        description="grid loops only over the nodes that material has reached (plus the "
        "stencil, level-set band and smoothing margin); false: every node, every step",
    )
    precision: Literal["f64", "f32"] = Field("f64", description="floating point precision")
    mass_scale: float = Field(
        1.0,
        ge=1.0,
        description="inertia scale s >= 1: the momentum equation sees s times the mass (heat "
        "capacity, weight and the thermal field keep the physical one); the elastic and "
        "capillary time-step limits grow by sqrt(s). For slow viscous or quasi-static flow "
        "(Ohnesorge >> 1); the kinetic_ratio monitor says when inertia starts to matter "
        "(docs/record/speed.md)",
    )
    small_mass: float = Field(
        1e-9, ge=0, description="nodes below this fraction of a full cell's mass are skipped"
    )
    stress_reading: Literal["model", "paper"] = Field(
        "model",
        description="model: s = 2 mu dev(eps_e), p = K tr(eps_e) (docs/model.md); paper: eq. 39 "
        'and p = lambda tr(eps) as printed (with stress_form = "total")',
    )
    stress_form: Literal["incremental", "total"] = Field(
        "incremental",
        description="total: the stress from the accumulated elastic strain at the current "
        "moduli (eqs. 38-39: a melt that freezes, E rising tenfold, is pulled back towards its "
        "stress-free start); incremental: the last stress plus the current moduli times the "
        "strain increment (the stress stays continuous through melting and freezing)",
    )
    optimize: bool = Field(
        False,
        description="Taichi's advanced optimisation: faster steps after a much longer one-off "
        "compile (cached on disk; docs/record/compile.md)",
    )
    fast_math: bool = Field(
        True,
        description="let the compiler reorder floating-point arithmetic (Taichi's fast_math); "
        "false: strict IEEE order, bitwise reproducible across changes of code structure",
    )
    strain: Literal["small", "finite"] = Field(
        "small",
        description="small: accumulated eps += sym(L) dt (eqs. 16-17; not objective), with "
        "stress_form and stress_reading; finite: multiplicative split F = Fe Fp, Hencky "
        "(logarithmic) elastic strain and the same Perzyna return map (eqs. 40-45) on the "
        "principal Kirchhoff stress, thermal and solidification strains removed from the "
        "elastic stretch (objective: a rigid rotation rotates the stress; needs stress_reading "
        '= "model"; stress_form does not apply: the stress stays continuous through melting and '
        "freezing as in the incremental form)",
    )
