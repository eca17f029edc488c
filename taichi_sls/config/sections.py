"""The tables of a case file other than bodies and materials."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import AfterValidator, Field

from .model import Model, Point


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
    seeding: Literal["centre", "area"] = Field(
        "centre",
        description="centre: a point is kept where its centre lies in a body, with the volume "
        "of its whole square (an outline seeded as a staircase, +-1/2 point spacing); area: a "
        "point is kept where its square touches a body, with the volume of the part inside (the "
        "outline and a narrow neck seeded to second order; solver/scene.py)",
    )
    ghost_cells: int = Field(
        1,
        ge=0,
        le=8,
        description="extra cells beyond left/right/bottom walls (surface tension stencil)",
    )


def _two_or_three_dims(v: int) -> int:
    if v not in (2, 3):
        raise ValueError("allowed values are 2, 3")
    return v


class Domain(Model):
    dim: Annotated[int, AfterValidator(_two_or_three_dims)] = Field(
        2,
        description="2: a plane section, every extensive output per unit depth (energies in "
        "J/m, the _J_per_m columns); 3: a box width x height x depth, the same outputs in J "
        "(timeseries.csv's columns end in _J); y is up in both. 3D runs spheres "
        "([[bodies]] discs with [x, y, z] centres), cylinders and boxes; what it lacks is "
        "refused by its key (docs/limitations.md)",
    )
    width_um: float = Field(80.0, gt=0, description="domain width (um); x from 0")
    height_um: float = Field(48.0, gt=0, description="domain height (um); y from 0 (baseplate)")
    depth_um: float | None = Field(
        None, gt=0, description="3D only: domain depth (um); z from 0; default the width"
    )

    def depth(self) -> float:
        """The z extent in 3D (um): depth_um, or the width without one."""
        return self.width_um if self.depth_um is None else self.depth_um


class Wall(Model):
    mechanical: Literal["slip", "stick", "open", "mirror", "periodic"] = Field(
        "slip",
        description="slip: zero normal velocity; mirror: a plane of symmetry (slip, insulated, "
        "no surface at the plane; the case is the half of a symmetric scene); periodic: front "
        "and back (3D) together, z wraps with the period depth_um (config/periodic.py)",
    )
    thermal: Literal["insulated", "fixed"] = Field("insulated", description="heat flux condition")
    temperature_C: float = Field(140.0, description="wall temperature when thermal = fixed")


class Boundary(Model):
    """Bottom wall default: `thermal = "fixed"` at 140 C; top wall default:
    `mechanical = "open"`. `front` (z = 0) and `back` (z = depth): 3D only, defaults slip and
    insulated."""

    left: Wall = Field(default_factory=Wall)
    right: Wall = Field(default_factory=Wall)
    bottom: Wall = Field(default_factory=lambda: Wall(thermal="fixed"))
    top: Wall = Field(default_factory=lambda: Wall(mechanical="open"))
    front: Wall = Field(default_factory=Wall, description="3D only: the wall at z = 0")
    back: Wall = Field(default_factory=Wall, description="3D only: the wall at z = depth")

    def walls(self, dim: int = 2) -> tuple[Wall, ...]:
        """(left, right, bottom, top[, front, back]): the order of the solver's wall codes."""
        six = self.left, self.right, self.bottom, self.top, self.front, self.back
        return six[: 2 * dim]


class Physics(Model):
    mechanics: bool = Field(True, description="move the points (off: frozen geometry, heat only)")
    thermal: bool = Field(True, description="heat conduction and enthalpy")
    surface_tension: bool = Field(True, description="capillary force (surface_tension.method)")
    plasticity: bool = Field(True, description="Perzyna return map (off: linear elastic)")
    thermal_strain: bool = Field(
        True, description="thermal and transformation strains (eqs. 36-37)"
    )
    gravity_m_s2: Point = Field(
        [0.0, -9.81],
        description="body force per mass; [gx, gy] (in 3D gz = 0) or [gx, gy, gz] in 3D; y is up",
    )


class Fusion(Model):
    """The verdict of a run: does this laser setting fuse the pair?"""

    neck_growth: float = Field(
        0.05,
        ge=0,
        description="fused: the refrozen neck exceeds the baseline neck by this fraction and the "
        "neck region melted through",
    )
    baseline: Literal["unheated", "initial"] = Field(
        "unheated",
        description="the neck that growth is measured against: unheated, the neck of the same "
        "case run without laser heat for baseline_s (a soft solid with a surface energy adheres "
        "and grows its contact unheated; jobs/unheated.py); initial: the neck at t = 0",
    )
    baseline_s: float = Field(
        2e-4,
        gt=0,
        description="unheated baseline: simulated time of the unheated run (s); the adhesive "
        "contact settles within some 50 us",
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


class Contact(Model):
    """How touching bodies meet at the start, and how their necks are read."""

    initial: Literal["fillet", "point"] = Field(
        "point",
        description="fillet: every pair of discs closer than twice fillet_radius_um is joined "
        "by the bridge that two fillet circles of that radius, tangent to both discs, cut off "
        "(a finite neck whose outline does not depend on h; solver/contacts.py); point: the "
        "discs as seeded (touching discs meet at one point, a neck the grid sets)",
    )
    fillet_radius_um: float = Field(
        2.0,
        gt=0,
        description="fillet: radius of the fillet circles (um). Between touching discs of "
        "radius R the neck is 2 (sqrt(rho^2 + 2 R rho) - rho): 8 um at rho = 0.5 um (the "
        "paper's neck, below the grid), 10.8 um at 1 um, 14.3 um at 2 um",
    )
    allow_overlap: bool = Field(
        False,
        description="true: [[bodies]] discs may overlap (the overlap's points go to the first "
        "body that holds them); false: two discs overlapping beyond round-off are an error "
        "naming both and the depth",
    )
    neck_section: Literal["column", "centres"] = Field(
        "column",
        description="column: the narrowest vertical node column between bodies 0 and 1, holes "
        "excluded, on the colour the force contours; centres: each contact's narrowest section "
        "perpendicular to the line of its bodies' centres, between the outermost crossings of "
        "the interface, on the colour neck_colour names (sub-cell, any direction; a gap "
        "crossing the section is ignored; docs/record/verification.md)",
    )
    neck_colour: Literal["kernel", "filtered", "raw"] = Field(
        "kernel",
        description="the colour the sections across the centres read (their contact line and "
        "verdict, a bed's necks). kernel: the points' kernel sum (each point's volume spread "
        "with its uGIMP shape function) on a raster of h / 4 (3D: h / 2), closed by a disc of "
        "one cell (it fills the slot two coalescing bodies' points leave on their mid-plane; "
        "solver/kernel_colour.py). filtered: after the force's [1 2 1] / 4 pass (the default "
        "before issue #54: it widens a concave neck by about kappa h^2 / 4). raw: the cell "
        "fraction on the nodes (it reads the slot; docs/record/verification.md)",
    )
    settle: bool = Field(
        False,
        description="true: the run starts from the bodies' own adhesive equilibrium at their "
        "initial temperature: before t = 0 they step with every laser absorbing nothing until "
        "the settle rule of a case no laser heats holds (time.settled_kinetic_fraction, "
        "time.settled_neck_change, checked on the output's log-spaced frame times, at most "
        "time.max_s), then the clock, the points' start positions and the integrator begin "
        "again there and the lasers act on their own times. The settled neck is the verdict's "
        "unheated baseline (no separate run). false: the laser meets the bodies as seeded "
        "(jobs/settle.py; docs/record/convergence.md)",
    )
    settle_steps: Literal["explicit", "implicit"] = Field(
        "explicit",
        description="settle: the steps that settle the bodies. explicit: the case's own (the "
        "hybrid's explicit steps until its hand-over rule holds); implicit: the adaptive "
        "implicit step from the start (backward Euler damps the ringing instead of stepping "
        "through it; needs time.integrator = hybrid or implicit; docs/record/convergence.md)",
    )


class Thermal(Model):
    initial_C: float = Field(140.0, description="initial temperature of every body without its own")
    enthalpy_reference_C: float = Field(0.0, description="temperature where enthalpy is zero")
    subgrid_filter: float = Field(
        1.0,
        ge=0,
        description="rate of the sub-grid temperature filter, in units of 1 / the thermal "
        "stability limit h^2 rho c / 4k, in 3D too (its own limit is 2/3 of that): each heat "
        "step removes 1 - exp(-rate dt_heat / limit) "
        "of the points' sub-grid temperature noise (energy-conserving; physics/thermal.py). "
        "Increments alone never damp it, and stirred by the flow it grew to 6 K below the plate "
        "over 30 ms; rates of 3 and more overshoot at a sharp front; 0: increments alone (FLIP)",
    )
    top_surface: Literal["insulated", "chamber"] = Field(
        "insulated",
        description="the layer's top surface: insulated (no heat crosses it); chamber: it loses "
        "q = convection_W_m2K (T - T_ch) + emissivity sigma (T^4 - T_ch^4) per area to the "
        "chamber at chamber_C, through each grid column's projected width, from the top three "
        "nodes of the column that hold material (docs/model.md, 'Top-surface heat loss')",
    )
    chamber_C: float | None = Field(
        None,
        description="top_surface = chamber: the chamber temperature T_ch (C); default initial_C",
    )
    emissivity: float = Field(
        0.92,
        ge=0,
        le=1,
        description="top_surface = chamber: the surface's emissivity (PA12 0.90-0.92, "
        "docs/record/pa12_process.md)",
    )
    convection_W_m2K: float = Field(
        0.0, ge=0, description="top_surface = chamber: the convection coefficient h (W/(m^2 K))"
    )

    imposed_temperature_csv: str | None = Field(
        None,
        description="a temperature history every point is held at: a CSV file (relative to the "
        "case file) with columns t_s (s, from 0, increasing) and T_C (C), linear between rows, "
        "the last value after them. Each heat step sets every point to T(t); its solid fraction "
        "follows (melting, crystallisation kinetics at the held T); the heat this takes is "
        "booked in heat_out. It assumes no gradient inside a particle (Biot number << 1) and "
        "replaces conduction and every heat source: no lasers, fixed-temperature walls or "
        "chamber top surface (docs/validation.md)",
    )

    def chamber_temperature_C(self) -> float:
        """T_ch (C): chamber_C, or the initial temperature."""
        return self.initial_C if self.chamber_C is None else self.chamber_C


# scan = across: a pass heats the plane while its spot centre is within this many spot radii
PASS_HALF_WIDTH = 3.0


class Laser(Model):
    power_W: float = Field(25.0, ge=0, description="P")
    spot_radius_um: float = Field(50.0, gt=0, description="r_0")
    absorptivity: float = Field(
        0.85, ge=0, description="A (fraction, docs/model.md reads 0.85 % as 0.85)"
    )
    penetration_depth_um: float = Field(100.0, gt=0, description="eta_l")
    depth_factor: float = Field(0.6, ge=0, description="the 0.6 prefactor of eq. 31")
    on_s: float = Field(0.0, ge=0, description="switch-on time (s)")
    off_s: float = Field(20e-6, ge=0, description="switch-off time (s)")
    x_start_um: float = Field(
        40.0, description="beam centre at on_s (um); scan = across: the first track's x (um)"
    )
    z_start_um: float | None = Field(
        None,
        description="3D only: the beam centre's z at on_s (um; the first track's z when the "
        "tracks run along x); default the domain's mid-depth",
    )
    direction: Literal["x", "z"] = Field(
        "x",
        description="3D only: the scan direction in the bed plane (x or z; y is up); the spot "
        "moves along +direction at speed_m_s and track k is offset k hatch_um along the other "
        'bed axis (docs/model.md, "The laser in 3D"); 2D: x',
    )
    speed_m_s: float = Field(
        0.0,
        description="scan speed along +x (m/s; 3D: along +direction); 0 = stationary. scan = "
        "across: the speed along the tracks, normal to the plane (> 0)",
    )
    scan: Literal["along", "across"] = Field(
        "along",
        description="along: the plane contains the track, the spot moves in x at speed_m_s; "
        "across: the plane is a section across parallel tracks (hatches): track k (k < tracks) "
        "runs normal to the plane at x_start_um + k hatch_um and its spot passes through the "
        "plane at speed_m_s, crossing it at on_s + 3 r0 / v + k return_s; each pass delivers the "
        "line energy A P / v, so the mean energy per area is A P / (v hatch) (docs/model.md, "
        "'Hatches')",
    )
    tracks: int = Field(
        1,
        ge=1,
        le=1000,
        description="number of tracks: scan = across (2D), or 3D, where they lie in the bed",
    )
    hatch_um: float = Field(
        100.0, gt=0, description="distance between tracks (um): scan = across (2D), or 3D"
    )
    return_s: float | None = Field(
        None,
        gt=0,
        description="time between successive tracks (s; a machine's track length / speed plus "
        "its turn): scan = across, between passes through the plane; 3D, between track starts "
        "(a track heats until the next one starts); needed for tracks > 1",
    )
    x_end_um: float | None = Field(
        None, description="beam switches off when its centre passes this x (3D: each track)"
    )
    z_end_um: float | None = Field(
        None,
        description='3D, direction = "z": each track stops heating when its centre passes this '
        "z (um)",
    )
    top_um: float | None = Field(
        None, description="y_l, top of the powder; default: highest body top"
    )
    surface: Literal["scene", "local"] = Field(
        "scene",
        description="where the depth of eq. 31 is measured from: scene, y_l (top_um, or the "
        "highest body top as seeded); local, the surface the beam meets first above the point: "
        "the highest point top in the grid column (2D: x; 3D: x, z) holding the point, each "
        'heat step (docs/model.md, "The beam\'s first surface")',
    )
    source_units: Literal["W_per_m3", "W_per_kg"] = Field(
        "W_per_m3",
        description="eq. 31 read as W/m^3 (docs/model.md) or, as printed in eq. 3, W/kg multiplied "
        "by rho",
    )
    depth_sign: Literal["decay"] = Field(
        "decay",
        description="decay: exp(-(y_l - y)/eta) (docs/model.md); the printed exp(+(y_l - y)/eta), "
        "which grows with depth, is not offered",
    )

    def track_windows_along_s(self) -> list[tuple[float, float]]:
        """scan = along: each track's heating window (s). Track k starts at on_s + k return_s
        and heats until off_s, the next track's start, or its centre passing the end key
        (x_end_um, or z_end_um for direction = "z")."""
        end_um = self.z_end_um if self.direction == "z" else self.x_end_um
        start_um = self.z_start_um if self.direction == "z" else self.x_start_um
        out = []
        for k in range(self.tracks):
            on = self.on_s + k * (self.return_s or 0.0)
            end = self.off_s
            if k < self.tracks - 1:
                end = min(end, on + (self.return_s or 0.0))
            if self.speed_m_s != 0.0 and end_um is not None and start_um is not None:
                end = min(end, on + (end_um - start_um) * 1e-6 / self.speed_m_s)
            out.append((min(on, self.off_s), max(end, on)))
        return out

    def pass_half_s(self) -> float:
        """scan = across: half the time a pass heats the plane (s), PASS_HALF_WIDTH r0 / v; the
        Gaussian beyond it carries erfc(3 sqrt 2) / 2 = 1e-9 of a pass's energy."""
        return PASS_HALF_WIDTH * self.spot_radius_um * 1e-6 / self.speed_m_s

    def track_windows_s(self) -> list[tuple[float, float]]:
        """scan = across: each track's heating window (s), centred on its crossing time
        on_s + pass_half_s + k return_s and cut to [on_s, off_s]."""
        half = self.pass_half_s()
        out = []
        for k in range(self.tracks):
            tc = self.on_s + half + k * (self.return_s or 0.0)
            out.append((max(tc - half, self.on_s), max(min(tc + half, self.off_s), self.on_s)))
        return out


class Output(Model):
    frames: int | None = Field(
        None,
        gt=0,
        le=100000,
        description="number of output frames over the run, linearly spaced; setting it asks for "
        'linear spacing under spacing = auto (stop = "end"). Unset: log spacing in a case a '
        "laser heats, 20 linear frames otherwise",
    )
    spacing: Literal["auto", "linear", "log"] = Field(
        "auto",
        description="frame and time-series row times: linear (frames over end_s), log "
        "(frames_per_decade from first_frame_s, so that the microsecond melting transient is "
        'seen); auto: log for stop = "solidified" and for a case a laser heats that does not '
        "set frames (31 frames to 1 ms by default), linear otherwise (e.g. an isothermal "
        "coalescence)",
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
    validation: Literal["none", "pulse_pair_R125"] = Field(
        "none",
        description="a measured neck of the package (taichi_sls/data/pa12) beside the pair's "
        "a / R (bodies 0 and 1 of one radius R; a = half the contact line): validation.png and "
        "validation.csv in the run's folder (docs/validation.md). pulse_pair_R125: the "
        "laser-pulsed PA12 pair of R = 125 um (Hejmady et al.); none: no comparison",
    )
    validation_up_to_s: float = Field(
        1.0,
        gt=0,
        description="validation: the largest |error| of a / R is over the times up to this (s)",
    )
