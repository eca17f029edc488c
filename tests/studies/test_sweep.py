"""Parameter sweeps on Dask: a 3-case sweep on a local cluster (one case refused by the loader),
a restart that reruns nothing, and a sweep on a scheduler and worker started as subprocesses."""

import csv
import os
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from taichi_sls.cli import main as cli_main
from taichi_sls.config import bundled_case, load_case
from taichi_sls.jobs.sweep.plots import neck_growth
from taichi_sls.jobs.sweep.results import read_results
from taichi_sls.jobs.sweep.runner import run_sweep
from taichi_sls.jobs.sweep.spec import case_id, load_sweep

ROOT = Path(__file__).resolve().parents[2]
BASE = bundled_case("power25W_coarse")
TINY = ["time.end_s=2e-5", "output.frames=2", "output.png=false", "output.gif=false"]


def _sweep_file(folder: Path, cases: list[dict], name: str = "t") -> Path:
    lines = [
        "[sweep]",
        f'name = "{name}"',
        f'base = "{BASE.as_posix()}"',
        'collect = ["T_peak_C", "contact_line_um", "status"]',
        "set = [" + ", ".join(f"'{s}'" for s in TINY) + "]",
    ]
    for c in cases:
        lines += ["[[cases]]"] + [f'"{k}" = {v}' for k, v in c.items()]
    path = folder / f"{name}.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


CASES = [
    {"lasers.0.power_W": 25},
    {"lasers.0.power_W": 5},
    {"materials.PA12.poisson": 0.7},  # refused by the loader: must become an error row
]


@pytest.fixture(scope="module")
def first_sweep(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sweep")
    sweep = load_sweep(_sweep_file(folder, CASES))
    out = folder / "out"
    t0 = time.perf_counter()
    rows = run_sweep(sweep, out, workers=2, progress=False)
    return sweep, out, rows, time.perf_counter() - t0


def test_sweep_file_grid_bundles_and_ids():
    paper = load_sweep("paper")  # a bundled sweep by name; its base is a bundled case
    assert paper.base == bundled_case("power15W").resolve()
    assert len(paper.cases) == 6  # 3 powers, 2 radii, 1 scan
    pm = load_sweep(ROOT / "sweeps" / "process_map.toml")  # from the repository's folder
    assert len(pm.cases) == 25 and len({c.id for c in pm.cases}) == 25
    assert pm.keys[:2] == ["lasers.0.power_W", "lasers.0.speed_m_s"]
    scan = [c for c in pm.cases if c.params["lasers.0.speed_m_s"] == 4.0][0]
    assert "lasers.0.x_end_um=80.0" in scan.overrides
    assert case_id("b", ["x=1", "y=2"]) == case_id("b", ["y=2", "x=1"])
    assert case_id("b", ["x=1"]) != case_id("b", ["x=2"])


@pytest.mark.parametrize("path", sorted((ROOT / "sweeps").glob("*.toml")), ids=lambda p: p.stem)
def test_every_bundled_sweep_case_loads(path):
    """A sweep file whose case a key or value refuses would fail one worker per case, minutes in."""
    sweep = load_sweep(path)
    for c in sweep.cases:
        load_case(str(sweep.base), c.overrides)


def test_three_cases_give_three_rows(first_sweep):
    sweep, out, rows, _ = first_sweep
    with (out / "results.csv").open() as f:
        table = list(csv.DictReader(f))
    assert len(table) == 3
    assert [r["id"] for r in table] == [c.id for c in sweep.cases]
    for col in ("id", "lasers.0.power_W", "materials.PA12.poisson", "T_peak_C", "status"):
        assert col in table[0]
    assert list(table[0])[-3:] == ["status", "error", "wall_s"]
    hot, cold = table[0], table[1]
    assert hot["status"] == cold["status"] == "complete"
    assert float(hot["T_peak_C"]) > float(cold["T_peak_C"]) > 140.0
    for r in (hot, cold):
        assert (out / r["id"] / "summary.json").is_file()
    import pyarrow.parquet as pq  # a test dependency: the parquet table is written too

    assert pq.read_table(out / "results.parquet").num_rows == 3


def test_failing_case_is_recorded(first_sweep):
    _, out, rows, _ = first_sweep
    bad = [r for r in read_results(out / "results.csv") if r["status"] == "error"]
    assert len(bad) == 1
    assert "materials.PA12.poisson = 0.7" in bad[0]["error"]
    assert "(-1, 0.5)" in bad[0]["error"]


def test_restart_skips_finished_cases(first_sweep, tmp_path):
    sweep, out0, _, _ = first_sweep
    out = tmp_path / "out"
    shutil.copytree(out0, out)  # keeps mtimes
    before = read_results(out / "results.csv")
    stamps = {p: p.stat().st_mtime_ns for p in out.glob("*/summary.json")}
    # nothing to do: no cluster is started (this scheduler address does not exist)
    rows = run_sweep(sweep, out, scheduler="tcp://127.0.0.1:9", progress=False)
    assert read_results(out / "results.csv") == before == rows
    # one more case: only it runs; the old outputs are untouched
    more = load_sweep(_sweep_file(tmp_path, [*CASES, {"lasers.0.power_W": 15}]))
    rows = run_sweep(more, out, workers=1, progress=False)
    assert len(rows) == 4 and rows[:3] == before
    assert rows[3]["status"] == "complete" and rows[3]["id"] == more.cases[3].id
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps
    assert len(list(out.glob("*/summary.json"))) == 3


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow  # a second scheduler path; the local Dask runner is tested above
def test_sweep_on_existing_scheduler(tmp_path):
    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
    }
    common = {
        "env": env,
        "cwd": tmp_path,
        "stdout": subprocess.DEVNULL,
        "stderr": subprocess.DEVNULL,
    }
    sched = subprocess.Popen(
        [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1"]
        + ["--port", str(port), "--no-dashboard"],
        **common,
    )
    worker = subprocess.Popen(
        [sys.executable, "-m", "distributed.cli.dask_worker", addr, "--host", "127.0.0.1"]
        + ["--nworkers", "1", "--nthreads", "1", "--no-dashboard"],
        **common,
    )
    try:
        sweep = _sweep_file(tmp_path, [{"lasers.0.power_W": 25}], name="remote")
        out = tmp_path / "out"
        args = ["sweep", str(sweep), "--out", str(out), "--scheduler", addr, "--no-progress"]
        assert cli_main(args) == 0
        rows = read_results(out / "results.csv")
        assert len(rows) == 1 and rows[0]["status"] == "complete", rows
        assert (out / rows[0]["id"] / "summary.json").is_file()
    finally:
        for p in (worker, sched):
            p.terminate()
        for p in (worker, sched):
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def test_the_process_map_measures_growth_against_the_verdicts_baseline():
    """Where the rows collected the unheated pair's neck (the default verdict's reference), the
    map colours the growth over it; a row set without it keeps the growth over the start."""
    rows = [
        {"contact0_um": 18.6, "neck_final_um": 19.2, "neck_unheated_um": 19.6},
        {"contact0_um": 18.6, "neck_final_um": 21.0, "neck_unheated_um": 19.6},
    ]
    growth, reference = neck_growth(rows, "neck_final_um")
    assert reference == "unheated" and growth == pytest.approx([-0.4, 1.4])
    growth, reference = neck_growth([{**rows[0], "neck_unheated_um": ""}, rows[1]], "neck_final_um")
    assert reference == "initial" and growth == pytest.approx([0.6, 2.4])


def test_plot_only_draws_a_results_table_without_its_run_folders(tmp_path):
    """--plot-only on a results.csv copied away from its runs: the spot radius is then unknown
    (it comes from each run's case.toml), and every figure is still drawn."""
    from taichi_sls.jobs.sweep.draw import draw_all

    rows = [(P, v) for P in (5, 25) for v in (0.0, 1.0)]
    with (tmp_path / "results.csv").open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(
            ["id", "lasers.0.power_W", "lasers.0.speed_m_s", "T_peak_C", "neck_1ms_um",
             "neck_final_um", "neck_unheated_um", "status"]
        )  # fmt: skip
        for k, (P, v) in enumerate(rows):
            w.writerow([f"c{k}", P, v, 160 + 6 * P, 19.5, 19.6 + P / 100, 19.64, "complete"])
    drawn = {p.name for p in draw_all(tmp_path)}
    assert drawn == {"fig5_power.png", "fig8_radius_scan.png", "process_map.png"}
