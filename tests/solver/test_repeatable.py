"""A bed run repeats: the same case twice, in two processes with different hash seeds, gives the
same summary, time series and contacts table, bit for bit. The blocks layout on two threads (the
layout cases/bed_track.toml takes on a CPU): its surface-energy stage once let two threads add to
one node at a time (physics/surface_energy.py, in_passes), and the heat that fixed nodes pass to
the walls was a float sum in thread order (solver/step.py)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import deep_update

# a small deposited layer under a track, in the blocks layout on two threads, for 20 us
CASE = {
    "case": {"name": "repeat_bed"},
    "grid": {"spacing_um": 4.0},
    "bed": {
        "generator": "deposition",
        "layers": 1.5,
        "median_diameter_um": 40.0,
        "spread": 0.2,
        "seed": 1,
        "x_range_um": [0.0, 200.0],
    },
    "contact": {"initial": "fillet"},
    "boundary": {"bottom": {"thermal": "fixed", "temperature_C": 140.0}},
    "thermal": {"initial_C": 140.0},
    "lasers": [{"power_W": 25.0, "x_start_um": 0.0, "x_end_um": 200.0, "speed_m_s": 4.0}],
    "time": {"end_s": 2e-5},
    "solver": {"layout": "blocks", "threads": 2, "optimize": False},
    "output": {"frames": 4, "png": False, "gif": False},
}
# what measures the machine, not the run
TIMINGS = (
    "compile_s",
    "compile_front_end_s",
    "compile_back_end_s",
    "compile_cpu_s",
    "kernels_compiled",
    "wall_s",
    "step_wall_s",
    "wall_breakdown_s",
    "steps_per_s",
)

RUN = """
import json, sys
from taichi_sls.config.loading import case_from_dict
from taichi_sls.jobs.case_run import run_case
run_case(case_from_dict(json.loads(sys.argv[1])), sys.argv[2], progress=False)
"""


def _run(tmp: Path, seed: str) -> dict:
    out = tmp / f"seed{seed}"
    env = {**os.environ, "PYTHONHASHSEED": seed}
    env["PYTHONPATH"] = os.pathsep.join([str(Path(__file__).parents[2]), env.get("PYTHONPATH", "")])
    subprocess.run(
        [sys.executable, "-c", RUN, json.dumps(CASE), str(out)], env=env, check=True, timeout=900
    )
    summary = json.loads((out / "summary.json").read_text())
    for k in TIMINGS:
        summary.pop(k, None)
    return {
        "summary": summary,
        "series": (out / "timeseries.csv").read_text(),
        "contacts": (out / "contacts.csv").read_text(),
    }


@pytest.mark.slow  # two processes that compile every kernel: about 5 min on a busy 2-core machine
def test_a_bed_run_twice_gives_the_same_summary_bit_for_bit(tmp_path):
    a, b = _run(tmp_path, "1"), _run(tmp_path, "2")
    assert a["summary"]["points"] > 1000  # a bed, not an empty scene
    assert a["summary"]["bed"]["contacts"] > 3
    assert a["summary"] == b["summary"]
    assert a["series"] == b["series"]
    assert a["contacts"] == b["contacts"]


def test_the_case_is_in_the_blocks_layout_with_a_surface_and_a_fixed_wall():
    """What the test above exercises: the layout, the surface-energy force and the wall heat."""
    from taichi_sls.config.loading import case_from_dict
    from taichi_sls.solver.scene import build_scene
    from taichi_sls.solver.step_config import Layout, choose_layout

    case = case_from_dict(deep_update({}, CASE))
    assert choose_layout(case, build_scene(case).n_points) == Layout.BLOCKS
    assert case.surface_tension.method == "surface_energy"
    assert case.boundary.bottom.thermal == "fixed"
