"""A bed sweep's collection and figure: dotted names reach into a run's summary (the bed's
record), and the bed map is drawn from a results.csv of those columns (synthetic rows: the
bundled sweep itself runs on request, docs/record/sweeps.md)."""

import math

from taichi_sls.jobs.sweep.bed_plots import bed_rows
from taichi_sls.jobs.sweep.draw import draw_all
from taichi_sls.jobs.sweep.results import write_results
from taichi_sls.jobs.sweep.runner import _collect
from taichi_sls.jobs.sweep.spec import load_sweep

SUMMARY = {
    "status": "complete",
    "steps": 120,
    "final": {"T_peak_C": 250.0},
    "bed": {"fused_fraction": 0.25, "relative_density": {"initial": 0.82, "final": 0.86}},
}


def test_dotted_names_reach_into_the_summary():
    got = _collect(
        SUMMARY,
        ["T_peak_C", "steps", "bed.fused_fraction", "bed.relative_density.final", "bed.nothing"],
    )
    assert got == {
        "T_peak_C": 250.0,
        "steps": 120,
        "bed.fused_fraction": 0.25,
        "bed.relative_density.final": 0.86,
        "bed.nothing": None,
    }


def test_the_bundled_bed_sweep_collects_the_beds_record():
    sweep = load_sweep("bed_map")
    assert len(sweep.cases) == 9
    assert {"bed.fused_fraction", "bed.relative_density.final"} <= set(sweep.collect)


def test_bed_map_from_results(tmp_path):
    """Nine rows of power x speed: the map is drawn (and only it, not the pair's figures), and
    each row carries its line energy P / v and density gain."""
    rows, cols = [], ["id", "lasers.0.power_W", "lasers.0.speed_m_s", "status"]
    cols += ["bed.fused_fraction", "bed.relative_density.initial", "bed.relative_density.final"]
    for i, (P, v) in enumerate((P, v) for P in (5, 15, 25) for v in (2.0, 4.0, 8.0)):
        e = P / v
        rows.append(
            {
                "id": f"c{i}",
                "lasers.0.power_W": P,
                "lasers.0.speed_m_s": v,
                "status": "complete",
                "bed.fused_fraction": min(1.0, e / 10.0),
                "bed.relative_density.initial": 0.82,
                "bed.relative_density.final": 0.82 + 0.01 * math.log1p(e),
            }
        )
    write_results(tmp_path, rows, cols)
    drawn = draw_all(tmp_path)
    assert [p.name for p in drawn] == ["bed_map.png"]
    assert 10_000 < drawn[0].stat().st_size < 500_000
    got = bed_rows(tmp_path / "results.csv")
    assert len(got) == 9
    r = next(r for r in got if r["P_W"] == 25 and r["v_m_s"] == 2.0)
    assert r["line_energy_J_m"] == 12.5
    assert math.isclose(r["density_gain"], 0.01 * math.log1p(12.5))
