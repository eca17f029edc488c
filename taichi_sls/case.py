"""Case files (TOML) -> typed, validated dataclasses.

Every key carries its unit in its name (``_um``, ``_s``, ``_C``, ``_Pa`` ...). Lengths in case
files are micrometres and temperatures degrees Celsius because that is how the paper states
them; :class:`Case` converts nothing -- the solver converts to SI (m, K) when it builds fields.

All validation happens here, before any work, and every failure raises :class:`CaseError`
naming the key, the value and what is allowed.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

MAX_CELLS = 2e7  # ~4 GB of grid and 8e7 points at 2x2 per cell: beyond this machine's memory


class CaseError(ValueError):
    """A case file (or an override) is invalid. The message names key, value and what is allowed."""


def _opt(
    default: Any = dataclasses.MISSING,
    *,
    choices: tuple | None = None,
    positive: bool = False,
    nonneg: bool = False,
    doc: str = "",
    factory: Any = None,
    maximum: float | None = None,
) -> Any:
    meta = {"choices": choices, "positive": positive, "nonneg": nonneg, "doc": doc, "max": maximum}
    if factory is not None:
        return field(default_factory=factory, metadata=meta)
    return field(default=default, metadata=meta)


@dataclass
class CaseInfo:
    name: str = _opt("case", doc="case name; default output folder is out/<name>")
    description: str = _opt("", doc="free text")


@dataclass
class Grid:
    spacing_um: float = _opt(2.0, positive=True, doc="grid spacing h (um)")
    points_per_cell: int = _opt(
        2,
        positive=True,
        maximum=8,
        doc="material points per cell along each axis (2 -> 2x2 quarter points)",
    )
    ghost_cells: int = _opt(
        1,
        nonneg=True,
        maximum=8,
        doc="extra cells beyond left/right/bottom walls (surface tension stencil)",
    )


@dataclass
class Domain:
    width_um: float = _opt(80.0, positive=True, doc="domain width (um); x from 0")
    height_um: float = _opt(48.0, positive=True, doc="domain height (um); y from 0 (baseplate)")


@dataclass
class Body:
    shape: str = _opt("disc", choices=("disc", "rect"), doc="disc or axis-aligned rectangle")
    material: str = _opt("PA12", doc="name of a [materials.NAME] table")
    center_um: list[float] = _opt(factory=lambda: [20.0, 20.0], doc="disc centre (um)")
    radius_um: float = _opt(20.0, positive=True, doc="disc radius (um)")
    min_um: list[float] = _opt(factory=lambda: [0.0, 0.0], doc="rectangle lower-left corner (um)")
    max_um: list[float] = _opt(factory=lambda: [10.0, 10.0], doc="rectangle upper-right (um)")
    temperature_C: float | None = _opt(None, doc="initial temperature; default thermal.initial_C")
    velocity_m_s: list[float] = _opt(factory=lambda: [0.0, 0.0], doc="initial velocity (m/s)")
    perturbation: float = _opt(
        0.0, doc="disc only: outline r = R (1 + perturbation cos(mode theta)), |value| < 0.5"
    )
    mode: int = _opt(2, doc="disc only: shape mode n >= 2 of the perturbation")


@dataclass
class Material:
    """Every parameter of the paper's Table 3. `_solid` holds for T <= T_c, `_liquid` for
    T >= T_m; in between they are interpolated linearly in the solid fraction (eq. 33)."""

    density_kg_m3: float = _opt(1020.0, positive=True, doc="rho")
    conductivity_solid_W_mK: float = _opt(0.28, positive=True, doc="k_c")
    conductivity_liquid_W_mK: float = _opt(0.24, positive=True, doc="k_m")
    heat_capacity_solid_J_kgK: float = _opt(2700.0, positive=True, doc="c_c")
    heat_capacity_liquid_J_kgK: float = _opt(2700.0, positive=True, doc="c_m")
    latent_heat_J_kg: float = _opt(50e3, nonneg=True, doc="l_s")
    melt_C: float = _opt(175.0, doc="T_m")
    crystallization_C: float = _opt(146.0, doc="T_c (< T_m)")
    expansion_solid_1_K: float = _opt(15e-5, doc="alpha for T <= T_c")
    expansion_liquid_1_K: float = _opt(5e-5, doc="alpha for T >= T_m")
    solidification_dilatation: float = _opt(
        0.015, doc="beta: d(eps_m) = beta d(xi_s) 1 (eq. 37); 0.015 = the paper's 1.5 %"
    )
    poisson: float = _opt(0.42, doc="nu for T <= T_c, in (-1, 0.5) (Table 3)")
    poisson_liquid: float = _opt(
        0.49,
        doc="nu for T >= T_m, in (-1, 0.5); interpolated in xi_s like E. Default 0.49: a melt is "
        "nearly incompressible; the paper's one nu (set 0.42 for its reading) makes the 10 kPa "
        "melt's bulk modulus 21 kPa, which its own Laplace pressure compresses by 8 % in area "
        "and so opens the neck (README). 0.49 keeps the melt's P-wave modulus below the solid's: "
        "the same time step",
    )
    youngs_solid_Pa: float = _opt(1e5, positive=True, doc="E for T <= T_c")
    youngs_liquid_Pa: float = _opt(1e4, positive=True, doc="E for T >= T_m")
    yield_solid_Pa: float = _opt(1e5, nonneg=True, doc="sigma_Y for T <= T_c")
    yield_liquid_Pa: float = _opt(1e4, nonneg=True, doc="sigma_Y for T >= T_m")
    hardening_solid_Pa: float = _opt(1e5, nonneg=True, doc="H for T <= T_c")
    hardening_liquid_Pa: float = _opt(0.0, nonneg=True, doc="H for T >= T_m")
    viscosity_model: str = _opt(
        "exponential",
        choices=("exponential", "constant"),
        doc="exponential: eta = A exp(-b T[C]) (Table 3); constant: eta = viscosity_Pas",
    )
    viscosity_A_Pas: float = _opt(130219.0, positive=True, doc="A of the exponential law (Pa s)")
    viscosity_b_1_C: float = _opt(0.02, nonneg=True, doc="b of the exponential law (1/C)")
    viscosity_Pas: float = _opt(1e3, positive=True, doc="constant viscosity (Pa s)")
    surface_tension_N_m: float = _opt(36.3e-3, nonneg=True, doc="gamma (N/m)")


@dataclass
class Wall:
    mechanical: str = _opt(
        "slip", choices=("slip", "stick", "open"), doc="slip: zero normal velocity"
    )
    thermal: str = _opt("insulated", choices=("insulated", "fixed"), doc="heat flux condition")
    temperature_C: float = _opt(140.0, doc="wall temperature when thermal = fixed")


def _bottom_wall() -> Wall:
    return Wall(thermal="fixed")


def _top_wall() -> Wall:
    return Wall(mechanical="open")


@dataclass
class Boundary:
    left: Wall = _opt(factory=Wall)
    right: Wall = _opt(factory=Wall)
    bottom: Wall = _opt(factory=_bottom_wall)
    top: Wall = _opt(factory=_top_wall)


@dataclass
class Physics:
    mechanics: bool = _opt(True, doc="move the points (off: frozen geometry, heat only)")
    thermal: bool = _opt(True, doc="heat conduction and enthalpy")
    surface_tension: bool = _opt(True, doc="CSF force (eqs. 19-24)")
    plasticity: bool = _opt(True, doc="Perzyna return map (off: linear elastic)")
    thermal_strain: bool = _opt(True, doc="thermal and transformation strains (eqs. 36-37)")
    gravity_m_s2: list[float] = _opt(factory=lambda: [0.0, -9.81], doc="body force per mass")


@dataclass
class Time:
    dt_s: float | str = _opt("auto", doc='time step (s), or "auto" from the stability limits')
    end_s: float = _opt(1e-3, positive=True, doc="simulated end time (s)")
    safety: float = _opt(0.4, positive=True, doc='fraction of the stability limit for "auto"')
    allow_unstable_dt: bool = _opt(False, doc="let a fixed dt exceed the stability limit")
    heat_every: int | str = _opt(
        "auto",
        doc="conduction and laser every N mechanical steps, with a heat step of N dt (the "
        'thermal limit is ~100x the elastic one); "auto": the largest N with N dt <= '
        "heat_step_fraction x the thermal limit; 1: every step",
    )
    heat_step_fraction: float = _opt(
        0.1,
        positive=True,
        maximum=1.0,
        doc='heat step as a fraction of the thermal stability limit for heat_every = "auto"',
    )


@dataclass
class Solver:
    transfer: str = _opt(
        "pic_flip",
        choices=("apic", "flip", "pic_flip"),
        doc="apic; flip as printed (eq. 14); pic_flip: flip_ratio*FLIP + (1-flip_ratio)*PIC",
    )
    update: str = _opt(
        "usl",
        choices=("usl", "musl"),
        doc="usl: eqs. 14-17 as printed; musl: move points with the remapped grid velocity "
        "(bounded on nearly empty nodes, but slows capillary flow)",
    )
    flip_ratio: float = _opt(0.9, nonneg=True, doc="FLIP share of the pic_flip blend, in [0, 1]")
    arch: str = _opt("cpu", choices=("cpu", "gpu"), doc="Taichi backend")
    layout: str = _opt(
        "auto",
        choices=("auto", "serial", "parallel"),
        doc="serial: many steps per kernel call, loops serialized; parallel: one call per step, "
        "every stage a parallel loop; auto: serial on CPU (faster at every size measured on 2 "
        "cores, to 1M points), parallel on GPU",
    )
    active_region: bool = _opt(
        True,
        doc="grid loops only over the nodes that material has reached (plus the stencil, "
        "level-set band and smoothing margin); false: every node, every step",
    )
    precision: str = _opt("f64", choices=("f64", "f32"), doc="floating point precision")
    small_mass: float = _opt(
        1e-9, nonneg=True, doc="nodes below this fraction of a full cell's mass are skipped"
    )
    stress_reading: str = _opt(
        "model",
        choices=("model", "paper"),
        doc="model: s = 2 mu dev(eps_e), p = K tr(eps_e) (MODEL.md); paper: eq. 39 and "
        "p = lambda tr(eps) as printed",
    )
    optimize: bool = _opt(
        False,
        doc="Taichi's advanced optimisation: ~1.5x faster steps after a ~100 s one-off compile "
        "(cached on disk); false compiles in ~5-10 s",
    )
    strain: str = _opt(
        "small",
        choices=("small",),
        doc="small: accumulated eps += sym(L) dt (eqs. 16-17; not objective)",
    )


@dataclass
class Thermal:
    initial_C: float = _opt(140.0, doc="initial temperature of every body without its own")
    enthalpy_reference_C: float = _opt(0.0, doc="temperature where enthalpy is zero")


@dataclass
class Laser:
    power_W: float = _opt(25.0, nonneg=True, doc="P")
    spot_radius_um: float = _opt(50.0, positive=True, doc="r_0")
    absorptivity: float = _opt(0.85, nonneg=True, doc="A (fraction, MODEL.md reads 0.85 % as 0.85)")
    penetration_depth_um: float = _opt(100.0, positive=True, doc="eta_l")
    depth_factor: float = _opt(0.6, nonneg=True, doc="the 0.6 prefactor of eq. 31")
    on_s: float = _opt(0.0, nonneg=True, doc="switch-on time (s)")
    off_s: float = _opt(20e-6, nonneg=True, doc="switch-off time (s)")
    x_start_um: float = _opt(40.0, doc="beam centre at on_s (um)")
    speed_m_s: float = _opt(0.0, doc="scan speed along +x (m/s); 0 = stationary")
    x_end_um: float | None = _opt(None, doc="beam switches off when its centre passes this x")
    top_um: float | None = _opt(None, doc="y_l, top of the powder; default: highest body top")
    source_units: str = _opt(
        "W_per_m3",
        choices=("W_per_m3", "W_per_kg"),
        doc="eq. 31 read as W/m^3 (MODEL.md) or, as printed in eq. 3, W/kg multiplied by rho",
    )
    depth_sign: str = _opt(
        "decay",
        choices=("decay", "paper"),
        doc="decay: exp(-(y_l - y)/eta) (MODEL.md); paper: exp(+(y_l - y)/eta) as printed",
    )


@dataclass
class SurfaceTension:
    point_radius_over_h: float = _opt(
        0.375, positive=True, doc="r_p / h in eq. 21; > sqrt(2)/4 so interior nodes read inside"
    )
    band_cells: int = _opt(
        3, positive=True, maximum=8, doc="half-width of the level-set band (cells)"
    )
    level_set: str = _opt(
        "redistanced",
        choices=("redistanced", "raw"),
        doc="redistanced: signed distance to the eq. 21 zero contour; raw: eq. 21 as printed",
    )
    level_set_smoothing_passes: int = _opt(
        8, nonneg=True, maximum=64, doc="binomial smoothing passes over phi before the fit"
    )
    smoothing_passes: int = _opt(
        16, nonneg=True, maximum=64, doc="mass-weighted curvature smoothing passes"
    )
    colour_threshold: float = _opt(
        0.0,
        nonneg=True,
        maximum=0.9,
        doc="CSF acts on nodes above this fraction of a full cell's mass (0: eq. 19 as printed)",
    )
    zero_net_force: bool = _opt(
        True, doc="remove the CSF resultant left by curvature noise (mass-weighted)"
    )
    curvature_cap_h: float = _opt(
        0.5, nonneg=True, doc="|kappa| h capped here (0 = no cap); the grid resolves R >= 2h"
    )
    curvature_every: int | str = _opt(
        "auto",
        doc="rebuild level set and curvature every N steps (the CSF force uses the current mass "
        'every step); "auto": the largest N with N dt <= curvature_step_fraction x the '
        "capillary limit. A stale curvature is a delayed restoring force: every 10 steps on "
        "the paper's fine grid (N dt = the capillary limit) doubled the kinetic energy",
    )
    curvature_step_fraction: float = _opt(
        0.25,
        positive=True,
        maximum=1.0,
        doc='curvature age as a fraction of the capillary limit for curvature_every = "auto"',
    )
    initial_stress: str = _opt(
        "laplace",
        choices=("laplace", "none"),
        doc="laplace: every disc starts in equilibrium with its own surface tension (in-plane "
        "pressure gamma/R, carried by the elastic strain at its initial temperature; other "
        "shapes start stress-free); none: every body starts stress-free and its Laplace "
        "pressure compresses it once the run starts (the paper does not say)",
    )


@dataclass
class Output:
    frames: int = _opt(
        20, positive=True, maximum=100000, doc="number of output frames over the run"
    )
    png: bool = _opt(True, doc="write frames/*.png")
    gif: bool = _opt(True, doc="write animation.gif from the frames")
    vtu: bool = _opt(False, doc="write ParaView point data (points_*.vtu + points.pvd)")
    dpi: int = _opt(80, positive=True, maximum=600, doc="resolution of the frames")
    deformation: str = _opt(
        "displacement",
        choices=("displacement", "plastic_strain"),
        doc="what the right-hand panel colours the points by",
    )


VERIFICATION_KINDS = (
    "none",
    "bar",
    "steffen",
    "perzyna",
    "erf",
    "gaussian",
    "stefan",
    "energy",
    "curvature",
    "laplace",
    "square",
    "viscous_decay",
    "inviscid",
)


@dataclass
class Verification:
    """Verification cases (cases/verification/, :mod:`taichi_sls.verification`): the analytic
    comparison the case is built for and the initial conditions or loads the ordinary keys cannot
    express. Only ``bar``, ``steffen`` and ``gaussian`` change the run itself; the other kinds
    name the measure that ``python -m taichi_sls.bench accuracy`` takes."""

    kind: str = _opt("none", choices=VERIFICATION_KINDS, doc="which comparison; none: a plain case")
    velocity_amplitude_m_s: float = _opt(
        0.0,
        nonneg=True,
        doc="bar: initial x-velocity v0 sin(pi x / 2L) of body 0 (a rectangle from x = 0, L its "
        "length), the first axial mode of a bar fixed at x = 0",
    )
    displacement_amplitude_um: float = _opt(
        0.0,
        nonneg=True,
        doc="steffen: A of the manufactured displacement u = A sin(2 pi X/L) sin(pi c t/L), "
        "c = sqrt(E/rho), driven by the body force it implies (references.steffen_body_force)",
    )
    center_um: list[float] = _opt(factory=lambda: [0.0, 0.0], doc="gaussian: centre (um)")
    sigma_um: float = _opt(
        0.0, nonneg=True, doc="gaussian: initial standard deviation s0 per axis (um)"
    )
    rise_C: float = _opt(
        0.0, doc="gaussian: initial peak rise over thermal.initial_C, rise exp(-r^2 / 2 s0^2)"
    )
    shear_rate_1_s: float = _opt(
        0.0, nonneg=True, doc="perzyna: engineering shear rate of the constant-rate drive (1/s)"
    )
    hold_strain: float = _opt(
        0.0, nonneg=True, doc="perzyna: shear strain eps_xy held fixed for the relaxation check"
    )


@dataclass
class Case:
    case: CaseInfo = _opt(factory=CaseInfo)
    grid: Grid = _opt(factory=Grid)
    domain: Domain = _opt(factory=Domain)
    bodies: list[Body] = _opt(factory=list)
    materials: dict[str, Material] = _opt(factory=lambda: {"PA12": Material()})
    boundary: Boundary = _opt(factory=Boundary)
    physics: Physics = _opt(factory=Physics)
    time: Time = _opt(factory=Time)
    solver: Solver = _opt(factory=Solver)
    thermal: Thermal = _opt(factory=Thermal)
    lasers: list[Laser] = _opt(factory=list)
    surface_tension: SurfaceTension = _opt(factory=SurfaceTension)
    output: Output = _opt(factory=Output)
    verification: Verification = _opt(factory=Verification)


# --------------------------------------------------------------------------- conversion


def _type_name(tp: Any) -> str:
    return getattr(tp, "__name__", str(tp))


def _convert(value: Any, tp: Any, key: str) -> Any:
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin in (typing.Union, getattr(__import__("types"), "UnionType", None)):
        if value is None and type(None) in args:
            return None
        errors = []
        for a in args:
            if a is type(None):
                continue
            try:
                return _convert(value, a, key)
            except CaseError as e:
                errors.append(str(e))
        allowed = " or ".join(_type_name(a) for a in args if a is not type(None))
        raise CaseError(f"{key} = {value!r}: expected {allowed}")
    if dataclasses.is_dataclass(tp):
        if not isinstance(value, dict):
            raise CaseError(f"{key} = {value!r}: expected a table")
        return _build(tp, value, key)
    if origin is list:
        if not isinstance(value, list):
            raise CaseError(f"{key} = {value!r}: expected a list")
        return [_convert(v, args[0], f"{key}[{i}]") for i, v in enumerate(value)]
    if origin is dict:
        if not isinstance(value, dict):
            raise CaseError(f"{key} = {value!r}: expected a table")
        return {k: _convert(v, args[1], f"{key}.{k}") for k, v in value.items()}
    if tp is bool:
        if not isinstance(value, bool):
            raise CaseError(f"{key} = {value!r}: expected true or false")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise CaseError(f"{key} = {value!r}: expected an integer")
        return value
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise CaseError(f"{key} = {value!r}: expected a number")
        if not math.isfinite(value):
            raise CaseError(f"{key} = {value!r}: expected a finite number")
        return float(value)
    if tp is str:
        if not isinstance(value, str):
            raise CaseError(f"{key} = {value!r}: expected a string")
        return value
    raise CaseError(f"{key}: unsupported type {tp}")  # pragma: no cover


def _build(cls: type, data: dict, prefix: str) -> Any:
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - set(fields))
    if unknown:
        where = f"{prefix}.{unknown[0]}" if prefix else unknown[0]
        raise CaseError(f"unknown key {where!r}; allowed here: {', '.join(sorted(fields))}")
    kwargs = {}
    for name, value in data.items():
        key = f"{prefix}.{name}" if prefix else name
        f = fields[name]
        v = _convert(value, hints[name], key)
        meta = f.metadata
        if meta.get("choices") and v not in meta["choices"]:
            raise CaseError(f"{key} = {v!r}: allowed values are {', '.join(meta['choices'])}")
        if meta.get("positive") and isinstance(v, (int, float)) and not v > 0:
            raise CaseError(f"{key} = {v!r}: must be > 0")
        if meta.get("nonneg") and isinstance(v, (int, float)) and not v >= 0:
            raise CaseError(f"{key} = {v!r}: must be >= 0")
        if meta.get("max") is not None and isinstance(v, (int, float)) and v > meta["max"]:
            raise CaseError(f"{key} = {v!r}: must be at most {meta['max']}")
        kwargs[name] = v
    return cls(**kwargs)


def _parse_override(text: str) -> tuple[list[str], Any]:
    if "=" not in text:
        raise CaseError(f"--set {text!r}: expected section.key=value")
    path, raw = text.split("=", 1)
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw  # a bare word is a string: --set solver.transfer=flip
    parts = path.strip().split(".")
    return parts, value


def apply_override(data: dict, text: str) -> None:
    """Apply one ``section.key=value`` override to raw case data. List items: ``bodies.0.radius_um``
    or ``lasers.0.power_W``."""
    parts, value = _parse_override(text)
    node: Any = data
    for i, p in enumerate(parts[:-1]):
        if isinstance(node, list):
            if not p.isdigit() or int(p) >= len(node):
                raise CaseError(f"--set {text!r}: {'.'.join(parts[: i + 1])} is no list index")
            node = node[int(p)]
        else:
            if p not in node and parts[i + 1].isdigit():
                raise CaseError(f"--set {text!r}: {'.'.join(parts[: i + 1])} is no list")
            node = node.setdefault(p, {})
            if not isinstance(node, (dict, list)):
                raise CaseError(f"--set {text!r}: {'.'.join(parts[: i + 1])} is not a table")
    last = parts[-1]
    if isinstance(node, list):
        if not last.isdigit() or int(last) >= len(node):
            raise CaseError(f"--set {text!r}: {last!r} is no list index")
        node[int(last)] = value
    else:
        node[last] = value


def case_from_dict(data: dict) -> Case:
    """Build and validate a :class:`Case` from raw TOML data."""
    case = _build(Case, data, "")
    validate(case)
    return case


def read_toml(path: str | Path, what: str, error: type[Exception] = CaseError) -> dict:
    """Parse a TOML file, turning a missing file or bad syntax into ``error`` with the path."""
    path = Path(path)
    if not path.is_file():
        raise error(f"{what} {str(path)!r} does not exist")
    try:
        return tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as e:
        raise error(f"{path}: not valid TOML: {e}") from None


def load_case(path: str | Path, overrides: list[str] | None = None) -> Case:
    """Read a case file, apply ``--set`` overrides, validate, return the :class:`Case`."""
    path = Path(path)
    data = read_toml(path, "case file")
    for o in overrides or []:
        apply_override(data, o)
    if "case" not in data or "name" not in data.get("case", {}):
        data.setdefault("case", {})["name"] = path.stem
    return case_from_dict(data)


def _check_pair(key: str, v: list[float]) -> None:
    if len(v) != 2:
        raise CaseError(f"{key} = {v!r}: expected two numbers [x, y]")


def validate(case: Case) -> None:
    """Cross-field checks that a field type alone cannot express."""
    W, Hh = case.domain.width_um, case.domain.height_um
    h = case.grid.spacing_um
    if h > min(W, Hh) / 2:
        raise CaseError(f"grid.spacing_um = {h}: must be at most half the smaller domain side")
    cells = (W / h) * (Hh / h)
    if cells > MAX_CELLS:
        raise CaseError(
            f"grid.spacing_um = {h}: {cells:.3g} cells in a {W} x {Hh} um domain; at most "
            f"{MAX_CELLS:.0e} are allowed (memory)"
        )
    if not case.bodies:
        raise CaseError("bodies: at least one [[bodies]] table is required")
    for name, m in case.materials.items():
        key = f"materials.{name}"
        for k in ("poisson", "poisson_liquid"):
            v = getattr(m, k)
            if not -1.0 < v < 0.5:
                raise CaseError(f"{key}.{k} = {v}: must lie in (-1, 0.5)")
        if not m.crystallization_C < m.melt_C:
            raise CaseError(
                f"{key}.crystallization_C = {m.crystallization_C}: must be below "
                f"melt_C = {m.melt_C}"
            )
    eps = 1e-9 * max(W, Hh)
    for i, b in enumerate(case.bodies):
        key = f"bodies[{i}]"
        if b.material not in case.materials:
            raise CaseError(
                f"{key}.material = {b.material!r}: no such material; defined: "
                f"{', '.join(case.materials)}"
            )
        _check_pair(f"{key}.velocity_m_s", b.velocity_m_s)
        if b.shape == "disc":
            _check_pair(f"{key}.center_um", b.center_um)
            (cx, cy), r = b.center_um, b.radius_um
            r *= 1.0 + abs(b.perturbation)
            lo, hi = (cx - r, cy - r), (cx + r, cy + r)
            if not abs(b.perturbation) < 0.5:
                raise CaseError(f"{key}.perturbation = {b.perturbation}: must lie in (-0.5, 0.5)")
            if b.mode < 2:
                raise CaseError(f"{key}.mode = {b.mode}: must be an integer >= 2")
        else:
            if b.perturbation != 0.0:
                raise CaseError(
                    f"{key}.perturbation = {b.perturbation}: only a disc takes a perturbation "
                    f"(shape = {b.shape!r})"
                )
            _check_pair(f"{key}.min_um", b.min_um)
            _check_pair(f"{key}.max_um", b.max_um)
            lo, hi = tuple(b.min_um), tuple(b.max_um)
            if not (hi[0] > lo[0] and hi[1] > lo[1]):
                raise CaseError(f"{key}.max_um = {b.max_um}: must exceed min_um = {b.min_um}")
        if lo[0] < -eps or lo[1] < -eps or hi[0] > W + eps or hi[1] > Hh + eps:
            raise CaseError(
                f"{key}: extent x {lo[0]}..{hi[0]}, y {lo[1]}..{hi[1]} um lies outside the "
                f"domain 0..{W} x 0..{Hh} um"
            )
    _check_pair("physics.gravity_m_s2", case.physics.gravity_m_s2)
    dt = case.time.dt_s
    if isinstance(dt, str) and dt != "auto":
        raise CaseError(f'time.dt_s = {dt!r}: expected a positive number or "auto"')
    if isinstance(dt, float) and not dt > 0:
        raise CaseError(f"time.dt_s = {dt}: must be > 0")
    for key, v in (
        ("time.heat_every", case.time.heat_every),
        ("surface_tension.curvature_every", case.surface_tension.curvature_every),
    ):
        if (isinstance(v, str) and v != "auto") or (isinstance(v, int) and v < 1):
            raise CaseError(f'{key} = {v!r}: expected an integer >= 1 or "auto"')
    if not 0 <= case.solver.flip_ratio <= 1:
        raise CaseError(f"solver.flip_ratio = {case.solver.flip_ratio}: must lie in [0, 1]")
    for i, las in enumerate(case.lasers):
        if las.off_s < las.on_s:
            raise CaseError(f"lasers[{i}].off_s = {las.off_s}: must be >= on_s = {las.on_s}")
    _validate_verification(case)
    if case.surface_tension.point_radius_over_h <= math.sqrt(2) / 4:
        raise CaseError(
            f"surface_tension.point_radius_over_h = {case.surface_tension.point_radius_over_h}: "
            f"must exceed sqrt(2)/4 = {math.sqrt(2) / 4:.4f} (interior nodes would read outside)"
        )


def _validate_verification(case: Case) -> None:
    v = case.verification
    _check_pair("verification.center_um", v.center_um)

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
                f"x = 0 (the fixed end), got shape = {b.shape!r}, min_um = {b.min_um}"
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
    elif v.kind == "perzyna":
        need("shear_rate_1_s", v.shear_rate_1_s, "the constant-rate drive")
        need("hold_strain", v.hold_strain, "the relaxation check")


def case_to_dict(case: Case) -> dict:
    """The resolved case as plain data (None values dropped: TOML has no null)."""

    def clean(x: Any) -> Any:
        if isinstance(x, dict):
            return {k: clean(v) for k, v in x.items() if v is not None}
        if isinstance(x, list):
            return [clean(v) for v in x]
        return x

    return clean(dataclasses.asdict(case))


def to_toml(data: dict) -> str:
    """Minimal TOML writer for resolved cases (tables, arrays of tables, scalars, lists)."""
    lines: list[str] = []

    def scalar(v: Any) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (int, float)):
            return repr(v)
        if isinstance(v, str):
            return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
        if isinstance(v, list):
            return "[" + ", ".join(scalar(x) for x in v) + "]"
        raise TypeError(v)

    def table(prefix: str, d: dict, array: bool = False) -> None:
        simple = {k: v for k, v in d.items() if not isinstance(v, dict) and not _is_tables(v)}
        nested = {k: v for k, v in d.items() if k not in simple}
        if prefix:
            lines.append(f"[[{prefix}]]" if array else f"[{prefix}]")
        for k, v in simple.items():
            lines.append(f"{k} = {scalar(v)}")
        lines.append("")
        for k, v in nested.items():
            sub = f"{prefix}.{k}" if prefix else k
            if isinstance(v, dict):
                table(sub, v)
            else:
                for item in v:
                    table(sub, item, array=True)

    table("", data)
    return "\n".join(lines)


def _is_tables(v: Any) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def describe_keys() -> str:
    """Markdown reference of every key, its default and its meaning (docs/case_reference.md)."""
    out = ["# Case file reference", "", "Generated by `python -m taichi_sls.case`.", ""]
    sections = [
        ("case", CaseInfo),
        ("grid", Grid),
        ("domain", Domain),
        ("[[bodies]]", Body),
        ("materials.NAME", Material),
        ("boundary.left / right / bottom / top", Wall),
        ("physics", Physics),
        ("time", Time),
        ("solver", Solver),
        ("thermal", Thermal),
        ("[[lasers]]", Laser),
        ("surface_tension", SurfaceTension),
        ("output", Output),
        ("verification", Verification),
    ]
    for title, cls in sections:
        out += [f"## `{title}`", ""]
        if cls.__doc__ and not cls.__doc__.startswith(cls.__name__ + "("):
            out += [" ".join(cls.__doc__.split()), ""]
        out += ["| key | default | meaning |", "|---|---|---|"]
        for f in dataclasses.fields(cls):
            if f.default is not dataclasses.MISSING:
                d = f.default
            elif f.default_factory is not dataclasses.MISSING:
                d = f.default_factory()
            else:
                d = ""
            meta = f.metadata
            doc = meta.get("doc", "")
            if meta.get("choices"):
                doc += f" (one of: {', '.join(meta['choices'])})"
            out.append(f"| `{f.name}` | `{d!r}` | {doc} |")
        out.append("")
    out.append(
        'Bottom wall default: `thermal = "fixed"` at 140 C; top wall default: '
        '`mechanical = "open"`.'
    )
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    print(describe_keys(), end="")
