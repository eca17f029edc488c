"""The case schema: one validated model per table of a case file.

Every key carries its unit in its name (``_um``, ``_s``, ``_C``, ``_Pa`` ...). Lengths are
micrometres and temperatures degrees Celsius because that is how the paper states them; the
solver converts to SI (m, K) when it builds its fields. Every check runs here, before any work.
"""

from __future__ import annotations

import math
from typing import Any

from pydantic import Field, model_validator

from .bed import Bed
from .bodies import EXTRUDED, Body, Disc
from .dim import check_dimension
from .errors import CaseError
from .layer_file import read_layer
from .materials import Material
from .model import Model, Pair
from .numerics import Solver, Time
from .overlap import check_overlaps
from .presets import expand_presets
from .sections import (
    Boundary,
    CaseInfo,
    Contact,
    Domain,
    Fusion,
    Grid,
    Laser,
    Output,
    Physics,
    Thermal,
)
from .surface import SurfaceTension
from .symmetry import check_symmetry, within_mirrors
from .temperature_table import read_temperature_table

MAX_CELLS = 2e7  # ~4 GB of grid and 8e7 points at 2x2 per cell: beyond this machine's memory

__all__ = ["Bed", "Body", "Case", "Disc", "Material", "MAX_CELLS", "Pair"]


NO_BODIES = "at least one [[bodies]] table or a [bed] table is required"


# time.linear_solver values with no direct factorization to keep (time.refactorize)
KEEPS_NO_FACTOR = ("amg", "matrix_free")


class Case(Model):
    case: CaseInfo = Field(default_factory=CaseInfo)
    grid: Grid = Field(default_factory=Grid)
    domain: Domain = Field(default_factory=Domain)
    bodies: list[Body] = Field(default_factory=list)
    bed: Bed | None = None
    materials: dict[str, Material] = Field(default_factory=lambda: {"PA12": Material()})
    boundary: Boundary = Field(default_factory=Boundary)
    physics: Physics = Field(default_factory=Physics)
    time: Time = Field(default_factory=Time)
    solver: Solver = Field(default_factory=Solver)
    thermal: Thermal = Field(default_factory=Thermal)
    lasers: list[Laser] = Field(default_factory=list)
    surface_tension: SurfaceTension = Field(default_factory=SurfaceTension)
    output: Output = Field(default_factory=Output)
    fusion: Fusion = Field(default_factory=Fusion)
    contact: Contact = Field(default_factory=Contact)

    @model_validator(mode="before")
    @classmethod
    def _default_shape(cls, data: Any) -> Any:
        """A body without ``shape`` is a disc (the discriminator needs the tag); a material that
        names a preset takes its values (config/presets.py)."""
        data = expand_presets(data)
        if isinstance(data, dict) and "bodies" not in data and "bed" not in data:
            # the default [] is not validated: say here what --set bodies=[] says
            raise CaseError(f"bodies: missing; {NO_BODIES}")
        if isinstance(data, dict) and isinstance(data.get("bodies"), list):
            data = dict(data)
            data["bodies"] = [
                {"shape": "disc", **b} if isinstance(b, dict) and "shape" not in b else b
                for b in data["bodies"]
            ]
        return data

    @model_validator(mode="after")
    def _cross_checks(self) -> Case:
        """What a field type alone cannot express. Checks only: nothing here changes the case
        (what derives from it is built by config/resolve.py). With a [bed], the domain and the
        bodies are checked on the resolved case, once the bed's bodies are in a fitted domain."""
        check_dimension(self)
        check_symmetry(self)
        check_overlaps(self._bodies_to_check_overlaps(), self.contact.allow_overlap)
        if self.bed is None and not self.bodies:
            raise CaseError(f"bodies = []: {NO_BODIES}")
        if self.bed is not None and self.bed.material not in self.materials:
            raise CaseError(
                f"bed.material = {self.bed.material!r}: no such material; defined: "
                f"{', '.join(self.materials)}"
            )
        if self.bed is None:
            self._check_domain()
        self._check_materials()
        if self.bed is None:
            self._check_bodies()
        self._check_lasers()
        self._check_imposed_temperature()
        self._check_solver()
        return self

    def _bodies_to_check_overlaps(self) -> list[Body]:
        """The bodies whose overlaps validation refuses: the case's own (a [bed]'s are checked
        against bed.overlap_tolerance_um by its generator)."""
        return self.bodies

    def _check_domain(self) -> None:
        """The grid fits the domain and the machine's memory."""
        sides = self.domain_um()
        h = self.grid.spacing_um
        if h > min(sides) / 2:
            raise CaseError(f"grid.spacing_um = {h}: must be at most half the smaller domain side")
        cells = math.prod(s / h for s in sides)
        if cells > MAX_CELLS:
            raise CaseError(
                f"grid.spacing_um = {h}: {cells:.3g} cells in a "
                f"{' x '.join(f'{s}' for s in sides)} um domain; at most "
                f"{MAX_CELLS:.0e} are allowed (memory)"
            )

    def _check_materials(self) -> None:
        """Each material's transition temperatures in order; one crystallisation model."""
        for name, m in self.materials.items():
            if not m.crystallization_C < m.melt_C:
                raise CaseError(
                    f"materials.{name}.crystallization_C = {m.crystallization_C}: must be below "
                    f"melt_C = {m.melt_C}"
                )
            rng = m.crystallization_range_C
            kin = m.crystallization_kinetics
            if kin is not None and rng is not None:
                raise CaseError(
                    f"materials.{name}.crystallization_kinetics: set with "
                    f"crystallization_range_C = {rng}; choose one (kinetics or a range)"
                )
            if kin is not None and not kin.T_inf_C < kin.T_m0_C:
                raise CaseError(
                    f"materials.{name}.crystallization_kinetics.T_inf_C = {kin.T_inf_C}: must "
                    f"be below T_m0_C = {kin.T_m0_C}"
                )
            if rng is not None and not rng[0] < rng[1] <= m.crystallization_C:
                raise CaseError(
                    f"materials.{name}.crystallization_range_C = {rng}: must be [T_low, T_high] "
                    f"with T_low < T_high <= crystallization_C = {m.crystallization_C} (the "
                    "crystallisation range lies below the melting range, without overlap)"
                )

    def _check_bodies(self) -> None:
        """Each body of a defined material, well formed and inside the domain."""
        sides = self.domain_um()
        eps = 1e-9 * max(sides)
        for i, b in enumerate(self.bodies):
            key = f"bodies[{i}]"
            if b.material not in self.materials:
                raise CaseError(
                    f"{key}.material = {b.material!r}: no such material; defined: "
                    f"{', '.join(self.materials)}"
                )
            rect = b.shape == "rect"
            if rect and not all(c > a for a, c in zip(b.min_um, b.max_um, strict=True)):
                raise CaseError(f"{key}.max_um = {b.max_um}: must exceed min_um = {b.min_um}")
            layer_dim = read_layer(b.file).dim if b.shape == "points" else self.domain.dim
            if layer_dim != self.domain.dim:
                raise CaseError(
                    f"{key}.file = {b.file!r}: a {layer_dim}D layer with "
                    f"domain.dim = {self.domain.dim}; allowed: a layer file written by a "
                    f"{self.domain.dim}D run"
                )
            if b.shape == "points" and len(b.points_um()[1]) == 0:
                raise CaseError(
                    f"{key}.body = {b.body}: the layer file {b.file!r} has no such body"
                )
            if b.shape in ("polygon", "prism") and len(b.outline_um()) < 3:
                raise CaseError(
                    f"{key}.vertices_um: {len(b.outline_um())} vertices; a {b.shape} needs at "
                    "least 3 (or a vertices_file)"
                )
            lo, hi = b.centres_extent() if b.shape == "points" else b.extent()
            lo, hi = within_mirrors(self, b, lo, hi)
            if any(a < -eps or c > s + eps for a, c, s in zip(lo, hi, sides, strict=False)):
                span = ", ".join(f"{n} {a}..{c}" for n, a, c in zip("xyz", lo, hi, strict=False))
                raise CaseError(
                    f"{key}: extent {span} um lies outside the domain "
                    f"{' x '.join(f'0..{s}' for s in sides)} um"
                )

    def _check_imposed_temperature(self) -> None:
        """A held temperature history: its table readable, and nothing else that heats."""
        path = self.thermal.imposed_temperature_csv
        if path is None:
            return
        key = f"thermal.imposed_temperature_csv = {path!r}"
        if not self.physics.thermal:
            raise CaseError(f"{key}: with physics.thermal = false; allowed: physics.thermal = true")
        read_temperature_table(path)
        heated = [i for i, las in enumerate(self.lasers) if las.power_W > 0]
        if heated:
            raise CaseError(
                f"{key}: with lasers[{heated[0]}].power_W = {self.lasers[heated[0]].power_W}; "
                "the held temperature replaces every heat source; allowed: no laser with power"
            )
        sides = ("left", "right", "bottom", "top", "front", "back")
        for side, wall in zip(sides, self.boundary.walls(self.domain.dim), strict=False):
            if wall.thermal == "fixed":
                raise CaseError(
                    f"{key}: with boundary.{side}.thermal = 'fixed'; the held temperature "
                    "replaces conduction to the walls; allowed: insulated walls"
                )
        if self.thermal.top_surface != "insulated":
            raise CaseError(
                f"{key}: with thermal.top_surface = {self.thermal.top_surface!r}; the held "
                "temperature replaces the chamber's loss; allowed: 'insulated'"
            )

    def _check_lasers(self) -> None:
        """Each laser's times and scan keys consistent."""
        for i, las in enumerate(self.lasers):
            if las.off_s < las.on_s:
                raise CaseError(f"lasers[{i}].off_s = {las.off_s}: must be >= on_s = {las.on_s}")
            if las.surface == "local" and las.top_um is not None:
                raise CaseError(
                    f'lasers[{i}].top_um = {las.top_um}: surface = "local" reads the surface '
                    'in each column (allowed: unset, or surface = "scene")'
                )
            if las.scan == "along" and las.tracks > 1 and self.domain.dim == 2:
                raise CaseError(
                    f'lasers[{i}].tracks = {las.tracks}: hatches need scan = "across" '
                    '(allowed with scan = "along": 1)'
                )
            if las.scan == "across":
                if las.speed_m_s <= 0.0:
                    raise CaseError(
                        f'lasers[{i}].speed_m_s = {las.speed_m_s}: scan = "across" needs the '
                        "speed along the tracks (allowed: > 0)"
                    )
                if las.x_end_um is not None:
                    raise CaseError(
                        f'lasers[{i}].x_end_um = {las.x_end_um}: not used with scan = "across" '
                        "(the tracks end where tracks and hatch_um put them; allowed: unset)"
                    )
                if las.tracks > 1 and las.return_s is None:
                    raise CaseError(
                        f"lasers[{i}].return_s = None: {las.tracks} tracks need the time "
                        "between their passes (allowed: > 0 s)"
                    )
                passage = 6e-6 * las.spot_radius_um / las.speed_m_s
                if las.tracks > 1 and las.return_s < passage:
                    raise CaseError(
                        f"lasers[{i}].return_s = {las.return_s}: shorter than a pass, 6 r0 / v "
                        f"= {passage:g} s (allowed: >= {passage:g})"
                    )

    def _check_solver(self) -> None:
        """The solver's, the integrator's and the stop's switches compatible."""
        if self.solver.stress_reading == "paper" and self.solver.strain == "finite":
            raise CaseError(
                'solver.stress_reading = "paper" with solver.strain = "finite": the printed '
                'eq. 39 is a small-strain law; use stress_reading = "model" (allowed with '
                'finite strain) or strain = "small" (allowed: "small", "finite")'
            )
        if self.solver.stress_reading == "paper" and self.solver.stress_form != "total":
            raise CaseError(
                f"solver.stress_form = {self.solver.stress_form!r}: the printed eq. 39 "
                '(solver.stress_reading = "paper") exists in the total form only'
            )
        if (
            self.time.integrator != "explicit"
            and self.physics.surface_tension
            and self.surface_tension.method != "surface_energy"
        ):
            raise CaseError(
                f"surface_tension.method = {self.surface_tension.method!r}: the implicit "
                "integrator linearises the surface-energy force only (allowed with it: "
                '"surface_energy")'
            )
        if self.solver.dilatation == "cell" and self.solver.update != "usl":
            raise CaseError(
                f'solver.dilatation = "cell" with solver.update = {self.solver.update!r}: the '
                "cells' dilatation is read from the grid velocity of the step, which MUSL "
                'remaps; allowed with it: solver.update = "usl" (any time.integrator), or '
                'dilatation = "point"'
            )
        if self.time.linear_solver == "matrix_free" and self.time.implicit_velocity_penalty > 0:
            raise CaseError(
                f"time.implicit_velocity_penalty = {self.time.implicit_velocity_penalty:g} with "
                'time.linear_solver = "matrix_free": the penalty is added to assembled rows; '
                'allowed with it: 0, or linear_solver = "auto", "direct" or "amg"'
            )
        if self.solver.dilatation == "cell" and self.time.linear_solver == "matrix_free":
            raise CaseError(
                'solver.dilatation = "cell" with time.linear_solver = "matrix_free": the '
                "matrix-free tangent is each point's own (solver/multigrid.py), not the cell's "
                'volumetric part; allowed with it: linear_solver = "auto", "direct" or "amg", or '
                'dilatation = "point"'
            )
        if self.time.refactorize == "when_slow" and self.time.linear_solver in KEEPS_NO_FACTOR:
            raise CaseError(
                f'time.refactorize = "when_slow" with time.linear_solver = '
                f'"{self.time.linear_solver}": only a direct factorization is kept across '
                'tangents; allowed with it: linear_solver = "auto" or "direct", or refactorize '
                '= "each_tangent"'
            )
        folded = [
            w.mechanical
            for w in self.boundary.walls(self.domain.dim)
            if w.mechanical in ("mirror", "periodic")
        ]
        if self.solver.dilatation == "cell" and folded:
            raise CaseError(
                f'solver.dilatation = "cell" with a {folded[0]!r} wall: its pressure force is '
                "not folded over the wall's images; allowed with it: walls that are not mirror "
                'or periodic, or dilatation = "point"'
            )
        if self.time.integrator != "explicit" and self.solver.update != "usl":
            raise CaseError(
                f"solver.update = {self.solver.update!r}: the implicit integrator moves the "
                'points with its converged grid velocity (allowed with it: "usl")'
            )
        if self.contact.settle_steps == "implicit" and not self.implicit_mechanics():
            raise CaseError(
                f'contact.settle_steps = "implicit" with time.integrator = '
                f"{self.time.integrator!r}: settling by implicit steps needs them (allowed: "
                'time.integrator = "hybrid" or "implicit", or settle_steps = "explicit")'
            )
        if self.time.adaptive and not self.implicit_mechanics():
            raise CaseError(
                f"time.adaptive = true with time.integrator = {self.time.integrator!r}"
                + ("" if self.physics.mechanics else " and physics.mechanics = false")
                + ": an adaptive step needs the implicit mechanics (the explicit step is "
                'bounded by its stability limits); allowed: time.integrator = "implicit"'
            )
        t = self.time
        if t.adaptive and "auto" not in (t.dt_min_s, t.dt_max_s) and t.dt_min_s > t.dt_max_s:
            raise CaseError(
                f"time.dt_min_s = {t.dt_min_s}: must not exceed time.dt_max_s = {t.dt_max_s}"
            )
        if self.time.stop == "solidified" and self.time.max_s <= self.lasers_off_s():
            raise CaseError(
                f"time.max_s = {self.time.max_s}: must exceed the time every laser is off "
                f"({self.lasers_off_s():g} s)"
            )

    def domain_um(self) -> tuple[float, ...]:
        """The domain's sides (um): width, height[, depth in 3D]."""
        d = self.domain
        return (d.width_um, d.height_um) + ((d.depth(),) if d.dim == 3 else ())

    def implicit_mechanics(self) -> bool:
        """Whether the mechanics steps implicitly (``time.integrator``; without mechanics there
        is nothing to step)."""
        return self.time.integrator != "explicit" and self.physics.mechanics

    def step_adapts(self) -> bool:
        """Whether the implicit step's size is chosen by the physics (``time.adaptive``, or the
        hybrid integrator's implicit phase)."""
        t = self.time
        return self.implicit_mechanics() and (t.adaptive or t.integrator == "hybrid")

    def implicit_heat(self) -> bool:
        """Whether the implicit step takes its heat by backward Euler (``time.heat_integrator``;
        "auto": where the step adapts)."""
        if not self.implicit_mechanics() or not self.physics.thermal:
            return False
        if self.time.heat_integrator == "auto":
            return self.step_adapts()
        return self.time.heat_integrator == "implicit"

    def lasers_off_s(self) -> float:
        """The time after which no laser heats (s): switched off, or scanned past its end."""
        ends = [0.0]
        for las in self.lasers:
            end = las.off_s
            if las.scan == "across":
                end = min(end, las.track_windows_s()[-1][1])
            elif self.domain.dim == 3:
                end = min(end, las.track_windows_along_s()[-1][1])
            elif las.speed_m_s != 0.0 and las.x_end_um is not None:
                end = min(end, las.on_s + (las.x_end_um - las.x_start_um) * 1e-6 / las.speed_m_s)
            ends.append(max(end, las.on_s) if las.power_W > 0 else 0.0)
        return max(ends)

    def perimeter_um(self) -> float:
        """Total outline length of the bodies as seeded (um)."""
        return sum(b.perimeter_um() for b in self.bodies)

    def outline_um(self) -> float:
        """The bodies' outline as seeded: their perimeter (um, per unit depth) in 2D, their
        surface (um^2) in 3D: a sphere's or a box's, and a cylinder's or a prism's side across
        the depth (extruded, their ends on the front and back walls or the period)."""
        if self.domain.dim == 2:
            return self.perimeter_um()
        depth = self.domain.depth()
        return sum(
            b.perimeter_um() * depth if b.shape in EXTRUDED else b.area_um2() for b in self.bodies
        )

    def top_um(self) -> float:
        """The highest point of any body (um): the top of the powder."""
        return max(b.extent()[1][1] for b in self.bodies)
