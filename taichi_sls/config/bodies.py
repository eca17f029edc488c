"""Bodies of a case: discs, rectangles and polygons (in 3D spheres, cylinders, boxes and
prisms), each seeded with material points, and the bodies of a previous layer, whose points are
read from its layer file (lengths in um)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, field_validator

from .layer_file import read_layer
from .model import Model, Pair, Point


class BodyBase(Model):
    material: str = Field("PA12", description="name of a [materials.NAME] table")
    temperature_C: float | None = Field(
        None, description="initial temperature; default thermal.initial_C"
    )
    velocity_m_s: Point = Field(
        [0.0, 0.0],
        description="initial velocity (m/s); [vx, vy], in 3D also [vx, vy, vz] (vz = 0 without)",
    )


class Disc(BodyBase):
    shape: Literal["disc"] = Field(
        "disc", description="disc, cylinder, rect, polygon, prism or points"
    )
    center_um: Point = Field(
        [20.0, 20.0], description="disc centre (um); [x, y] in 2D, [x, y, z] in 3D (a sphere)"
    )
    radius_um: float = Field(20.0, gt=0, description="disc radius (um)")
    perturbation: float = Field(
        0.0,
        gt=-0.5,
        lt=0.5,
        description="outline r = R (1 + perturbation cos(mode theta)), |value| < 0.5; a sphere: "
        "r = R (1 + perturbation P_mode(cos theta)), theta from the x axis (Legendre P)",
    )
    mode: int = Field(2, ge=2, description="shape mode n >= 2 of the perturbation")

    def extent(self) -> tuple[tuple[float, float], tuple[float, float]]:
        r = self.radius_um * (1.0 + abs(self.perturbation))
        return tuple(c - r for c in self.center_um), tuple(c + r for c in self.center_um)

    def perimeter_um(self) -> float:
        return 2 * math.pi * self.radius_um

    def area_um2(self) -> float:
        """The surface of the sphere that a disc with a 3D centre is."""
        return 4 * math.pi * self.radius_um**2


class Cylinder(BodyBase):
    """3D only: a disc extruded along z across the whole depth (with a periodic depth, an
    infinite cylinder; config/periodic.py)."""

    shape: Literal["cylinder"] = Field(description="disc, cylinder, rect, polygon, prism or points")
    axis_um: Pair = Field(
        [20.0, 20.0],
        description="3D only: the axis' [x, y] (um); a disc extruded along z across the depth",
    )
    radius_um: float = Field(20.0, gt=0, description="cylinder radius (um)")

    def extent(self) -> tuple[tuple[float, float], tuple[float, float]]:
        r = self.radius_um
        return tuple(c - r for c in self.axis_um), tuple(c + r for c in self.axis_um)

    def perimeter_um(self) -> float:
        return 2 * math.pi * self.radius_um


class Rect(BodyBase):
    shape: Literal["rect"] = Field(description="disc, cylinder, rect, polygon, prism or points")
    min_um: Point = Field(
        [0.0, 0.0], description="rectangle lower-left corner (um); [x, y, z] in 3D (a box)"
    )
    max_um: Point = Field(
        [10.0, 10.0], description="rectangle upper-right corner (um); [x, y, z] in 3D (a box)"
    )

    def extent(self) -> tuple[tuple[float, float], tuple[float, float]]:
        return tuple(self.min_um), tuple(self.max_um)

    def perimeter_um(self) -> float:
        return 2 * (self.max_um[0] - self.min_um[0] + self.max_um[1] - self.min_um[1])

    def area_um2(self) -> float:
        """The surface of the box that a rect with 3D corners is."""
        a, b, c = (hi - lo for lo, hi in zip(self.min_um, self.max_um, strict=True))
        return 2 * (a * b + b * c + c * a)


class _Outline(BodyBase):
    """A closed outline in x-y: a polygon (2D) or the section of a prism (3D)."""

    vertices_um: list[Pair] = Field(
        [],
        description="outline vertices [[x, y], ...] (um), in order, either sense; or give "
        "vertices_file",
    )
    vertices_file: str | None = Field(
        None,
        description="file of outline vertices, one 'x y' pair (um) per line ('#' comments), "
        "relative to the case file",
    )

    @field_validator("vertices_file")
    @classmethod
    def _readable(cls, v: str | None) -> str | None:
        if v is not None and not Path(v).is_file():
            raise ValueError("no such file")
        return v

    def outline_um(self) -> list[list[float]]:
        """The vertices, from the table or the file."""
        if self.vertices_file is None:
            return [list(p) for p in self.vertices_um]
        rows = []
        for line in Path(self.vertices_file).read_text().splitlines():
            line = line.split("#", 1)[0].strip()
            if line:
                x, y = (float(s) for s in line.replace(",", " ").split())
                rows.append([x, y])
        return rows

    def extent(self) -> tuple[tuple[float, float], tuple[float, float]]:
        xs, ys = zip(*self.outline_um(), strict=True)
        return (min(xs), min(ys)), (max(xs), max(ys))

    def perimeter_um(self) -> float:
        v = self.outline_um()
        return sum(math.dist(v[i], v[i - 1]) for i in range(len(v)))


class Polygon(_Outline):
    shape: Literal["polygon"] = Field(description="disc, cylinder, rect, polygon, prism or points")


class Prism(_Outline):
    """3D only: a polygon's outline in x-y extruded along z across the whole depth, as a
    cylinder extrudes a disc (with a periodic depth, an infinite prism; config/periodic.py)."""

    shape: Literal["prism"] = Field(description="disc, cylinder, rect, polygon, prism or points")


class LayerBody(BodyBase):
    """One body of a previous layer: its points as that run left them (positions, volumes, and
    where the file carries them their deformation and stress), placed at rest; the case's
    ``bed.previous_layer`` lists one per body."""

    shape: Literal["points"] = Field(description="disc, cylinder, rect, polygon, prism or points")
    file: str = Field(description="layer file (layer.npz of a bed run), relative to the case file")
    body: int = Field(0, ge=0, description="which body of the layer file")

    @field_validator("file")
    @classmethod
    def _readable(cls, v: str) -> str:
        if not Path(v).is_file():
            raise ValueError("no such file")
        return v

    def points_um(self) -> tuple[np.ndarray, np.ndarray]:
        """(positions (n, dim), volumes (n,)) of the body's points (um, um^dim)."""
        return read_layer(self.file, "bodies[].file").of_body(self.body)

    def extent(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        x, vol = self.points_um()
        half = 0.5 * vol ** (1.0 / x.shape[1])
        lo, hi = (x - half[:, None]).min(axis=0), (x + half[:, None]).max(axis=0)
        return tuple(float(v) for v in lo), tuple(float(v) for v in hi)

    def carried_state(self) -> tuple[np.ndarray, dict[str, np.ndarray]] | None:
        """(seeded volumes (um^2), the points' deformation and stress members) as the layer's
        run left them, or None where the file does not carry them (config/layer_file.py)."""
        return read_layer(self.file, "bodies[].file").state_of_body(self.body)

    def centres_extent(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """The box of the points themselves (their squares may reach a hair into a wall that
        the run pressed them against)."""
        x, _ = self.points_um()
        lo, hi = x.min(axis=0), x.max(axis=0)
        return tuple(float(v) for v in lo), tuple(float(v) for v in hi)

    def perimeter_um(self) -> float:
        """The perimeter of the circle of the body's area (a lower bound of its outline)."""
        return 2.0 * math.sqrt(math.pi * float(np.sum(self.points_um()[1])))

    def area_um2(self) -> float:
        """3D: the surface of the sphere of the body's volume (a lower bound of its outline)."""
        volume = float(np.sum(self.points_um()[1]))
        return (36.0 * math.pi * volume**2) ** (1.0 / 3.0)


EXTRUDED = ("cylinder", "prism")  # 3D only: a 2D section extruded along z across the depth

Body = Annotated[Disc | Cylinder | Rect | Polygon | Prism | LayerBody, Field(discriminator="shape")]
