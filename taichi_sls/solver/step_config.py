"""The compile-time configuration of a step: grid geometry, physics switches, named codes and
derived constants. Kernels read it through ``ti.static``, so a case compiles only the physics it
uses; everything that may change during a run (time step, clocks, laser settings) lives in
fields instead."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from enum import IntEnum

from ..config import Case
from ..physics.codes import (
    Strain,
    StressForm,
    StressReading,
    SurfaceMethod,
    Transfer,
    Update,
    WallMechanical,
)
from ..physics.materials import KELVIN
from ..physics.stiffness import WIDTH as ROW_WIDTH
from .params import imposed_table
from .scene import Scene


class Layout(IntEnum):
    """How a step runs (``solver.layout``, solver/step.py)."""

    SERIAL = 0  # many steps per kernel call, every loop serial (one CPU core)
    PARALLEL = 1  # one call per step, every loop parallel with atomic scatters (GPU)
    BLOCKS = 2  # one call per step, points by blocks in four colours (every CPU core)


# the blocks layout pays for itself above about this many points (docs/record/speed.md)
BLOCKS_FROM_POINTS = 20_000
T_RUNAWAY_K = 1e4  # no polymer state of this model lives above it (the guard's bound too)


@dataclass(frozen=True)
class SurfaceEnergyConfig:
    """The switches of the surface-energy force (physics/surface_energy.py)."""

    weight_lp: float  # half-width of the Gauss points' weight (0: the bilinear hat)
    gauss_points: int
    floor_mass: float  # kg per depth
    spread: bool  # hand a light node's rest to its neighbours (else clip)
    filter: bool


@dataclass(frozen=True)
class StepConfig:
    # ---- grid (array indices: node (off, off[, off]) sits at x = y [= z] = 0)
    dim: int
    n_points: int
    nx: int
    ny: int
    nz: int  # 1 in 2D
    off: int
    ncx: int  # cells across the domain
    ncy: int
    ncz: int  # 0 in 2D
    h: float
    inv_h: float
    lp: float  # uGIMP half-width of a point (h/4 for 2x2 per cell)
    cell_volume: float
    # ---- physics switches
    mech: bool
    thermal: bool
    surface: bool
    plastic: bool
    th_strain: bool
    laser: bool
    n_lasers: int
    local_surface: bool  # some beam reads its depth below the local surface (beam_surface.py)
    gravity: tuple[float, ...]  # dim components
    has_gravity: bool
    stress_reading: StressReading
    stress_form: StressForm
    strain: Strain  # small (stress_form, stress_reading) or finite (physics/constitutive.py)
    solvent: bool  # some material has a Kelvin-Voigt solvent viscosity (force term)
    # ---- transfers and layout
    transfer: Transfer
    flip_ratio: float
    update: Update
    cell_dilatation: bool  # solver.dilatation = "cell": the Q1P0 volume of physics/mechanics.py
    dilatation_floor: float  # kg per depth: the light nodes' floor of its pressure force
    implicit: bool  # time.integrator = "implicit" (solver/implicit.py)
    layout: Layout
    parallel: bool  # one kernel call per step, its loops parallel (not the serial layout)
    race_free: bool  # the layout keeps scattering threads apart: plain adds (blocks)
    active_region: bool
    box_margin: int  # nodes beyond the points' footprint that the step still changes
    # ---- clocks
    heat_every: int
    geom_every: int
    # ---- walls (left, right, bottom, top[, front, back])
    wall_mechanical: tuple[WallMechanical, ...]
    wall_fixed: tuple[bool, ...]
    wall_T: tuple[float, ...]  # K
    any_fixed: bool
    subgrid_filter: float  # chi of the sub-grid temperature filter (physics/thermal.py)
    subgrid_rate: float  # its rate (1/s): chi = 1 - exp(-rate dt_heat) for a varying heat step
    heat_implicit: bool  # time.heat_integrator = "implicit" (solver/implicit_heat.py)
    sparse_rows: bool  # time.implicit_rows: the 3D rows by blocks (solver/fields.py row_field)
    matrix_free: bool  # time.linear_solver = "matrix_free": no tangent rows (solver/multigrid.py)
    top_loss: bool  # thermal.top_surface = "chamber" (physics/thermal.py)
    chamber_T: float  # K
    emissivity: float
    convection: float  # W/(m^2 K)
    hysteresis: bool  # some material crystallises below its melting range (physics/thermal.py)
    kinetics: bool  # some material crystallises by kinetics (hysteresis too; physics/thermal.py)
    imposed: int  # rows of thermal.imposed_temperature_csv, the held T(t); 0: none (State.imposed)
    # ---- mass and surface tension
    surface_method: SurfaceMethod
    se: SurfaceEnergyConfig
    mass_scale: float  # inertia scale s (physics/mechanics.py)
    rho_ref: float  # s times the first body's density: the grid mass of a full cell / V_c
    mass_cut: float
    gamma: float
    gamma_ramp_s: float  # gamma rises linearly over this time (0: at once)
    r_p: float
    band: int
    phi_cap: float
    blur_passes: int
    smooth_passes: int
    kappa_cap: float
    csf_c0: float
    zero_net_force: bool
    # ---- the guard's watch (solver/step.py): a temperature beyond this has run away
    T_runaway: float

    @property
    def shape(self) -> tuple[int, ...]:
        """The node arrays' shape: (nx, ny) or (nx, ny, nz)."""
        return (self.nx, self.ny, self.nz)[: self.dim]

    @property
    def wall_index(self) -> tuple[int, ...]:
        """The array index of the upper wall's node line per axis (the lower one is ``off``)."""
        return tuple(self.off + n for n in (self.ncx, self.ncy, self.ncz)[: self.dim])


def threads(case: Case) -> int:
    """The CPU threads the run may use (``solver.threads``, 0: every core)."""
    return case.solver.threads or os.cpu_count() or 1


def choose_layout(case: Case, n_points: int) -> Layout:
    """``solver.layout``; "auto": parallel on a GPU; on a CPU the blocks layout for large 2D
    scenes when there is more than one thread, else the serial one (3D on a CPU: serial, as the
    parallel layout's atomic scatters cost more CPU time than the serial loops and more wall
    time too; docs/record/speed.md, ``taichi-sls bench speed3d``)."""
    lay = case.solver.layout
    if lay != "auto":
        return Layout[lay.upper()]
    if case.solver.arch == "gpu":
        return Layout.PARALLEL
    if n_points >= BLOCKS_FROM_POINTS and threads(case) > 1 and case.domain.dim == 2:
        # the blocks' 4-colour scatter is 2D (config/dim.py refuses it by name in 3D)
        return Layout.BLOCKS
    return Layout.SERIAL


def flip_share(case: Case, dt: float) -> float:
    """The FLIP share of one step of the pic_flip blend (``solver.blend_per``): with "time",
    flip_ratio^(dt / flip_ratio_dt_s), the same PIC damping per unit time at any step."""
    sv = case.solver
    if sv.blend_per == "step" or dt <= 0.0 or dt == sv.flip_ratio_dt_s:
        return sv.flip_ratio
    return sv.flip_ratio ** (dt / sv.flip_ratio_dt_s)


DENSE_ROWS_MAX_BYTES = 2**30  # time.implicit_rows = "auto": blocks above this


def sparse_rows(case: Case, grid: tuple[int, ...]) -> bool:
    """Whether the 3D implicit rows are stored by blocks (``time.implicit_rows``): asked for,
    or "auto" where the dense rows (WIDTH^3 neighbours, 1 + 9 values each, f64) pass
    DENSE_ROWS_MAX_BYTES, and always with the matrix-free step: it keeps the fixed part's rows
    alone, which dense over the box outweigh the rest of its memory (2.6 against 1.1 kB a point
    at 10k points, for a step 4 % slower; docs/record/implicit.md)."""
    rows = case.time.implicit_rows
    if case.domain.dim != 3 or not case.implicit_mechanics() or rows == "dense":
        return False
    dense_bytes = math.prod(grid) * ROW_WIDTH**3 * 8 * (1 + 9)
    matrix_free = case.time.linear_solver == "matrix_free"
    return rows == "blocks" or matrix_free or dense_bytes > DENSE_ROWS_MAX_BYTES


def step_config(
    case: Case,
    scene: Scene,
    heat_every: int,
    curvature_every: int,
    dt: float = 0.0,
    thermal_limit: float = math.inf,
    heat_dt: float = 0.0,
) -> StepConfig:
    """The configuration of ``case`` on ``scene`` with the resolved time step and clocks
    (``heat_dt``: the implicit step's heat substep)."""
    ph, st, sv = case.physics, case.surface_tension, case.solver
    dim = case.domain.dim
    walls = case.boundary.walls(dim)
    h = scene.h
    first = case.materials[case.bodies[0].material]
    surface = ph.surface_tension and ph.mechanics
    method = SurfaceMethod[st.method.upper()]
    csf = surface and method == SurfaceMethod.CSF
    thermal = ph.thermal
    rho_ref = first.density_kg_m3 * sv.mass_scale
    layout = choose_layout(case, scene.n_points)
    floor = st.surface_energy_mass_floor * rho_ref * h**dim
    implicit = case.implicit_mechanics()
    # the sub-grid filter's time unit: the 2D thermal limit h^2 rho c / 4k in either dimension.
    # The 3D limit h^2 rho c / 6k is 2/3 of it: per that limit, rate 1 relaxed 1.5 times as fast
    # as in 2D and lifted a sphere cooling from 200 C to 200.15 C (cases/sphere3d_heat.toml;
    # 2D does the same at rate 1.5). dim / 2 = 1.0 exactly in 2D: its bits are kept.
    filter_limit = thermal_limit * (dim / 2)
    return StepConfig(
        dim=dim,
        n_points=scene.n_points,
        nx=scene.nx,
        ny=scene.ny,
        nz=scene.nz,
        off=scene.off,
        ncx=int(round(scene.width / h)),
        ncy=int(round(scene.height / h)),
        ncz=int(round(scene.depth / h)),
        h=h,
        inv_h=1.0 / h,
        lp=h / (2 * case.grid.points_per_cell),
        cell_volume=h**dim,
        mech=ph.mechanics,
        thermal=thermal,
        surface=surface,
        plastic=ph.plasticity,
        th_strain=ph.thermal_strain and thermal,
        laser=thermal and any(las.power_W > 0 for las in case.lasers),
        n_lasers=len(case.lasers),
        local_surface=thermal
        and any(las.power_W > 0 and las.surface == "local" for las in case.lasers),
        gravity=tuple(ph.gravity_m_s2) + (0.0,) * (dim - len(ph.gravity_m_s2)),
        has_gravity=any(g != 0.0 for g in ph.gravity_m_s2),
        stress_reading=StressReading.PAPER if sv.stress_reading == "paper" else StressReading.MODEL,
        stress_form=StressForm[sv.stress_form.upper()],
        strain=Strain[sv.strain.upper()],
        solvent=ph.mechanics
        and any(m.solvent_viscosity_Pa_s > 0.0 for m in case.materials.values()),
        transfer=Transfer[sv.transfer.upper()],
        flip_ratio=flip_share(case, dt),
        update=Update[sv.update.upper()],
        cell_dilatation=sv.dilatation == "cell",
        dilatation_floor=sv.dilatation_mass_floor * rho_ref * h**dim,
        implicit=implicit,
        layout=layout,
        parallel=layout != Layout.SERIAL,
        race_free=layout == Layout.BLOCKS,
        active_region=sv.active_region,
        # CSF: the level-set band and the blur's reach, plus one for the 3x3 fits; surface
        # energy: the Gauss points of the cells next to the points' nodes
        box_margin=(st.band_cells + st.level_set_smoothing_passes + 2 if csf else 1)
        if surface
        else 0,
        heat_every=heat_every if thermal else 1,
        geom_every=curvature_every if csf else 1,
        wall_mechanical=tuple(WallMechanical[w.mechanical.upper()] for w in walls),
        wall_fixed=tuple(w.thermal == "fixed" for w in walls),
        wall_T=tuple(w.temperature_C + KELVIN for w in walls),
        any_fixed=thermal and any(w.thermal == "fixed" for w in walls),
        # the filter's fraction per heat step, from its rate per (2D) thermal limit
        subgrid_filter=(
            -math.expm1(-case.thermal.subgrid_filter * heat_dt / filter_limit)
            if implicit
            else -math.expm1(-case.thermal.subgrid_filter * dt * heat_every / filter_limit)
        )
        if thermal
        else 0.0,
        subgrid_rate=case.thermal.subgrid_filter / filter_limit if thermal else 0.0,
        heat_implicit=case.implicit_heat(),
        sparse_rows=sparse_rows(case, (scene.nx, scene.ny, scene.nz)[: case.domain.dim]),
        matrix_free=implicit and case.time.linear_solver == "matrix_free",
        top_loss=thermal and case.thermal.top_surface == "chamber",
        chamber_T=case.thermal.chamber_temperature_C() + KELVIN,
        emissivity=case.thermal.emissivity,
        convection=case.thermal.convection_W_m2K,
        hysteresis=thermal
        and any(
            m.crystallization_range_C is not None or m.crystallization_kinetics is not None
            for m in case.materials.values()
        ),
        kinetics=thermal
        and any(m.crystallization_kinetics is not None for m in case.materials.values()),
        imposed=len(imposed_table(case)[0]) if thermal else 0,
        surface_method=method,
        se=SurfaceEnergyConfig(
            weight_lp=h / (2 * case.grid.points_per_cell)
            if st.surface_energy_weight == "gimp"
            else 0.0,
            gauss_points=st.surface_energy_gauss_points,
            floor_mass=floor,
            spread=st.surface_energy_floor_mode == "spread" and floor > 0.0,
            filter=st.surface_energy_colour_filter,
        ),
        gamma_ramp_s=st.ramp_s,
        mass_scale=sv.mass_scale,
        rho_ref=rho_ref,
        mass_cut=(case.time.implicit_small_mass if implicit else sv.small_mass)
        * first.density_kg_m3
        * sv.mass_scale
        * h**dim,
        gamma=first.surface_tension_N_m,
        r_p=st.point_radius_over_h * h,
        band=st.band_cells,
        phi_cap=(st.band_cells + 1) * h,
        blur_passes=st.level_set_smoothing_passes,
        smooth_passes=st.smoothing_passes,
        kappa_cap=st.curvature_cap_h / h if st.curvature_cap_h > 0 else 0.0,
        csf_c0=st.colour_threshold,
        zero_net_force=st.zero_net_force,
        T_runaway=T_RUNAWAY_K,
    )
