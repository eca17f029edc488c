"""Verification case files: a case plus a ``[verification]`` table naming the analytic comparison
and the initial conditions or loads that ordinary case keys cannot express.

The table belongs to the studies, not to the case schema: :func:`split` takes it off the raw
data before the case is validated. Resolution parameter of :func:`load`, by kind:
- ``bar``, ``steffen``: cells along the bar (the cross-section is one cell of points);
- ``stefan``: cells across the melt depth X_m at the end time (the slab is 5 X_m long);
- ``curvature``, ``laplace``, ``viscous_decay``, ``inviscid``: R/h of the disc;
- ``hopper``: R0/h of each cylinder (touching discs, or Hopper's outline at hopper_tau0);
- ``perzyna``: time steps over the constant-rate drive;
- ``finite_strain``: time steps over end_s (the Maxwell drives) and increments of the full turn;
- every other kind: the grid spacing in um.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from pydantic import Field, ValidationError

from ...config import Case, CaseError, bundled_cases, case_from_dict, deep_update, read_toml
from ...config.errors import case_error
from ...config.loading import bundled_root, find_case, in_file, read_case_file, resolve_files
from ...config.model import Model, Pair
from .. import references as ref
from .geometry import bar_geometry, disc_geometry, hopper_geometry, slab_length

Kind = Literal[
    "none",
    "bar",
    "steffen",
    "perzyna",
    "finite_strain",
    "erf",
    "gaussian",
    "spot3d",
    "stefan",
    "energy",
    "curvature",
    "laplace",
    "square",
    "viscous_decay",
    "inviscid",
    "hopper",
]


class VerificationSpec(Model):
    """The ``[verification]`` table: which comparison, and its initial fields or loads. Only
    ``bar``, ``steffen`` and ``gaussian`` change the run itself; the other kinds name the measure
    that the accuracy study takes."""

    kind: Kind = Field("none", description="which comparison; none: a plain case")
    velocity_amplitude_m_s: float = Field(
        0.0,
        ge=0,
        description="bar: initial x-velocity v0 sin(pi x / 2L) of body 0 (a rectangle from x = 0, "
        "L its length), the first axial mode of a bar fixed at x = 0",
    )
    displacement_amplitude_um: float = Field(
        0.0,
        ge=0,
        description="steffen: A of the manufactured displacement u = A sin(2 pi X/L) "
        "sin(pi c t/L), c = sqrt(E/rho), driven by the body force it implies "
        "(references.steffen_body_force)",
    )
    center_um: Pair = Field([0.0, 0.0], description="gaussian: centre (um)")
    sigma_um: float = Field(0.0, ge=0, description="gaussian: initial standard deviation s0 (um)")
    rise_C: float = Field(
        0.0, description="gaussian: initial peak rise over thermal.initial_C, rise exp(-r^2/2 s0^2)"
    )
    shear_rate_1_s: float = Field(
        0.0,
        ge=0,
        description="perzyna: engineering shear rate of the constant-rate drive (1/s); "
        "finite_strain: rate of the simple shear v_x = rate y (1/s)",
    )
    hold_strain: float = Field(
        0.0,
        ge=0,
        description="perzyna: shear strain eps_xy held fixed for the relaxation check; "
        "finite_strain: the elastic shear strain of the prestressed point (relaxation, rotation)",
    )
    hopper_tau0: float = Field(
        0.0,
        ge=0,
        description="hopper: 0: the run starts from two touching discs and its clock is aligned "
        "where the neck first reaches hopper_align; > 0: it starts from Hopper's exact outline "
        "at this tau = gamma t / (eta_N R0) (a polygon body)",
    )
    hopper_align: float = Field(
        0.35, gt=0, lt=1.4, description="hopper from touching discs: r_n / R0 where clocks align"
    )
    hopper_taus: list[float] = Field(
        [0.5, 1.0, 2.0, 3.0], description="hopper: the tau at which r_n / R0 is compared"
    )
    hopper_angle_deg: float = Field(
        0.0,
        ge=-180,
        le=180,
        description="hopper at a resolution (verification.load): the line of centres turned by "
        "this angle from x in the x-y plane, about the neck (the neck read on the turned "
        "mid-plane); 0: along x",
    )
    hopper_midplane: Literal["node", "cell"] = Field(
        "node",
        description="hopper at a resolution (verification.load): the mid-plane on a node line "
        "or through cell centres",
    )


@dataclass
class VerificationCase:
    """A validated case and its verification table."""

    case: Case
    spec: VerificationSpec


def split(data: dict) -> tuple[dict, dict | None]:
    """(case data, the ``[verification]`` table or None) of raw TOML data."""
    data = dict(data)
    return data, data.pop("verification", None)


def _check(case: Case, v: VerificationSpec) -> None:
    def need(key: str, value: float, why: str) -> None:
        if not value > 0:
            raise CaseError(
                f"verification.{key} = {value}: must be > 0 for kind = {v.kind!r} ({why})"
            )

    if v.kind in ("bar", "steffen"):
        b = case.bodies[0]
        if b.shape != "rect" or b.min_um[0] != 0.0:
            raise CaseError(
                f"verification.kind = {v.kind!r}: bodies[0] must be a rectangle starting at "
                f"x = 0 (the fixed end), got shape = {b.shape!r}, min_um = "
                f"{getattr(b, 'min_um', None)}"
            )
        if not case.physics.mechanics:
            raise CaseError(f"verification.kind = {v.kind!r}: needs physics.mechanics = true")
        if v.kind == "bar":
            need("velocity_amplitude_m_s", v.velocity_amplitude_m_s, "the initial velocity")
        else:
            need("displacement_amplitude_um", v.displacement_amplitude_um, "the manufactured field")
    elif v.kind == "gaussian":
        need("sigma_um", v.sigma_um, "the initial width")
        if not case.physics.thermal:
            raise CaseError("verification.kind = 'gaussian': needs physics.thermal = true")
    elif v.kind == "spot3d":
        if case.domain.dim != 3 or len(case.lasers) != 1 or case.lasers[0].speed_m_s != 0.0:
            raise CaseError(
                "verification.kind = 'spot3d': needs domain.dim = 3 and one stationary laser"
            )
    elif v.kind in ("perzyna", "finite_strain"):
        need("shear_rate_1_s", v.shear_rate_1_s, "the constant-rate drive")
        need("hold_strain", v.hold_strain, "the relaxation check")


def from_dict(data: dict) -> VerificationCase:
    """Validate raw data of a verification case file."""
    case_data, table = split(data)
    try:
        spec = VerificationSpec.model_validate(table or {})
    except ValidationError as e:
        err = case_error(e, VerificationSpec, table)
        raise CaseError(f"verification.{err}") from None
    case = case_from_dict(case_data)
    _check(case, spec)
    return VerificationCase(case, spec)


def is_verification_file(path: str | Path) -> bool:
    """Whether a case file carries a ``[verification]`` table."""
    return "verification" in read_toml(find_case(path), "case file")


def load_file(path: str | Path, overrides: list[str] | None = None) -> VerificationCase:
    """A verification case file with ``--set`` overrides (``verification.*`` keys included)."""
    from ...config.loading import apply_override

    path = find_case(path)
    data = read_case_file(path)
    for o in overrides or []:
        apply_override(data, o)
    data.setdefault("case", {}).setdefault("name", path.stem)
    resolve_files(data, path.parent)
    return in_file(path, from_dict, data)


# ------------------------------------------------------------------------------ resolution


def case_path(name: str) -> Path:
    return bundled_root() / "verification" / f"{name}.toml"


def case_names() -> list[str]:
    return [p.stem for p in bundled_cases("verification")]


def stefan_slab(case: Case) -> ref.StefanSlab:
    """The melting slab of a stefan verification case (body 0's material, the left wall)."""
    m = case.materials[case.bodies[0].material]
    return ref.StefanSlab(
        case.thermal.initial_C,
        case.boundary.left.temperature_C,
        m.crystallization_C,
        m.melt_C,
        m.conductivity_solid_W_mK,
        m.density_kg_m3,
        m.heat_capacity_solid_J_kgK,
        m.latent_heat_J_kg,
    )


def stefan_melt_depth_um(case: Case) -> float:
    Xm, _ = ref.mushy_stefan_fronts(case.time.end_s, stefan_slab(case))
    return float(Xm) * 1e6


def load(name: str, resolution: float | None = None, sets: dict | None = None) -> VerificationCase:
    """Verification case ``name`` (bundled cases/verification/NAME.toml) at a resolution (module
    docstring), with ``sets`` (nested dict) merged in first."""
    path = case_path(name)
    if not path.is_file():
        raise CaseError(
            f"verification case {name!r} does not exist; available: {', '.join(case_names())}"
        )
    data = deep_update(read_toml(path, "verification case"), sets or {})
    data.setdefault("case", {}).setdefault("name", name)
    resolve_files(data, path.parent)
    data.setdefault("grid", {})
    kind = data.get("verification", {}).get("kind", "none")
    if resolution is not None:
        if kind in ("bar", "steffen"):
            bar_geometry(data, int(resolution), kind == "steffen")
        elif kind in ("curvature", "laplace", "viscous_decay", "inviscid"):
            disc_geometry(data, float(resolution))
        elif kind == "stefan":
            Xm = stefan_melt_depth_um(from_dict(data).case)
            slab_length(data, Xm / float(resolution), 5.0 * Xm)
        elif kind == "erf":
            slab_length(data, float(resolution), data["domain"]["width_um"])
        elif kind == "hopper":
            hopper_geometry(data, float(resolution))
        elif kind in ("perzyna", "finite_strain"):
            data.setdefault("time", {})["dt_s"] = data["time"]["end_s"] / int(resolution)
            data["time"]["allow_unstable_dt"] = True  # a point-level drive: no grid limit
        else:
            data["grid"]["spacing_um"] = float(resolution)
    return from_dict(data)
