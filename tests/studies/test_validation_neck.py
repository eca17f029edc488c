"""The pair's a / R beside the measured neck (output.validation): the comparison's arithmetic,
and the command line's run writing validation.csv, validation.png and the summary's record."""

import csv
import json
import math
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from taichi_sls.cli import main
from taichi_sls.config import CaseError, load_case
from taichi_sls.studies.validation.measured import NeckPoint, load_pulse_neck
from taichi_sls.studies.validation.neck import (
    COLUMNS,
    compare,
    largest_error,
    validation_observers,
)

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "cases" / "validation" / "pulse_pair_temperature.toml"


def _point(t, a):
    return NeckPoint("s", 125.0, t, a, "a source", "")


def test_compare_reads_between_frames_and_not_past_the_run():
    t = np.array([0.0, 0.1, 0.3])
    a = np.array([0.2, 0.3, 0.5])
    rows = compare(t, a, [_point(0.05, 0.3), _point(0.2, 0.3), _point(0.5, 0.9)])
    assert [r.computed for r in rows[:2]] == pytest.approx([0.25, 0.4])
    assert [r.error for r in rows[:2]] == pytest.approx([-0.05, 0.1])
    assert math.isnan(rows[2].computed)  # after the run's last frame: not compared
    assert largest_error(rows, 1.0) == pytest.approx(0.1)
    assert largest_error(rows, 0.1) == pytest.approx(0.05)
    assert all(r.source == "a source" for r in rows)


def test_a_single_body_is_refused_naming_the_key():
    case = load_case(CASE, ["bodies=[{center_um = [300.0, 210.0], radius_um = 125.0}]"])
    with pytest.raises(CaseError, match="output.validation = 'pulse_pair_R125': bodies 0 and 1"):
        validation_observers(case, "out")
    assert validation_observers(load_case(CASE, ["output.validation=none"]), "out") == []


def test_the_run_writes_the_comparison(tmp_path):
    """The bundled case to 0.15 s on a coarse grid (h = 12.5 um, speed only): the measured
    times it reached are compared (computed a / R read from its frames, error = computed -
    measured, each row with its source), the later ones left empty; the plot is drawn."""
    out = tmp_path / "o"
    code = main(
        [
            "run",
            str(CASE),
            "--out",
            str(out),
            "--no-progress",
            "--set",
            "grid.spacing_um=12.5",
            "--set",
            "time.end_s=0.15",
            "--set",
            "output.png=false",
            "--set",
            "solver.optimize=false",
        ]
    )
    assert code == 0
    with (out / "validation.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == COLUMNS
    measured = load_pulse_neck()
    assert [float(r["t_s"]) for r in rows] == [p.t_s for p in measured]
    reached = [r for r in rows if r["computed_a_over_R"]]
    assert [float(r["t_s"]) for r in reached] == [p.t_s for p in measured if p.t_s <= 0.15]
    for r in reached:
        computed, meas = float(r["computed_a_over_R"]), float(r["measured_a_over_R"])
        assert 0.0 < computed < 1.26
        assert float(r["error"]) == pytest.approx(computed - meas, abs=1e-12)
        assert "Hejmady" in r["source"]
    assert all(r["error"] == "" for r in rows if not r["computed_a_over_R"])
    summary = json.loads((out / "summary.json").read_text())["validation"]
    assert summary["compared"] == len(reached) == 2
    assert summary["max_abs_error"] == pytest.approx(max(abs(float(r["error"])) for r in reached))
    png = iio.imread(out / "validation.png")
    assert png.std() > 10  # drawn, not blank
