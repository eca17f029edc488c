"""A 3D bed runs: cases/bed3d_cooling.toml (20 deposited spheres), shortened, from the command
line. Its outputs are the time series, summary (with the generator's report), frames and GIF,
and the per-contact bed outputs read by the 3D neck section (contacts.csv, the summary's bed)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_bundled_3d_bed_runs_from_the_command_line(tmp_path):
    out = tmp_path / "run"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    cmd = [sys.executable, "-m", "taichi_sls.run", "bed3d_cooling", "--out", str(out)]
    cmd += ["--set", "time.end_s=2e-6", "--set", "output.frames=1", "--no-progress"]
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "complete" and s["points"] == 11340  # measured: 20 spheres, h = 4 um
    assert s["outcome"]["fused"] is None and "per contact" in s["outcome"]["no_verdict"]
    assert s["bed_generator"]["spheres"] == 20 and s["bed_generator"]["contacts"] == 35
    assert s["bed"]["contacts"] >= 35 and (out / "contacts.csv").is_file()
    assert (out / "timeseries.csv").is_file()
    assert len(list((out / "frames").glob("frame_*.png"))) == 2  # the start and 1 frame
    assert (out / "animation.gif").is_file()
