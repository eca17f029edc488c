"""The three process studies of a PA12 layer as sweeps on the Dask runner (docs/record/sweeps.md,
"What a process engineer reads"): the energy density (power x scan speed x hatch), the bed
temperature, and the sensitivity of the density to the uncertain inputs.

Every case starts from a base case (default ``cases/machine_layer.toml``; any hatched layer:
in 2D ``lasers.0.scan = "across"``, in 3D tracks in the bed plane, e.g.
``cases/machine_layer3d.toml``). A 2D base is made smaller by ``REDUCTION``: a 0.3 mm bed
(about 19 discs of 40 um) under two tracks centred on it, held 5 s instead of the layer's 10 s.
The density of that layer has levelled off by then (docs/record/sweeps.md has the full-length
check, which the sensitivity sweep reruns as its ``layer time`` row). A 3D base keeps its bed
and layer time (its density still rises at 5 s) and holds with the error-controlled step
(``REDUCTION_3D``); its energy sweep adds two other draws of the bed at the base's power, the
spread a 3D density is read with. Values that scale the base's own inputs (viscosity x2,
surface tension +-20 %, ...) are read from the base, so the same command reruns the studies on
another material.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...config import Bed, Case, load_case
from ...config.loading import apply_override, find_case, read_case_file
from ...jobs.sweep.spec import Sweep, SweepCase, SweepError, case_id, toml_value

DEFAULT_BASE = "cases/machine_layer.toml"
BED_WIDTH_UM = 300.0
LAYER_TIME_S = 5.0
REDUCTION: tuple[str, ...] = (
    f"bed.x_range_um=[0.0, {BED_WIDTH_UM}]",
    "lasers.0.tracks=2",
    f"time.end_s={LAYER_TIME_S}",
    "output.png=false",
    "output.gif=false",
)

# the 3D layer (48 spheres over 60 x 180 um) as bundled, its hold's step set by the error of the
# plastic strain at 3e-2: the density at 10 s moves by 0.002 against the bundled control for 262
# steps instead of 623 (docs/record/implicit.md, "strain_control = error")
REDUCTION_3D: tuple[str, ...] = (
    "time.strain_control=error",
    "time.max_strain_error=3e-2",
    "output.png=false",
    "output.gif=false",
)

# (power W, scan speed m/s, hatch um): Andrew numbers P / (v h) from 0.0125 to 0.06 J/mm^2;
# 20 W at 0.1 mm and 40 W at 0.2 mm share 0.025 J/mm^2, a check that the number alone decides
ENERGY_POINTS: tuple[tuple[float, float, float], ...] = (
    (10.0, 8.0, 100.0),
    (15.0, 8.0, 100.0),
    (25.0, 8.0, 150.0),
    (20.0, 8.0, 100.0),
    (40.0, 8.0, 200.0),
    (25.0, 8.0, 100.0),
    (25.0, 6.0, 100.0),
    (30.0, 5.0, 100.0),
)
# 3D: power alone at the base's speed and hatch (the 180 um bed holds two tracks 100 um apart),
# Andrew numbers 0.0125-0.044 J/mm^2 (50 W, 0.0625, stalled in its scan: docs/record/sweeps.md)
ENERGY_POWERS_3D_W: tuple[float, ...] = (10.0, 15.0, 20.0, 25.0, 35.0)
OTHER_SEEDS_3D = 2  # other draws of the bed at the base's power: the spread over beds

# around the crystallisation range on cooling (145-150 C in machine_layer) up to the bed's 172 C
BED_TEMPERATURES_C: tuple[float, ...] = (140.0, 145.0, 148.0, 150.0, 155.0, 163.0, 172.0)
BED_TEMPERATURE_KEYS = ("thermal.initial_C", "thermal.chamber_C", "boundary.bottom.temperature_C")
# the prefactor that scales a material's melt viscosity under each viscosity_model
VISCOSITY_PREFACTOR = {
    "exponential": "viscosity_A_Pas",
    "constant": "viscosity_Pas",
    "arrhenius": "viscosity_ref_Pas",  # the law is proportional to its value at the reference
}

COLLECT = [
    "bed.relative_density.initial",
    "bed.relative_density.final",
    "bed.fused_fraction",
    "bed.melted_through",
    "bed.still_molten",
    "bed.melt_depth_um",
    "T_peak_C",
    "steps",
    "status",
]


@dataclass(frozen=True)
class Factor:
    """One uncertain input of the sensitivity: its label and the overrides of its two levels."""

    label: str
    low: tuple[str, dict[str, Any]]  # (level label, {key: value})
    high: tuple[str, dict[str, Any]]


def _g(x: float) -> float:
    """``x`` to 6 significant digits: scaled inputs read as written (0.04116, not 0.0411599...)."""
    return float(f"{x:.6g}")


def andrew_J_mm2(power_W: float, speed_m_s: float, hatch_um: float) -> float:
    """Andrew number P / (v h), incident energy per area (J/mm^2)."""
    return power_W / (speed_m_s * 1e3 * hatch_um * 1e-3)


def load_base(base: str | Path, extra_set: Sequence[str] = ()) -> tuple[Case, Bed]:
    """The base case with ``extra_set`` and its [bed] table (the loaded case has made the bed's
    particles bodies); refused unless its first laser scans hatches over a generated bed (2D:
    ``scan = "across"``; 3D: tracks in the bed plane, the bed's range across them given)."""
    data = _base_data(base, extra_set)
    lasers = data.get("lasers") or [{}]
    if _dim_of(data) == 2 and lasers[0].get("scan") != "across":
        raise SweepError(
            f"base {base}: lasers.0.scan must be 'across' (a hatched layer, e.g. "
            f"{DEFAULT_BASE}); the process studies sweep its power, speed and hatch"
        )
    if "bed" not in data:
        raise SweepError(f"base {base}: needs a [bed] (its sizes are swept)")
    bed = Bed.model_validate(data["bed"])
    case = load_case(base, list(extra_set))
    key = _across_range_key(case)
    if getattr(bed, key) is None:
        raise SweepError(f"base {base}: needs bed.{key} (the bed across its tracks)")
    return case, bed


def _base_data(base: str | Path, extra_set: Sequence[str] = ()) -> dict[str, Any]:
    """The base case file's table with ``extra_set`` applied (not validated)."""
    data = read_case_file(find_case(base))
    for text in extra_set:
        apply_override(data, text)
    return data


def _dim_of(data: dict[str, Any]) -> int:
    return int((data.get("domain") or {}).get("dim", 2))


def base_dim(base: str | Path, extra_set: Sequence[str] = ()) -> int:
    """The base case's ``domain.dim``, read from its file."""
    return _dim_of(_base_data(base, extra_set))


def _across_range_key(case: Case) -> str:
    """The [bed] range across the tracks: x in 2D and for 3D tracks along z, else z."""
    if case.domain.dim == 3 and case.lasers[0].direction == "x":
        return "z_range_um"
    return "x_range_um"


def _start_key(case: Case) -> str:
    """The override that places the first track across the bed."""
    return f"lasers.0.{_across_range_key(case)[0]}_start_um"


def _reduction(case_path: Path, reduction: Sequence[str] | None) -> Sequence[str]:
    """``reduction``, or the base dimension's own (``REDUCTION`` in 2D, ``REDUCTION_3D``)."""
    if reduction is not None:
        return reduction
    return REDUCTION_3D if base_dim(case_path) == 3 else REDUCTION


def _tracks_start(tracks: int, hatch_um: float, width_um: float) -> float:
    """x of the first track (um) so that the tracks are centred on the bed."""
    return 0.5 * width_um - 0.5 * (tracks - 1) * hatch_um


def _make(
    name: str,
    base: Path,
    settings: list[tuple[dict[str, Any], dict[str, Any]]],
    common: Sequence[str],
) -> Sweep:
    """A Sweep of (params, overrides) pairs; ``common`` overrides come first in every case."""
    path = find_case(base).resolve()
    # the ids hash the base's contents too: a base whose material changed reruns in the same OUT
    text = f"{base}@{hashlib.sha1(path.read_bytes()).hexdigest()[:10]}"
    sweep = Sweep(name=name, base=path, base_text=text, collect=COLLECT, keys=[])
    seen = set()
    for params, values in settings:
        overrides = list(common) + [f"{k}={toml_value(v)}" for k, v in values.items()]
        cid = case_id(text, overrides)
        if cid in seen:
            continue
        seen.add(cid)
        for k in params:
            if k not in sweep.keys:
                sweep.keys.append(k)
        sweep.cases.append(SweepCase(cid, overrides, dict(params)))
    return sweep


def energy_sweep(
    base: Path,
    extra_set: Sequence[str] = (),
    points: Sequence[tuple[float, float, float]] | None = None,
    reduction: Sequence[str] | None = None,
) -> Sweep:
    """Final density against the Andrew number: each (P, v, h) of ``points`` on the reduced
    layer, its tracks centred on the bed whatever the hatch. Default points: ``ENERGY_POINTS``
    in 2D; in 3D ``ENERGY_POWERS_3D_W`` at the base's speed and hatch, then the base's power on
    ``OTHER_SEEDS_3D`` other draws of the bed (the rows' ``seed``)."""
    reduction = _reduction(base, reduction)
    case, bed = load_base(base, [*reduction, *extra_set])
    las = case.lasers[0]
    three_d = case.domain.dim == 3
    if points is None:
        points = (
            [(P, las.speed_m_s, las.hatch_um) for P in ENERGY_POWERS_3D_W]
            if three_d
            else ENERGY_POINTS
        )
    lo, width = _across(case, bed)
    settings = []
    for P, v, h in points:
        params: dict[str, Any] = {
            "power_W": P,
            "speed_m_s": v,
            "hatch_um": h,
            "andrew_J_mm2": andrew_J_mm2(P, v, h),
        }
        if three_d:
            params["seed"] = bed.seed
        values = {
            "lasers.0.power_W": P,
            "lasers.0.speed_m_s": v,
            "lasers.0.hatch_um": h,
            _start_key(case): lo + _tracks_start(las.tracks, h, width),
        }
        settings.append((params, values))
    if three_d and points:
        P, v, h = las.power_W, las.speed_m_s, las.hatch_um
        start = {_start_key(case): lo + _tracks_start(las.tracks, h, width)}
        for k in range(1, OTHER_SEEDS_3D + 1):
            params = {"power_W": P, "speed_m_s": v, "hatch_um": h}
            params |= {"andrew_J_mm2": andrew_J_mm2(P, v, h), "seed": bed.seed + k}
            settings.append((params, {**start, "bed.seed": bed.seed + k}))
    return _make("density_energy", base, settings, [*reduction, *extra_set])


def bed_temperature_sweep(
    base: Path,
    extra_set: Sequence[str] = (),
    temperatures_C: Sequence[float] = BED_TEMPERATURES_C,
    reduction: Sequence[str] | None = None,
) -> Sweep:
    """Final density against the bed temperature: powder, plate and chamber set together."""
    reduction = _reduction(base, reduction)
    case, bed = load_base(base, [*reduction, *extra_set])
    start = _start_of(case, bed)
    settings = [
        ({"bed_C": T}, {**start, **dict.fromkeys(BED_TEMPERATURE_KEYS, T)}) for T in temperatures_C
    ]
    return _make("bed_temperature", base, settings, [*reduction, *extra_set])


def _across(case: Case, bed: Bed) -> tuple[float, float]:
    """The bed's start and width across its tracks (um)."""
    lo, hi = getattr(bed, _across_range_key(case))
    return lo, hi - lo


def _start_of(case: Case, bed: Bed) -> dict[str, float]:
    """The override that centres the base's own tracks on the bed."""
    las = case.lasers[0]
    lo, width = _across(case, bed)
    return {_start_key(case): lo + _tracks_start(las.tracks, las.hatch_um, width)}


def factors(case: Case, bed: Bed) -> list[Factor]:
    """The uncertain inputs of ``case`` and their two levels: melt viscosity x2 and /2, surface
    tension and absorptivity +-20 %, bed temperature +-3 K, median particle diameter +-20 %,
    and two other beds of the same sizes (other seeds: the noise a bed's draw brings)."""
    name = bed.material
    mat = case.materials[name]
    key = VISCOSITY_PREFACTOR.get(mat.viscosity_model)
    if key is None:
        raise SweepError(
            f"materials.{name}.viscosity_model = {mat.viscosity_model!r}: the sensitivity scales "
            f"{', '.join(f'{k} ({v})' for k, v in VISCOSITY_PREFACTOR.items())}"
        )
    m = f"materials.{name}."
    eta, gamma = getattr(mat, key), mat.surface_tension_N_m
    A = case.lasers[0].absorptivity
    T = case.thermal.initial_C
    d, seed = bed.median_diameter_um, bed.seed
    return [
        Factor("viscosity x2 / 2", ("/2", {m + key: _g(eta / 2)}), ("x2", {m + key: _g(eta * 2)})),
        Factor(
            "surface tension +-20 %",
            ("-20 %", {m + "surface_tension_N_m": _g(0.8 * gamma)}),
            ("+20 %", {m + "surface_tension_N_m": _g(1.2 * gamma)}),
        ),
        Factor(
            "absorptivity +-20 %",
            ("-20 %", {"lasers.0.absorptivity": _g(0.8 * A)}),
            ("+20 %", {"lasers.0.absorptivity": _g(1.2 * A)}),
        ),
        Factor(
            "bed temperature +-3 K",
            ("-3 K", dict.fromkeys(BED_TEMPERATURE_KEYS, T - 3.0)),
            ("+3 K", dict.fromkeys(BED_TEMPERATURE_KEYS, T + 3.0)),
        ),
        Factor(
            "median diameter +-20 %",
            ("-20 %", {"bed.median_diameter_um": _g(0.8 * d)}),
            ("+20 %", {"bed.median_diameter_um": _g(1.2 * d)}),
        ),
        Factor(
            "another bed (seed)",
            (f"seed {seed + 1}", {"bed.seed": seed + 1}),
            (f"seed {seed + 2}", {"bed.seed": seed + 2}),
        ),
    ]


def sensitivity_sweep(
    base: Path,
    extra_set: Sequence[str] = (),
    reduction: Sequence[str] | None = None,
    full_layer_time: bool = True,
) -> Sweep:
    """The reference (the reduced base), each factor at its two levels, and (with
    ``full_layer_time``, where the reduction shortens it) the reference held for the base's own
    layer time: the plateau check."""
    reduction = _reduction(base, reduction)
    case, bed = load_base(base, [*reduction, *extra_set])
    start = _start_of(case, bed)
    settings: list[tuple[dict[str, Any], dict[str, Any]]] = [
        ({"factor": "reference", "level": "reference"}, dict(start))
    ]
    for f in factors(case, bed):
        for level, values in (f.low, f.high):
            settings.append(({"factor": f.label, "level": level}, {**start, **values}))
    end = load_base(base, list(extra_set))[0].time.end_s if full_layer_time else case.time.end_s
    if end != case.time.end_s:  # a 3D base is held its own layer time already
        settings.append(
            ({"factor": "layer time", "level": f"{end:g} s"}, {**start, "time.end_s": end})
        )
    return _make("sensitivity", base, settings, [*reduction, *extra_set])


STUDIES = {
    "energy": energy_sweep,
    "bed": bed_temperature_sweep,
    "sensitivity": sensitivity_sweep,
}
