"""bench/bedgrid.py: a 3D layer over grids and seeds. The arithmetic on made-up rows (a quantity
exactly quadratic in h must give order 2 and its h = 0 value), and a finished run is read back,
not run again. The study's figures are in docs/record/convergence.md."""

import json
import math

import pytest

import bench.bedgrid as bedgrid
from taichi_sls.config import case_to_toml, load_case


def _row(h: float, seed: int, density: float) -> dict:
    row = dict.fromkeys(bedgrid.COLUMNS, "")
    row |= {"h_um": h, "seed": seed, "status": "complete", "density_final": density}
    row |= {"density_gain": density - 0.6, "melted_through_fraction": 0.5, "fused_fraction": 0.0}
    return row | {"neck_median_um": 14.0}


def test_a_quantity_quadratic_in_h_gives_order_two_and_its_limit():
    """f = 0.85 - 0.002 h^2 on h = 5, 4, 3.2 (ratio 1.25): order 2 and the estimate 0.85 to
    1e-9 (round-off of three subtractions); the seeds' range and sample sd at h = 4."""
    rows = [_row(h, 1, 0.85 - 0.002 * h * h) for h in (5.0, 4.0, 3.2)]
    rows += [_row(4.0, s, d) for s, d in ((2, 0.798), (3, 0.838))]
    density = bedgrid.analyse(rows, 4.0, 1)[0]
    assert density["order"] == pytest.approx(2.0, abs=1e-9)
    assert density["estimate"] == pytest.approx(0.85, abs=1e-9)
    assert density["at_vs_estimate"] == pytest.approx(-0.032 / 0.85, rel=1e-9)
    assert density["first_order"] == pytest.approx(0.82952 + 0.01152 / 0.25, rel=1e-9)
    assert density["seeds"] == [1, 2, 3]
    assert density["seed_sd"] == pytest.approx(0.02, rel=1e-9)  # 0.818, 0.798, 0.838
    gain, melted, fused = bedgrid.analyse(rows, 4.0, 1)[1:4]
    assert gain["order"] == pytest.approx(2.0, abs=1e-9)
    assert melted["estimate"] == 0.5 and "converged" in melted["note"]
    text = bedgrid.table(bedgrid.analyse(rows, 4.0, 1), 4.0)
    assert "| relative density at the end | 0.8 | 0.818 | 0.8295 | 2.00 | 0.85 " in text


def test_spacings_out_of_a_constant_ratio_give_no_estimate():
    rows = [_row(h, 1, 0.85 - 0.002 * h * h) for h in (5.0, 4.0, 2.0)]
    density = bedgrid.analyse(rows, 4.0, 1)[0]
    assert math.isnan(density["estimate"]) and "constant ratio" in density["note"]


def test_a_finished_run_is_read_not_run_again(tmp_path, monkeypatch):
    """A folder with a complete summary and this study's case.toml is read back, outputs aside;
    one whose case differs otherwise is run again."""
    case = load_case("machine_layer3d", ["grid.spacing_um=5", "bed.seed=2"])
    folder = tmp_path / "h5um_seed2"
    folder.mkdir()
    (folder / "case.toml").write_text(case_to_toml(case.given or case))
    bed = {
        "contacts": 10,
        "melted_through": 4,
        "fused_fraction": 0.1,
        "relative_density": {"initial": 0.6, "final": 0.75},
        "neck_final_um": {"median": 12.5},
    }
    summary = {"status": "complete", "points": 100, "steps": 7, "wall_s": 3.0, "bed": bed}
    (folder / "summary.json").write_text(json.dumps(summary))

    def no_run(*args, **kwargs):
        raise AssertionError("a finished run was run again")

    monkeypatch.setattr(bedgrid, "run_case", no_run)
    row = bedgrid.run_one("machine_layer3d", 5.0, 2, tmp_path, [])
    assert row["density_final"] == 0.75 and row["density_gain"] == 0.15
    assert row["melted_through_fraction"] == 0.4 and row["cells_across_d50"] == 4.0
    quiet = bedgrid.run_one("machine_layer3d", 5.0, 2, tmp_path, ["output.gif=false"])
    assert quiet["density_final"] == 0.75  # outputs change no answer: the same run
    with pytest.raises(AssertionError, match="run again"):
        bedgrid.run_one("machine_layer3d", 5.0, 2, tmp_path, ["time.end_s=5"])
