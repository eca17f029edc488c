"""The speed benchmark's pieces: the synthetic powder layers and the minimal MLS-MPM floor."""

import csv

import numpy as np
import pytest

from bench.baseline import MinimalMPM
from bench.speed import layer_case
from taichi_sls.backend import ti
from taichi_sls.cli import main
from taichi_sls.config import case_from_dict
from taichi_sls.solver.scene import build_scene


@pytest.mark.parametrize("n", [10_000, 100_000])
def test_layer_has_about_the_points_asked_for(n):
    scene = build_scene(case_from_dict(layer_case(n)))
    assert abs(scene.n_points - n) < 0.03 * n
    # seeded in cell order within each particle, particles one after another
    assert np.all(np.diff(scene.body) >= 0)


def test_floor_conserves_momentum_and_mass():
    """The minimal elastic step is a real MPM step: a spinning, drifting disc keeps its linear
    momentum to round-off (APIC conserves it exactly) and its points stay together."""
    ti.init(arch=ti.cpu, default_fp=ti.f64, log_level=ti.ERROR)
    h = 1e-6
    g = (np.arange(64) + 0.5) * 0.5 * h
    X, Y = np.meshgrid(g, g, indexing="ij")
    x = np.stack([X.ravel(), Y.ravel()], axis=1)
    c = np.array([16e-6, 16e-6])
    x = x[np.linalg.norm(x - c, axis=1) < 8e-6] + 8e-6
    fl = MinimalMPM(x, 48, 48, h, 1e-9)
    r = x - x.mean(axis=0)
    fl.v.from_numpy(np.stack([-r[:, 1], r[:, 0]], axis=1) * 1e3 + np.array([0.1, 0.05]))
    p0 = fl.v.to_numpy().sum(axis=0)
    fl.advance(200, parallel=False)
    p1 = fl.v.to_numpy().sum(axis=0)
    assert np.allclose(p1, p0, rtol=1e-10, atol=1e-12 * np.abs(p0).max())
    xe = fl.x.to_numpy()
    assert np.all(np.isfinite(xe)) and np.ptp(xe, axis=0).max() < 20e-6


@pytest.mark.slow
def test_speed_bench_writes_its_table(tmp_path):
    args = ["bench", "speed", "--sizes", "3000", "--seconds", "0.05", "--no-switches"]
    assert main([*args, "--out", str(tmp_path)]) == 0
    rows = list(csv.DictReader((tmp_path / "speed.csv").open()))
    variants = {r["variant"].split(",")[0] for r in rows}
    assert {"full physics", "one kernel call per stage", "minimal elastic MLS-MPM"} <= variants
    assert all(float(r["us_per_step"]) > 0 for r in rows)
    assert (tmp_path / "speed.png").stat().st_size > 0


def test_cost_errors_are_relative_to_the_reference_row():
    """The run-time/error study: each paper row's errors are relative to the reference row's
    neck at 1 ms, final neck and peak temperature; its error is the largest of the three, and
    rows of other scenarios keep their own error."""
    from bench.cost import errors

    paper = "paper 25 W to solidification"
    rows = [
        {
            "scenario": paper,
            "setting": "reference: dt",
            "neck_1ms_um": 20.0,
            "neck_final_um": 21.0,
            "T_peak_C": 300.0,
        },
        {
            "scenario": paper,
            "setting": "dt x2",
            "neck_1ms_um": 20.2,
            "neck_final_um": 21.0,
            "T_peak_C": 303.0,
        },
        {"scenario": "hopper R/h = 10", "setting": "auto dt, s = 1", "error": 0.05},
    ]
    errors(rows)
    assert rows[0]["error"] == 0.0
    assert rows[1]["err_1ms"] == pytest.approx(0.01)
    assert rows[1]["err_final"] == 0.0
    assert rows[1]["error"] == pytest.approx(0.01)
    assert rows[2]["error"] == 0.05
