"""The ``[surface_tension]`` table: the capillary force and its options."""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import AfterValidator, Field

from .model import Model
from .numerics import AutoCount


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
    surface_energy_colour: Literal["mass"] = Field(
        "mass",
        description="surface_energy: colour from the node mass m_i / (rho V_c) (rho of the first "
        "body's material); the point volumes' sum V_p N_i / V_c is not offered",
    )
    surface_energy_colour_filter: bool = Field(
        True,
        description="surface_energy: contour the colour after one [1 2 1] / 4 pass along x and "
        "y (and z in 3D); without it a pair whose mid-plane lies on a node line keeps a "
        "one-cell notch at the neck (the points of the two bodies never cross it)",
    )
    surface_energy_weight: Literal["hat", "gimp"] = Field(
        "hat",
        description="surface_energy: grad N_i at the Gauss points: hat (bi/trilinear, the "
        "segment's or triangle's cell corners) or gimp (the solver's uGIMP)",
    )
    surface_energy_gauss_points: int = Field(
        1,
        gt=0,
        le=3,
        description="surface_energy: Gauss points per outline segment (1 is exact for the hat); "
        "3D triangles take the 3-point rule of degree 2 (exact for the trilinear hat)",
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
    level_set: Literal["redistanced"] = Field(
        "redistanced",
        description="redistanced: signed distance to the eq. 21 zero contour; eq. 21 as printed "
        "is not offered",
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
