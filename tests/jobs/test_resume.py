"""A run interrupted mid-way and resumed from its checkpoint (``--checkpoint-every``, then
``--resume``) ends with the summary of the uninterrupted run, wall times aside: its initial
frame, neck history and contacts travel in the checkpoint, so it does so even when resumed into
another folder (issue #52: the resumed summary's ``initial`` was the state at the checkpoint)."""

from __future__ import annotations

import json

import pytest

from taichi_sls.cli import main
from taichi_sls.config import load_case
from taichi_sls.jobs.case_run import run_case
from taichi_sls.jobs.run_loop import Frame, Observer

COMMON = [
    "output.png=false",
    "output.gif=false",
    "solver.optimize=false",
    "solver.fast_math=false",
    "solver.threads=1",
]
# name: (bundled case, overrides, the frame the run is stopped at)
RUNS = {
    "pair2d": ("power25W_coarse", ["time.stop=end", "time.end_s=4e-5"], 8),
    "bed3d": ("bed3d_cooling", ["time.end_s=4e-6", "output.frames=4"], 3),
}
VOLATILE = ("wall", "compile", "steps_per_s", "kernels_compiled")


class StopAt(Observer):
    """Stops the run at a frame, as Ctrl-C would (after the checkpoint of the frame before)."""

    def __init__(self, index: int) -> None:
        self.index = index

    def frame(self, frame: Frame) -> None:
        if frame.index == self.index:
            raise KeyboardInterrupt


def _steady(obj):
    """The summary without its wall and compile times."""
    if isinstance(obj, dict):
        return {k: _steady(v) for k, v in obj.items() if not any(w in k for w in VOLATILE)}
    if isinstance(obj, list):
        return [_steady(v) for v in obj]
    return obj


@pytest.mark.parametrize("name", sorted(RUNS))
def test_a_resumed_run_ends_as_the_uninterrupted_one(name, tmp_path):
    case_name, sets, stop_at = RUNS[name]
    sets = COMMON + sets
    full = run_case(load_case(case_name, sets), tmp_path / "full", progress=False)
    part = run_case(
        load_case(case_name, sets),
        tmp_path / "part",
        progress=False,
        checkpoint_every=1,
        observers=[StopAt(stop_at)],
    )
    assert part["status"] == "interrupted" and 0 < part["steps"] < full["steps"]
    args = ["run", case_name, "--out", str(tmp_path / "resumed"), "--no-progress"]
    args += ["--resume", str(tmp_path / "part" / "checkpoint.npz")]
    assert main(args + [a for s in sets for a in ("--set", s)]) == 0
    want = json.loads((tmp_path / "full" / "summary.json").read_text())
    got = json.loads((tmp_path / "resumed" / "summary.json").read_text())
    assert got["status"] == "complete" and got["steps"] == full["steps"]
    assert _steady(got) == _steady(want)
    # the time series up to the checkpoint came with it
    series = (tmp_path / "resumed" / "timeseries.csv").read_text()
    assert series == (tmp_path / "full" / "timeseries.csv").read_text()
