"""The case schema: one validated model per table of a case file.

Every key carries its unit in its name (``_um``, ``_s``, ``_C``, ``_Pa`` ...). Lengths are
micrometres and temperatures degrees Celsius because that is how the paper states them; the
solver converts to SI (m, K) when it builds its fields. Every check runs here, before any work.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import AfterValidator, Field, model_validator

from .bodies import Body, Disc
from .errors import CaseError
from .materials import Material
from .model import Model, Pair
from .numerics import Solver, Time
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

MAX_CELLS = 2e7  # ~4 GB of grid and 8e7 points at 2x2 per cell: beyond this machine's memory

__all__ = ["Body", "Case", "Disc", "Material", "MAX_CELLS", "Pair"]


def _not_empty(v: list) -> list:
    if not v:
        raise ValueError("at least one [[bodies]] table is required")
    return v


class Case(Model):
    case: CaseInfo = Field(default_factory=CaseInfo)
    grid: Grid = Field(default_factory=Grid)
    domain: Domain = Field(default_factory=Domain)
    bodies: Annotated[list[Body], AfterValidator(_not_empty)] = Field(default_factory=list)
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
        """A body without ``shape`` is a disc (the discriminator needs the tag)."""
        if isinstance(data, dict) and isinstance(data.get("bodies"), list):
            data = dict(data)
            data["bodies"] = [
                {"shape": "disc", **b} if isinstance(b, dict) and "shape" not in b else b
                for b in data["bodies"]
            ]
        return data

    @model_validator(mode="after")
    def _cross_checks(self) -> Case:
        """What a field type alone cannot express."""
        W, Hh = self.domain.width_um, self.domain.height_um
        h = self.grid.spacing_um
        if h > min(W, Hh) / 2:
            raise CaseError(f"grid.spacing_um = {h}: must be at most half the smaller domain side")
        cells = (W / h) * (Hh / h)
        if cells > MAX_CELLS:
            raise CaseError(
                f"grid.spacing_um = {h}: {cells:.3g} cells in a {W} x {Hh} um domain; at most "
                f"{MAX_CELLS:.0e} are allowed (memory)"
            )
        for name, m in self.materials.items():
            if not m.crystallization_C < m.melt_C:
                raise CaseError(
                    f"materials.{name}.crystallization_C = {m.crystallization_C}: must be below "
                    f"melt_C = {m.melt_C}"
                )
            rng = m.crystallization_range_C
            if rng is not None and not rng[0] < rng[1] <= m.crystallization_C:
                raise CaseError(
                    f"materials.{name}.crystallization_range_C = {rng}: must be [T_low, T_high] "
                    f"with T_low < T_high <= crystallization_C = {m.crystallization_C} (the "
                    "crystallisation range lies below the melting range, without overlap)"
                )
        eps = 1e-9 * max(W, Hh)
        for i, b in enumerate(self.bodies):
            key = f"bodies[{i}]"
            if b.material not in self.materials:
                raise CaseError(
                    f"{key}.material = {b.material!r}: no such material; defined: "
                    f"{', '.join(self.materials)}"
                )
            if b.shape == "rect" and not (b.max_um[0] > b.min_um[0] and b.max_um[1] > b.min_um[1]):
                raise CaseError(f"{key}.max_um = {b.max_um}: must exceed min_um = {b.min_um}")
            if b.shape == "polygon" and len(b.outline_um()) < 3:
                raise CaseError(
                    f"{key}.vertices_um: {len(b.outline_um())} vertices; a polygon needs at "
                    "least 3 (or a vertices_file)"
                )
            lo, hi = b.extent()
            if lo[0] < -eps or lo[1] < -eps or hi[0] > W + eps or hi[1] > Hh + eps:
                raise CaseError(
                    f"{key}: extent x {lo[0]}..{hi[0]}, y {lo[1]}..{hi[1]} um lies outside the "
                    f"domain 0..{W} x 0..{Hh} um"
                )
        for i, las in enumerate(self.lasers):
            if las.off_s < las.on_s:
                raise CaseError(f"lasers[{i}].off_s = {las.off_s}: must be >= on_s = {las.on_s}")
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
        if self.time.stop == "solidified" and self.time.max_s <= self.lasers_off_s():
            raise CaseError(
                f"time.max_s = {self.time.max_s}: must exceed the time every laser is off "
                f"({self.lasers_off_s():g} s)"
            )
        return self

    def lasers_off_s(self) -> float:
        """The time after which no laser heats (s): switched off, or scanned past x_end_um."""
        ends = [0.0]
        for las in self.lasers:
            end = las.off_s
            if las.speed_m_s != 0.0 and las.x_end_um is not None:
                end = min(end, las.on_s + (las.x_end_um - las.x_start_um) * 1e-6 / las.speed_m_s)
            ends.append(max(end, las.on_s) if las.power_W > 0 else 0.0)
        return max(ends)

    def perimeter_um(self) -> float:
        """Total outline length of the bodies as seeded (um)."""
        return sum(b.perimeter_um() for b in self.bodies)

    def top_um(self) -> float:
        """The highest point of any body (um): the top of the powder."""
        return max(b.extent()[1][1] for b in self.bodies)
