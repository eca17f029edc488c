"""``taichi-sls bench process``: the three process studies of a PA12 layer in one command, on the
Dask sweep runner (docs/record/sweeps.md, "What a process engineer reads").

    taichi-sls bench process [--base CASE] [--only energy bed sensitivity] [--out DIR]
                             [--figures DIR] [--workers N] [--scheduler ADDRESS] [--set K=V ...]
                             [--retry] [--plot-only] [--no-progress]

Each study is a sweep (:mod:`.design`) whose rows go to ``OUT/<sweep>/results.csv`` as they
finish (a rerun skips finished cases, as ``taichi-sls sweep`` does); then ``OUT/process.json``
holds the summaries (:mod:`.summary`) and ``density_energy.png``, ``bed_temperature.png`` and
``density_sensitivity.png`` are drawn into ``--figures`` (default OUT; another folder also
gets the results tables as ``<sweep>.csv`` and the summaries as ``process_study.json``). A 3D
base (``cases/machine_layer3d.toml``) names them with ``_3d`` (``density_energy_3d.png``, ...).
``--base`` names another hatched layer (another material, say): the sweeps scale that case's
own inputs.
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import sys
from pathlib import Path
from typing import Any

from ...config import CaseError
from ...config.loading import add_set_argument
from ...jobs.sweep.spec import SweepError
from . import plots, summary
from .design import DEFAULT_BASE, STUDIES, base_dim, load_base
from .measured import MeasuredDataError, MeasuredPoint, load_measured

SWEEP_NAMES = {"energy": "density_energy", "bed": "bed_temperature", "sensitivity": "sensitivity"}


def _marks(base: str, extra_set: list[str]) -> dict[str, Any]:
    """The base material's crystallisation range on cooling and melting onset on heating."""
    case, bed = load_base(base, extra_set)
    mat = case.materials[bed.material]
    rng = getattr(mat, "crystallization_range_C", None)
    return {
        "crystallization_range_C": list(rng) if rng else None,
        "melt_onset_C": getattr(mat, "crystallization_C", None),
        "machine_C": (168.0, 175.0),
    }


def measured_parts(
    measured: list[MeasuredPoint],
) -> tuple[list[MeasuredPoint], list[tuple[str, float, float]]]:
    """The measured part and powder of ``data/pa12`` beside a 3D layer: the part's Archimedes
    porosity as a line, its porosity by pycnometry and micrographs as a band (1 - porosity), and
    the powder as spread as a band over the consolidated (data sheet) and the bulk density (the
    largest ``relative_to`` of ``measured``, the file's dense reference)."""
    from ..validation.measured import load_densities

    records = load_densities()
    porosity = [r for r in records if r.quantity == "part porosity" and r.unit == "%"]

    def author(source: str) -> str:  # "Westphal & Seitz, <journal>, Table 7": the authors
        return source.split(", ", 1)[0]

    lines = [
        MeasuredPoint(
            source=f"{author(r.source)} ({r.source[len(author(r.source)) + 2 :]})",
            where=r.specimen,
            kind=f"{r.method}, porosity {r.value:g} %",
            material="PA12",
            process="laser sintering",
            energy_J_mm2=None,
            density_g_cm3=1.0 - r.value / 100.0,
            relative_to_g_cm3=1.0,
            note="",
        )
        for r in porosity
        if r.method == "Archimedes"
    ]
    bands = []
    for source in dict.fromkeys(r.source for r in porosity):  # a band per source, in file order
        closed = [
            1.0 - r.value / 100.0
            for r in porosity
            if r.source == source and r.method != "Archimedes"
        ]
        if closed:
            label = f"{author(source)}: a part, pycnometry and micrographs"
            bands.append((label, min(closed), max(closed)))
    g_cm3 = {"g/cm3": 1.0, "kg/m3": 1e-3}
    by_quantity = {
        q: [r.value * g_cm3[r.unit] for r in records if r.quantity == q and r.unit in g_cm3]
        for q in ("powder density as spread", "consolidated density")
    }
    powder, solid = by_quantity["powder density as spread"], by_quantity["consolidated density"]
    if powder and solid and measured:
        bulk = max(p.relative_to_g_cm3 for p in measured)
        lo, hi = powder[0] / bulk, powder[0] / min(solid)
        bands.append(("powder as spread, over the bulk and the consolidated density", lo, hi))
    return lines, bands


def _clean(v: Any) -> Any:
    """JSON-safe: NaN as null, containers recursively."""
    if isinstance(v, float) and math.isnan(v):
        return None
    if isinstance(v, dict):
        return {k: _clean(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_clean(x) for x in v]
    return v


def report(
    out: Path,
    figures: Path,
    base: str,
    extra_set: list[str],
    ids: dict[str, set[str]] | None = None,
) -> dict[str, Any]:
    """Summaries of whichever sweeps have results in ``out`` (of the cases ``ids[study]`` only,
    when given), their figures drawn into ``figures``; written to ``out/process.json`` and
    returned."""
    ids = ids or {}
    result: dict[str, Any] = {"base": base, "set": extra_set, "figures": []}
    dim = base_dim(base, extra_set)
    tag = "" if dim == 2 else f"_{dim}d"  # a 3D base's figures and tables beside the 2D ones
    csv = {k: out / name / "results.csv" for k, name in SWEEP_NAMES.items()}
    if csv["energy"].is_file():
        rows = summary.energy_summary(csv["energy"], ids.get("energy"))
        keep = ("power_W", "speed_m_s", "hatch_um", "andrew_J_mm2", "seed", summary.INITIAL)
        result["energy"] = [
            {k: r[k] for k in (*keep, summary.FINAL, "gain", "bed.fused_fraction") if k in r}
            for r in rows
        ]
        measured, bands = load_measured(), []
        if dim == 3:
            lines, bands = measured_parts(measured)
            measured += lines
        png = plots.plot_density_energy(
            rows, measured, figures / f"density_energy{tag}.png", dim=dim, bands=bands
        )
        result["figures"].append(str(png))
    if csv["bed"].is_file():
        bed = summary.bed_summary(csv["bed"], ids.get("bed"))
        result["bed_temperature"] = {
            "threshold_C": bed["threshold_C"],
            "rows": [{k: r[k] for k in ("bed_C", summary.FINAL, "gain")} for r in bed["rows"]],
        }
        png = plots.plot_bed_temperature(
            bed, _marks(base, extra_set), figures / f"bed_temperature{tag}.png"
        )
        result["figures"].append(str(png))
    if csv["sensitivity"].is_file():
        sens = summary.sensitivity_summary(csv["sensitivity"], ids.get("sensitivity"))
        result["sensitivity"] = sens
        if sens["reference"] is not None:
            png = plots.plot_sensitivity(sens, figures / f"density_sensitivity{tag}.png")
            result["figures"].append(str(png))
    out.mkdir(parents=True, exist_ok=True)
    text = json.dumps(_clean(result), indent=1) + "\n"
    (out / "process.json").write_text(text)
    if figures.resolve() != out.resolve():  # the tables beside the figures, for committing
        for k, name in SWEEP_NAMES.items():
            if csv[k].is_file():
                shutil.copyfile(csv[k], figures / f"{name}{tag}.csv")
        (figures / f"process_study{tag}.json").write_text(text)
    return result


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser(
        "process",
        help="a PA12 layer's density against energy density, bed temperature, and its "
        "sensitivities (three Dask sweeps)",
    )
    ap.add_argument(
        "--base", default=DEFAULT_BASE, help=f"hatched layer case (default {DEFAULT_BASE})"
    )
    ap.add_argument(
        "--only", nargs="+", choices=list(STUDIES), default=list(STUDIES), help="studies to run"
    )
    ap.add_argument("--out", default="out/process", help="results folder (default out/process)")
    ap.add_argument("--figures", help="folder for the PNGs (default: --out)")
    ap.add_argument("--workers", type=int, default=2, help="local worker processes (default 2)")
    ap.add_argument("--scheduler", metavar="ADDRESS", help="running Dask scheduler")
    add_set_argument(ap, "override for every case of every study (changes the ids)")
    ap.add_argument("--retry", action="store_true", help="rerun rows not complete")
    ap.add_argument("--plot-only", action="store_true", help="summaries and figures only")
    ap.add_argument("--no-progress", action="store_true", help="no progress bar")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    from ...jobs.sweep.runner import run_sweep

    out = Path(args.out)
    figures = Path(args.figures) if args.figures else out
    extra = list(args.set or [])
    if args.workers < 1:
        print(f"error: --workers {args.workers}: must be at least 1", file=sys.stderr)
        return 2
    try:
        sweeps = [STUDIES[name](Path(args.base), extra) for name in args.only]
        ids = {name: {c.id for c in sw.cases} for name, sw in zip(args.only, sweeps, strict=True)}
    except (SweepError, CaseError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if not args.plot_only:
        for sweep in sweeps:
            try:
                run_sweep(
                    sweep,
                    out / sweep.name,
                    scheduler=args.scheduler,
                    workers=args.workers,
                    retry=args.retry,
                    progress=not args.no_progress,
                )
            except KeyboardInterrupt:
                print("interrupted; finished cases are in results.csv", file=sys.stderr)
                return 130
    try:
        result = report(out, figures, args.base, extra, None if args.plot_only else ids)
    except MeasuredDataError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    for p in result["figures"]:
        print(f"wrote {p}", file=sys.stderr)
    print(f"wrote {out / 'process.json'}", file=sys.stderr)
    return 0
