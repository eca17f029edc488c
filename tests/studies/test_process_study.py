"""The process studies' machinery (taichi_sls/studies/process): the measured-density file and its
loader, the sweeps' design read from the base case, the summaries and figures, and a tiny energy
sweep run on the Dask runner end to end (the full studies: docs/record/sweeps.md, run by hand)."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import pytest

from taichi_sls.cli import main as cli_main
from taichi_sls.config import load_case
from taichi_sls.jobs.sweep.runner import run_sweep
from taichi_sls.jobs.sweep.spec import SweepError
from taichi_sls.studies.process import plots
from taichi_sls.studies.process.design import (
    BED_TEMPERATURE_KEYS,
    BED_WIDTH_UM,
    ENERGY_POWERS_3D_W,
    VISCOSITY_PREFACTOR,
    bed_temperature_sweep,
    energy_sweep,
    sensitivity_sweep,
)
from taichi_sls.studies.process.measured import MeasuredDataError, load_measured
from taichi_sls.studies.process.study import measured_parts, report
from taichi_sls.studies.process.summary import bed_summary, sensitivity_summary

ROOT = Path(__file__).resolve().parents[2]
BASE = ROOT / "cases" / "machine_layer.toml"
BASE_3D = ROOT / "cases" / "machine_layer3d.toml"


def _overrides(case) -> dict[str, str]:
    return dict(o.split("=", 1) for o in case.overrides)


# --- the measured points --------------------------------------------------------------------


def test_the_bundled_points_load_with_their_sources():
    points = load_measured()
    assert len(points) >= 1
    assert all(p.source and p.where and p.kind for p in points)
    eos = next(p for p in points if p.source.startswith("EOS PA 2200"))
    assert eos.relative_density == pytest.approx(0.93 / 1.01, rel=1e-12)
    assert eos.energy_J_mm2 is None  # the data sheet gives no energy density
    assert eos.label == "EOS PA 2200 safety data sheet"


def _write(path: Path, rows: list[dict[str, str]]) -> Path:
    cols = list(rows[0])
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        w.writerows(rows)
    return path


GOOD = {
    "source": "A. Author 2020 (J. X)",
    "where": "Table 2",
    "kind": "table",
    "material": "PA12",
    "process": "LS",
    "energy_density_J_mm2": "0.03",
    "density_g_cm3": "0.95",
    "relative_to_g_cm3": "1.01",
    "note": "",
}


def test_a_point_without_a_source_or_beyond_the_solid_is_refused(tmp_path):
    assert load_measured(_write(tmp_path / "ok.csv", [GOOD]))[0].energy_J_mm2 == 0.03
    with pytest.raises(MeasuredDataError, match="line 2: source is empty"):
        load_measured(_write(tmp_path / "a.csv", [{**GOOD, "source": " "}]))
    with pytest.raises(MeasuredDataError, match=r"density_g_cm3 = 1.2: must lie in \(0, "):
        load_measured(_write(tmp_path / "b.csv", [{**GOOD, "density_g_cm3": "1.2"}]))
    with pytest.raises(MeasuredDataError, match="energy_density_J_mm2 = 'x'"):
        load_measured(_write(tmp_path / "c.csv", [{**GOOD, "energy_density_J_mm2": "x"}]))
    bad = tmp_path / "e.csv"
    bad.write_text(",".join(GOOD) + "\nA,Table 1,data sheet, quoted,PA12,LS,,0.9,1.01,\n")
    with pytest.raises(MeasuredDataError, match="line 2: 9 columns expected"):
        load_measured(bad)
    no_kind = {k: v for k, v in GOOD.items() if k != "kind"}
    with pytest.raises(MeasuredDataError, match="no column 'kind'"):
        load_measured(_write(tmp_path / "d.csv", [no_kind]))


# --- the design, read from the base ---------------------------------------------------------


def test_the_energy_sweep_spans_the_andrew_numbers_with_centred_tracks():
    sweep = energy_sweep(BASE)
    andrew = [c.params["andrew_J_mm2"] for c in sweep.cases]
    assert min(andrew) <= 0.0125 and max(andrew) >= 0.06 and len(andrew) >= 6
    for c in sweep.cases:
        o = _overrides(c)
        P, v, h = c.params["power_W"], c.params["speed_m_s"], c.params["hatch_um"]
        assert c.params["andrew_J_mm2"] == pytest.approx(P / (v * 1e3 * h * 1e-3))
        # two tracks centred on the reduced bed, whatever the hatch
        assert float(o["lasers.0.x_start_um"]) + 0.5 * h == pytest.approx(0.5 * BED_WIDTH_UM)
        assert float(o["lasers.0.hatch_um"]) == h


def test_the_3d_energy_sweep_sweeps_power_over_the_bundled_layer_and_draws_other_beds():
    sweep = energy_sweep(BASE_3D)
    base = load_case(BASE_3D)
    las = base.lasers[0]
    energies = [c for c in sweep.cases if c.params["seed"] == 1]
    assert [c.params["power_W"] for c in energies] == list(ENERGY_POWERS_3D_W)
    andrew = [c.params["andrew_J_mm2"] for c in energies]
    assert len(andrew) >= 5 and min(andrew) <= 0.0125 and max(andrew) >= 0.04
    for c in sweep.cases:
        o = _overrides(c)
        # the bed and layer time as bundled, the hold's step by its error
        assert "bed.x_range_um" not in o and "time.end_s" not in o
        assert o["time.strain_control"] == "error"
        # the two tracks centred across the 180 um bed: z = 40 and 140 um as bundled
        assert float(o["lasers.0.z_start_um"]) == pytest.approx(las.z_start_um)
        assert "lasers.0.x_start_um" not in o
    draws = [c for c in sweep.cases if c.params["seed"] != 1]
    assert [c.params["seed"] for c in draws] == [2, 3]
    for c in draws:
        assert _overrides(c)["bed.seed"] == str(c.params["seed"])
        assert c.params["power_W"] == las.power_W
        assert "lasers.0.power_W" not in _overrides(c)  # the base's own
    # the 3D sensitivity: the same bed draws, no plateau row (the layer time is the base's)
    factors = {c.params["factor"] for c in sensitivity_sweep(BASE_3D).cases}
    assert "another bed (seed)" in factors and "layer time" not in factors


def test_the_3d_density_figure_sets_the_measured_part_and_powder_beside_it(tmp_path):
    lines, bands = measured_parts(load_measured())
    # Westphal & Seitz, Table 7 (data/pa12): the cuboid's porosity 1.15-2.96 % by pycnometry and
    # micrographs, 11.45 % by Archimedes; the powder 463 kg/m3 over 1,010 (bulk) and 950
    assert [round(p.relative_density, 4) for p in lines] == [0.8855]
    assert bands[0][1:] == pytest.approx((1 - 0.0296, 1 - 0.0115), abs=1e-12)
    assert bands[1][1:] == pytest.approx((0.463 / 1.01, 0.463 / 0.950), abs=1e-12)
    rows = [
        _row(0.70 + 0.01 * k, power_W=P, speed_m_s=8.0, hatch_um=100.0, seed=1)
        for k, P in enumerate(ENERGY_POWERS_3D_W)
    ]
    rows += [_row(0.72, power_W=25.0, speed_m_s=8.0, hatch_um=100.0, seed=s) for s in (2, 3)]
    for r in rows:
        r["andrew_J_mm2"] = r["power_W"] / (8.0 * 100.0)
    out = tmp_path / "out"
    _results(out / "density_energy" / "results.csv", rows)
    result = report(out, tmp_path / "figs", str(BASE_3D), [])
    # by Andrew number, then seed; the seed kept in the summary
    order = [(r["power_W"], r["seed"]) for r in result["energy"]]
    assert order[order.index((25.0, 1)) :][:3] == [(25.0, 1), (25.0, 2), (25.0, 3)]
    assert len(order) == len(rows)
    assert (tmp_path / "figs" / "density_energy_3d.png").stat().st_size > 20_000
    assert (tmp_path / "figs" / "density_energy_3d.csv").is_file()
    assert not (tmp_path / "figs" / "density_energy.png").exists()


def test_the_sensitivity_scales_the_bases_own_values():
    base = load_case(BASE)
    mat = base.materials["PA12"]
    sweep = sensitivity_sweep(BASE)
    by = {(c.params["factor"], c.params["level"]): _overrides(c) for c in sweep.cases}
    # the bundled base's process preset: an Arrhenius law, scaled by its reference viscosity
    assert mat.viscosity_model == "arrhenius"
    key = "materials.PA12." + VISCOSITY_PREFACTOR[mat.viscosity_model]
    assert float(by[("viscosity x2 / 2", "x2")][key]) == pytest.approx(2 * mat.viscosity_ref_Pas)
    gamma = float(by[("surface tension +-20 %", "-20 %")]["materials.PA12.surface_tension_N_m"])
    assert gamma == pytest.approx(0.8 * mat.surface_tension_N_m)
    warm = by[("bed temperature +-3 K", "+3 K")]
    assert {float(warm[k]) for k in BED_TEMPERATURE_KEYS} == {base.thermal.initial_C + 3.0}
    assert float(by[("layer time", f"{base.time.end_s:g} s")]["time.end_s"]) == base.time.end_s
    # another material's base: the same command scales its values
    other = sensitivity_sweep(BASE, [f"{key}=1000.0"])
    o = {(c.params["factor"], c.params["level"]): _overrides(c) for c in other.cases}
    assert float(o[("viscosity x2 / 2", "/2")][key]) == 500.0


def test_the_bed_sweep_sets_powder_plate_and_chamber_together():
    for c in bed_temperature_sweep(BASE).cases:
        o = _overrides(c)
        assert {float(o[k]) for k in BED_TEMPERATURE_KEYS} == {c.params["bed_C"]}


def test_a_base_that_scans_no_hatches_is_refused():
    with pytest.raises(SweepError, match="lasers.0.scan must be 'across'"):
        energy_sweep(ROOT / "cases" / "bed_track.toml")


# --- summaries and figures from results tables ----------------------------------------------


def _results(path: Path, rows: list[dict]) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    cols = list(rows[0])
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        w.writerows(rows)
    return path


def _row(final: float, **params) -> dict:
    return {
        **params,
        "bed.relative_density.initial": 0.83,
        "bed.relative_density.final": final,
        "bed.fused_fraction": 0.0,
        "status": "complete",
        "error": "",
    }


def test_bed_threshold_and_sensitivity_order(tmp_path):
    finals = {140: 0.830, 145: 0.831, 150: 0.845, 160: 0.850, 172: 0.852}
    bed = _results(tmp_path / "b.csv", [_row(f, bed_C=T) for T, f in finals.items()])
    s = bed_summary(bed)
    assert s["threshold_C"] == 150  # the first of the beds gaining >= half the hottest's 0.022
    rows = [
        _row(0.850, factor="reference", level="reference"),
        _row(0.851, factor="small", level="lo"),
        _row(0.849, factor="small", level="hi"),
        _row(0.840, factor="large", level="lo"),
        _row(0.853, factor="large", level="hi"),
        _row(0.8505, factor="layer time", level="10 s"),
        {**_row(0.86, factor="odd", level="+20 %"), "status": "failed", "error": "J = 71.6"},
    ]
    sens = sensitivity_summary(_results(tmp_path / "s.csv", rows))
    assert [f["factor"] for f in sens["factors"]] == ["large", "small", "odd"]
    assert sens["factors"][2] == {
        "factor": "odd",
        "changes": {},
        "gain_changes": {},
        "failed": {"+20 %": "failed: J = 71.6"},
    }
    assert sens["factors"][0]["changes"]["lo"] == pytest.approx(-0.010)
    assert sens["plateau"]["change"] == pytest.approx(0.0005)
    png = plots.plot_sensitivity(sens, tmp_path / "tornado.png")
    assert png.stat().st_size > 10_000
    marks = {"crystallization_range_C": [145.0, 150.0], "melt_onset_C": 175.0}
    png = plots.plot_bed_temperature(s, marks, tmp_path / "bed.png")
    assert png.stat().st_size > 10_000


# --- a tiny energy sweep on the Dask runner, end to end -------------------------------------

TINY = [
    "bed.x_range_um=[0.0, 120.0]",
    "bed.layers=1.5",
    "lasers.0.tracks=2",
    "time.end_s=2e-3",
    "output.png=false",
    "output.gif=false",
]


# slow: four runs on Dask (~25 s); the sweep runner's own runs stay in default (test_sweep.py)
@pytest.mark.slow
def test_a_tiny_energy_sweep_runs_and_draws_beside_the_measured_points(tmp_path):
    sweep = energy_sweep(BASE, points=[(10.0, 8.0, 80.0), (25.0, 8.0, 80.0)], reduction=TINY)
    out = tmp_path / "process"
    rows = run_sweep(sweep, out / "density_energy", workers=1, progress=False)
    assert [r["status"] for r in rows] == ["complete", "complete"], rows
    for r in rows:
        assert 0.5 < r["bed.relative_density.initial"] < 1.0
        assert 0.5 < r["bed.relative_density.final"] < 1.0
    assert sorted(r["andrew_J_mm2"] for r in rows) == pytest.approx([0.015625, 0.0390625])
    result = report(out, tmp_path / "figs", str(BASE), [])
    png = tmp_path / "figs" / "density_energy.png"
    assert str(png) in result["figures"]
    assert 20_000 < png.stat().st_size < 2_000_000
    saved = json.loads((out / "process.json").read_text())
    assert [r["power_W"] for r in saved["energy"]] == [10.0, 25.0]
    # the command line draws the same from the results alone
    code = cli_main(["bench", "process", "--out", str(out), "--plot-only", "--only", "energy"])
    assert code == 0 and (out / "density_energy.png").is_file()


def test_the_ids_follow_the_bases_contents(tmp_path):
    # a rerun on a changed material must not reuse the old rows of the same OUT
    copy = tmp_path / "layer.toml"
    copy.write_text(BASE.read_text())
    ids = [c.id for c in bed_temperature_sweep(copy).cases]
    assert ids == [c.id for c in bed_temperature_sweep(copy).cases]  # stable
    text, n = re.subn(
        r'(?m)^preset = "pa12_process".*$',
        'preset = "pa12_process"\nsurface_tension_N_m = 0.030',
        copy.read_text(),
    )
    assert n == 1
    copy.write_text(text)
    assert not set(ids) & {c.id for c in bed_temperature_sweep(copy).cases}


@pytest.mark.slow
def test_the_process_studies_rise_with_energy_and_stop_near_the_crystallisation_range(tmp_path):
    """The energy and bed-temperature studies in full (40 min on two shared cores): at the
    0.1 mm hatch the density gained rises with the Andrew number, and densification stops
    within 3 K of the base's crystallisation range on cooling (docs/record/sweeps.md), on the base
    those figures were measured on (a fixed range; the bundled base now crystallises by
    kinetics)."""
    out = tmp_path / "process"
    base = ROOT / "tests" / "data" / "machine_layer_range.toml"  # the range the threshold meets
    args = ["bench", "process", "--base", str(base), "--only", "energy", "bed", "--out", str(out)]
    assert cli_main(args) == 0
    saved = json.loads((out / "process.json").read_text())
    gains = [r["gain"] for r in saved["energy"] if r["hatch_um"] == 100.0]
    assert gains == sorted(gains) and gains[-1] > gains[0] + 0.02
    lo, hi = load_case(base).materials["PA12"].crystallization_range_C
    assert lo - 3.0 <= saved["bed_temperature"]["threshold_C"] <= hi + 3.0
