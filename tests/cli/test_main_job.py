"""The main job end to end: every output file, f32, and a run that the guard stops."""

import csv
import json
from pathlib import Path

import imageio.v3 as iio
import meshio
import numpy as np
import pytest
from helpers import PAPER_SCENE, deep_update, guard_message, make_case

from taichi_sls.config.reference import describe_keys
from taichi_sls.jobs.case_run import run_case
from taichi_sls.solver.simulation import Simulation

ROOT = Path(__file__).resolve().parents[2]


def _small(extra: dict | None = None):
    base = deep_update(
        PAPER_SCENE,
        {
            "case": {"name": "small"},
            "grid": {"spacing_um": 4.0},
            "time": {"end_s": 2e-5},
            "lasers": [{"power_W": 25.0}],
            "output": {"frames": 3, "vtu": True, "dpi": 50},
        },
    )
    return make_case(deep_update(base, extra or {}))


def test_main_job_writes_every_output(tmp_path):
    out = tmp_path / "run"
    summary = run_case(_small(), out, progress=False)
    assert summary["status"] == "complete"
    for name in ("case.toml", "timeseries.csv", "summary.json", "animation.gif", "points.pvd"):
        assert (out / name).is_file(), name
    frames = sorted((out / "frames").glob("frame_*.png"))
    assert len(frames) == 4  # the initial state and 3 frames
    assert iio.imread(frames[-1]).shape[2] in (3, 4)
    rows = list(csv.DictReader((out / "timeseries.csv").open()))
    assert len(rows) == 4
    for col in ("t_s", "T_max_C", "contact_line_um", "kinetic_energy_J_per_m", "J_min"):
        assert col in rows[0]
    s = json.loads((out / "summary.json").read_text())
    for key in ("case", "steps", "simulated_s", "wall_s", "compile_s", "steps_per_s", "points"):
        assert key in s
    assert s["nodes"] == 322 and s["points"] == 632
    # where the wall time went (issue #53): every part measured, none counted twice (the rest,
    # the wall time less the parts, is not negative), the frames by observer
    wall = s["wall_breakdown_s"]
    assert wall["stepping_s"] == s["step_wall_s"] and wall["settle_s"] < 1e-2  # no settling
    assert all(wall[k] >= 0.0 for k in ("baseline_s", "frames_s", "end_s", "other_s"))
    assert {"Frames", "TimeSeries", "PairVerdict"} <= set(wall["frames_by_observer_s"])
    assert sum(wall["frames_by_observer_s"].values()) == pytest.approx(wall["frames_s"])
    assert wall["end_by_observer_s"]["Frames"] > 0.0  # the GIF and the plots
    assert s["final"]["T_max_C"] > s["initial"]["T_max_C"]
    assert abs(s["simulated_s"] - 2e-5) < 1e-6
    mesh = meshio.read(sorted((out / "vtu").glob("*.vtu"))[-1])
    assert len(mesh.points) == 632 and "T_C" in mesh.point_data
    pd = mesh.point_data
    for name in ("velocity_m_s", "von_mises_Pa", "pressure_Pa", "equivalent_plastic_strain"):
        assert len(pd[name]) == 632 and np.isfinite(pd[name]).all(), name
    assert sorted(np.unique(pd["body_id"])) == [0, 1]  # the two discs
    left = pd["body_id"] == 0
    assert mesh.points[left, 0].max() < mesh.points[~left, 0].min() + 4.0  # disc 0 on the left
    assert 0.9 < pd["J"].min() and pd["J"].max() < 1.1
    assert pd["velocity_m_s"].shape == (632, 3) and np.abs(pd["velocity_m_s"][:, :2]).max() > 0
    # the Laplace pressure of the discs and the heated melt: stressed, the invariants consistent
    assert pd["von_mises_Pa"].max() > 0 and (pd["von_mises_Pa"] >= 0).all()
    mean = (pd["stress_xx_Pa"] + pd["stress_yy_Pa"] + pd["stress_zz_Pa"]) / 3
    np.testing.assert_allclose(pd["pressure_Pa"], -mean, atol=1e-6 * np.abs(mean).max())


def test_single_precision_runs():
    sim = Simulation(_small({"solver": {"precision": "f32"}}))
    H0 = sim.monitors()["enthalpy_J_per_m"]
    sim.advance_to(100 * sim.dt)  # 100 fixed steps
    m = sim.monitors()
    assert np.isfinite(m["T_max_C"]) and m["T_max_C"] > 140.0
    bal = m["enthalpy_J_per_m"] - H0 + m["heat_out_J_per_m"] - m["laser_energy_J_per_m"]
    assert abs(bal) < 1e-4 * m["laser_energy_J_per_m"]  # f32 round-off


def test_guard_stops_a_blow_up_and_keeps_the_outputs(tmp_path):
    out = tmp_path / "bad"
    case = _small({"time": {"dt_s": 2e-6, "allow_unstable_dt": True, "end_s": 4e-4}})
    summary = run_case(case, out, progress=False)
    assert summary["status"] == "failed"
    assert "likely cause: time step" in summary["error"]
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "failed"
    rows = list(csv.DictReader((out / "timeseries.csv").open()))
    assert len(rows) >= 1  # the frames before the trip are kept
    assert (out / "failed_state.npz").is_file()  # and the offending state beside them
    assert " at step " in s["error"] and " um" in s["error"]  # when and where


def test_case_reference_is_current():
    assert (ROOT / "docs" / "case_reference.md").read_text() == describe_keys()


def test_resume_matches_an_uninterrupted_run_bitwise(tmp_path):
    extra = {"time": {"end_s": 2e-5}, "output": {"frames": 4, "png": False, "vtu": False}}
    full = run_case(_small(extra), tmp_path / "full", progress=False, checkpoint_every=1)
    # the same run stopped after 2 of its 4 frames, then resumed from its checkpoint
    half = {"time": {"end_s": 1e-5}, "output": {"frames": 2, "png": False, "vtu": False}}
    run_case(_small(half), tmp_path / "part", progress=False, checkpoint_every=1)
    resumed = run_case(
        _small(extra),
        tmp_path / "part",
        progress=False,
        checkpoint_every=1,
        resume=tmp_path / "part" / "checkpoint.npz",
    )
    assert resumed["status"] == "complete" and resumed["steps"] == full["steps"]
    a = np.load(tmp_path / "full" / "checkpoint.npz")
    b = np.load(tmp_path / "part" / "checkpoint.npz")
    for k in a.files:
        if k.startswith(("p_", "s_")):
            assert np.array_equal(a[k], b[k]), k  # bitwise on the CPU
    rows_full = (tmp_path / "full" / "timeseries.csv").read_text()
    rows_part = (tmp_path / "part" / "timeseries.csv").read_text()
    assert rows_full == rows_part


def test_guard_catches_an_unstable_thermal_step():
    """Conduction at 10x the limit of eq. 48 (measured: 5x still runs, 10x diverges): caught as
    a temperature outside the physical range, with the thermal limit named."""
    case = make_case(
        {
            "grid": {"spacing_um": 2.0},
            "domain": {"width_um": 40.0, "height_um": 8.0},
            "bodies": [{"shape": "rect", "min_um": [0.0, 0.0], "max_um": [40.0, 4.0]}],
            "physics": {"mechanics": False},
            "thermal": {"initial_C": 100.0},
            "boundary": {"left": {"thermal": "fixed", "temperature_C": 300.0}},
            "time": {"dt_s": 1e-4, "allow_unstable_dt": True, "end_s": 1e-2},
            "output": {"frames": 10, "png": False},
        }
    )
    err = guard_message(Simulation(case), frames=10, steps=10)
    assert err is not None and "outside the physical range" in err and "thermal" in err


def test_guard_names_the_point_that_went_nan():
    sim = Simulation(_small())
    T = sim.state.points.T.to_numpy()
    T[17] = np.nan
    sim.state.points.T.from_numpy(T)
    err = guard_message(sim)
    assert err is not None, "the guard let a NaN temperature through"
    assert "NaN" in err and "point 17 " in err


def test_guard_names_the_point_that_left_the_grid():
    """A point thrown out of the open top is the one named, not the point farthest from the
    domain's centre (a point on a side wall is farther from the centre of a wide domain)."""
    sim = Simulation(_small())
    x = sim.state.points.x.to_numpy()
    cfg = sim.state.cfg
    x[5, 1] = (cfg.ny - cfg.off - 1.5) * cfg.h  # half a cell beyond the grid's reach, on top
    sim.state.points.x.from_numpy(x)
    err = guard_message(sim)
    assert err is not None, "the guard let a point beyond the grid through"
    assert "left the grid" in err and "point 5 " in err


def test_unwritable_out_is_one_line_error(tmp_path, capsys):
    from taichi_sls.cli import run_main

    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    assert run_main(["power25W_coarse", "--out", str(blocker / "sub"), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: --out") and "cannot write" in err[0]


def test_runaway_laser_names_the_heat_first():
    """A 5 kW beam (200x the paper's 25 W): the temperature runs away first and the points fly
    off later; the guard names the heat input, not the time step."""
    case = _small({"lasers": [{"power_W": 5000.0}], "time": {"end_s": 1e-4}})
    err = guard_message(Simulation(case), frames=20, steps=50)
    assert err is not None
    assert "likely cause: more heat than the melt can take" in err and "power_W" in err


def test_python_api_example(tmp_path):
    """The README's Python API: load a bundled case, override, run, read the outputs."""
    import taichi_sls as sls

    case = sls.load_case("power25W_coarse", ["time.end_s=1e-5", "output.png=false"])
    summary = sls.run_case(case, tmp_path / "api", progress=False)
    series = sls.read_series(tmp_path / "api" / "timeseries.csv")
    assert summary["status"] == "complete"
    assert series["t_s"][-1] == pytest.approx(summary["simulated_s"], rel=1e-12)
    assert summary["simulated_s"] >= 1e-5
    assert series["contact_line_um"][0] == pytest.approx(summary["initial"]["contact_line_um"])
