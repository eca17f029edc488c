"""The tables of a case file other than bodies and materials."""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BeforeValidator, Field

from .model import Model, Pair


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


class CaseInfo(Model):
    name: str = Field("case", description="case name; default output folder is out/<name>")
    description: str = Field("", description="free text")


class Grid(Model):
    spacing_um: float = Field(2.0, gt=0, description="grid spacing h (um)")
    points_per_cell: int = Field(
        2,
        gt=0,
        le=8,
        description="material points per cell along each axis (2 -> 2x2 quarter points)",
    )
    ghost_cells: int = Field(
        1,
        ge=0,
        le=8,
        description="extra cells beyond left/right/bottom walls (surface tension stencil)",
    )


class Domain(Model):
    width_um: float = Field(80.0, gt=0, description="domain width (um); x from 0")
    height_um: float = Field(48.0, gt=0, description="domain height (um); y from 0 (baseplate)")


class Wall(Model):
    mechanical: Literal["slip", "stick", "open"] = Field(
        "slip", description="slip: zero normal velocity"
    )
    thermal: Literal["insulated", "fixed"] = Field("insulated", description="heat flux condition")
    temperature_C: float = Field(140.0, description="wall temperature when thermal = fixed")


class Boundary(Model):
    """Bottom wall default: `thermal = "fixed"` at 140 C; top wall default:
    `mechanical = "open"`."""

    left: Wall = Field(default_factory=Wall)
    right: Wall = Field(default_factory=Wall)
    bottom: Wall = Field(default_factory=lambda: Wall(thermal="fixed"))
    top: Wall = Field(default_factory=lambda: Wall(mechanical="open"))

    def walls(self) -> tuple[Wall, Wall, Wall, Wall]:
        """(left, right, bottom, top): the order of the solver's wall codes."""
        return self.left, self.right, self.bottom, self.top


class Physics(Model):
    mechanics: bool = Field(True, description="move the points (off: frozen geometry, heat only)")
    thermal: bool = Field(True, description="heat conduction and enthalpy")
    surface_tension: bool = Field(True, description="capillary force (surface_tension.method)")
    plasticity: bool = Field(True, description="Perzyna return map (off: linear elastic)")
    thermal_strain: bool = Field(
        True, description="thermal and transformation strains (eqs. 36-37)"
    )
    gravity_m_s2: Pair = Field([0.0, -9.81], description="body force per mass")


class Time(Model):
    dt_s: AutoPositive = Field(
        "auto", description='time step (s), or "auto" from the stability limits'
    )
    end_s: float = Field(1e-3, gt=0, description='simulated end time (s) of stop = "end"')
    stop: Literal["end", "solidified"] = Field(
        "end",
        description="end: run to end_s; solidified: once every laser is off, run until every "
        "point is solid (T <= T_c) and the kinetic energy has fallen below "
        "settled_kinetic_fraction of the surface energy, or to max_s (then marked max_time)",
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


class Solver(Model):
    transfer: Literal["apic", "flip", "pic_flip"] = Field(
        "pic_flip",
        description="apic; flip as printed (eq. 14); pic_flip: flip_ratio*FLIP + "
        "(1-flip_ratio)*PIC",
    )
    update: Literal["usl", "musl"] = Field(
        "usl",
        description="usl: eqs. 14-17 as printed; musl: move points with the remapped grid "
        "velocity (bounded on nearly empty nodes, but slows capillary flow)",
    )
    flip_ratio: float = Field(
        0.9, ge=0, le=1, description="FLIP share of the pic_flip blend, in [0, 1]"
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
        "(docs/speed.md)",
    )
    small_mass: float = Field(
        1e-9, ge=0, description="nodes below this fraction of a full cell's mass are skipped"
    )
    stress_reading: Literal["model", "paper"] = Field(
        "model",
        description="model: s = 2 mu dev(eps_e), p = K tr(eps_e) (MODEL.md); paper: eq. 39 "
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
        description="Taichi's advanced optimisation: ~1.5x faster steps after a ~100 s "
        "one-off compile (cached on disk); false compiles in ~5-10 s",
    )
    fast_math: bool = Field(
        True,
        description="let the compiler reorder floating-point arithmetic (Taichi's fast_math); "
        "false: strict IEEE order, bitwise reproducible across changes of code structure",
    )
    strain: Literal["small"] = Field(
        "small", description="small: accumulated eps += sym(L) dt (eqs. 16-17; not objective)"
    )


class Fusion(Model):
    """The verdict of a run: does this laser setting fuse the pair?"""

    neck_growth: float = Field(
        0.05,
        ge=0,
        description="fused: the neck at the end exceeds the initial one by this fraction and the "
        "neck region melted through",
    )
    neck_region_cells: float = Field(
        1.0,
        gt=0,
        description="the neck region: points within this many cells of the mid-plane between "
        "bodies 0 and 1 (at the start)",
    )
    melted_through: float = Field(
        0.99,
        gt=0,
        le=1,
        description="melted through: this fraction of the neck region's points was fully molten "
        "(above T_m) at some time",
    )


class Thermal(Model):
    initial_C: float = Field(140.0, description="initial temperature of every body without its own")
    enthalpy_reference_C: float = Field(0.0, description="temperature where enthalpy is zero")
    subgrid_filter: float = Field(
        1.0,
        ge=0,
        description="rate of the sub-grid temperature filter, in units of 1 / the thermal "
        "stability limit h^2 rho c / 4k: each heat step removes 1 - exp(-rate dt_heat / limit) "
        "of the points' sub-grid temperature noise (energy-conserving; physics/thermal.py). "
        "Increments alone never damp it, and stirred by the flow it grew to 6 K below the plate "
        "over 30 ms; rates of 3 and more overshoot at a sharp front; 0: increments alone (FLIP)",
    )


class Laser(Model):
    power_W: float = Field(25.0, ge=0, description="P")
    spot_radius_um: float = Field(50.0, gt=0, description="r_0")
    absorptivity: float = Field(
        0.85, ge=0, description="A (fraction, MODEL.md reads 0.85 % as 0.85)"
    )
    penetration_depth_um: float = Field(100.0, gt=0, description="eta_l")
    depth_factor: float = Field(0.6, ge=0, description="the 0.6 prefactor of eq. 31")
    on_s: float = Field(0.0, ge=0, description="switch-on time (s)")
    off_s: float = Field(20e-6, ge=0, description="switch-off time (s)")
    x_start_um: float = Field(40.0, description="beam centre at on_s (um)")
    speed_m_s: float = Field(0.0, description="scan speed along +x (m/s); 0 = stationary")
    x_end_um: float | None = Field(
        None, description="beam switches off when its centre passes this x"
    )
    top_um: float | None = Field(
        None, description="y_l, top of the powder; default: highest body top"
    )
    source_units: Literal["W_per_m3", "W_per_kg"] = Field(
        "W_per_m3",
        description="eq. 31 read as W/m^3 (MODEL.md) or, as printed in eq. 3, W/kg multiplied "
        "by rho",
    )
    depth_sign: Literal["decay", "paper"] = Field(
        "decay",
        description="decay: exp(-(y_l - y)/eta) (MODEL.md); paper: exp(+(y_l - y)/eta) as printed",
    )


def _point_radius(v: float) -> float:
    if not v > math.sqrt(2) / 4:
        raise ValueError(
            f"must exceed sqrt(2)/4 = {math.sqrt(2) / 4:.4f} (interior nodes would read outside)"
        )
    return v


class SurfaceTension(Model):
    method: Literal["surface_energy", "csf"] = Field(
        "surface_energy",
        description="surface_energy: the gradient of gamma times the length of the c = 1/2 "
        "outline of the node colour (the weak form of surface tension, Hyde et al. 2020; "
        "physics/surface_energy.py; the surface_energy_* keys); csf: the paper's level set, "
        "least-squares curvature and CSF force (eqs. 19-24; the keys from point_radius_over_h "
        "to curvature_step_fraction)",
    )
    surface_energy_colour: Literal["mass", "volume"] = Field(
        "mass",
        description="surface_energy: colour from the node mass m_i / (rho V_c) (rho of the first "
        "body's material) or from the point volumes sum V_p N_i / V_c",
    )
    surface_energy_colour_filter: bool = Field(
        True,
        description="surface_energy: contour the colour after one [1 2 1] / 4 pass along x and "
        "y; without it a pair whose mid-plane lies on a node line keeps a one-cell notch at the "
        "neck (the points of the two bodies never cross it)",
    )
    surface_energy_weight: Literal["hat", "gimp"] = Field(
        "hat",
        description="surface_energy: grad N_i at the Gauss points: hat (bilinear, the segment's "
        "cell corners) or gimp (the solver's uGIMP)",
    )
    surface_energy_gauss_points: int = Field(
        1,
        gt=0,
        le=3,
        description="surface_energy: Gauss points per outline segment (1 is exact for the hat)",
    )
    surface_energy_mass_floor: float = Field(
        0.01,
        ge=0,
        le=1,
        description="surface_energy: a node below this fraction of a full cell's mass carries "
        "only m_i / floor of its surface force (nodes at the edge of the points' support hold "
        "almost no mass; their acceleration would be unbounded)",
    )
    surface_energy_floor_mode: Literal["spread", "clip"] = Field(
        "spread",
        description="surface_energy: the rest of a light node's surface force: spread to its "
        "3x3 neighbours by mass (momentum kept) or clip (dropped: a static disc drifts)",
    )
    point_radius_over_h: Annotated[float, AfterValidator(_point_radius)] = Field(
        0.375,
        gt=0,
        description="r_p / h in eq. 21; > sqrt(2)/4 so interior nodes read inside",
    )
    band_cells: int = Field(3, gt=0, le=8, description="half-width of the level-set band (cells)")
    level_set: Literal["redistanced", "raw"] = Field(
        "redistanced",
        description="redistanced: signed distance to the eq. 21 zero contour; raw: eq. 21 as "
        "printed",
    )
    level_set_smoothing_passes: int = Field(
        8, ge=0, le=64, description="binomial smoothing passes over phi before the fit"
    )
    smoothing_passes: int = Field(
        16, ge=0, le=64, description="mass-weighted curvature smoothing passes"
    )
    colour_threshold: float = Field(
        0.0,
        ge=0,
        le=0.9,
        description="CSF acts on nodes above this fraction of a full cell's mass (0: eq. 19 as "
        "printed)",
    )
    zero_net_force: bool = Field(
        True, description="remove the CSF resultant left by curvature noise (mass-weighted)"
    )
    curvature_cap_h: float = Field(
        0.5, ge=0, description="|kappa| h capped here (0 = no cap); the grid resolves R >= 2h"
    )
    curvature_every: AutoCount = Field(
        "auto",
        description="rebuild level set and curvature every N steps (the CSF force uses the "
        'current mass every step); "auto": the largest N with N dt <= curvature_step_fraction '
        "x the capillary limit. A stale curvature is a delayed restoring force: every 10 steps "
        "on the paper's fine grid (N dt = the capillary limit) doubled the kinetic energy",
    )
    curvature_step_fraction: float = Field(
        0.25,
        gt=0,
        le=1.0,
        description="curvature age as a fraction of the capillary limit for curvature_every = "
        '"auto"',
    )
    ramp_s: float = Field(
        0.0,
        ge=0,
        description="gamma rises linearly from 0 over this time (s), either method; 0: at once. "
        "A body started stress-free rings at its breathing period when gamma switches on at "
        "once (the Laplace verification case ramps it in)",
    )
    initial_stress: Literal["laplace", "none"] = Field(
        "laplace",
        description="laplace: every disc starts in equilibrium with its own surface tension "
        "(in-plane pressure gamma/R, carried by the elastic strain at its initial temperature; "
        "other shapes start stress-free); none: every body starts stress-free and its Laplace "
        "pressure compresses it once the run starts (the paper does not say)",
    )


class Output(Model):
    frames: int = Field(
        20, gt=0, le=100000, description="number of output frames over the run (linear spacing)"
    )
    spacing: Literal["auto", "linear", "log"] = Field(
        "auto",
        description="frame times: linear (frames over end_s), log (frames_per_decade from "
        'first_frame_s); auto: linear for stop = "end", log for "solidified"',
    )
    frames_per_decade: int = Field(10, gt=0, le=1000, description="log spacing: frames per decade")
    first_frame_s: float = Field(1e-6, gt=0, description="log spacing: time of the first frame")
    png: bool = Field(True, description="write frames/*.png")
    gif: bool = Field(True, description="write animation.gif from the frames")
    vtu: bool = Field(False, description="write ParaView point data (points_*.vtu + points.pvd)")
    dpi: int = Field(80, gt=0, le=600, description="resolution of the frames")
    neck_measure: Literal["auto", "colour", "level_set"] = Field(
        "auto",
        description="the interface the contact line is read on: colour ({c > 1/2}, the "
        "surface-energy force's), level_set ({phi < 0} of eq. 21 with r_p, the paper's Fig. 4); "
        "auto: the capillary force's own",
    )
    deformation: Literal["displacement", "plastic_strain"] = Field(
        "displacement", description="what the right-hand panel colours the points by"
    )
