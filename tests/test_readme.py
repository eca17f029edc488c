"""The README is the front page: short, and everything it names exists and runs. The commands it
shows parse and the case keys it names exist (test_docs.py checks every page, the README among
them); here every case and sweep file it names loads, and its main command runs, cut short."""

import json
import re

import pytest
from test_docs import ROOT, _commands

from taichi_sls.cli import main
from taichi_sls.config import load_case

README = (ROOT / "README.md").read_text()
CASES = sorted(set(re.findall(r"cases/[A-Za-z0-9_/]+\.toml", README)))
SWEEPS = sorted(set(re.findall(r"sweeps/[A-Za-z0-9_]+\.toml", README)))


def test_the_readme_is_a_front_page():
    lines = README.splitlines()
    assert len(lines) <= 150, f"README.md has {len(lines)} lines (at most 150)"
    # its first screen names the question, the two set-up commands and the answer table
    first = "\n".join(lines[:60])
    assert "fuse" in first and "```bash" in first
    assert "## What it answers" in README and README.index("## What it answers") < README.index(
        "## Where to go next"
    )


def test_it_names_cases_and_sweeps():
    assert "cases/power25W_resolved.toml" in CASES and len(CASES) >= 4
    assert SWEEPS


@pytest.mark.parametrize("name", CASES)
def test_every_case_it_names_loads(name):
    assert (ROOT / name).is_file(), f"README.md names {name}, which does not exist"
    load_case(ROOT / name)


@pytest.mark.parametrize("name", SWEEPS)
def test_every_sweep_it_names_loads(name):
    from taichi_sls.studies.sweep.spec import load_sweep

    assert (ROOT / name).is_file(), f"README.md names {name}, which does not exist"
    sweep = load_sweep(ROOT / name)
    assert sweep.cases
    for case in sweep.cases:  # every override of every case is one the loader takes
        load_case(sweep.base, case.overrides)


def test_its_main_command_runs(tmp_path, monkeypatch):
    """The first command the README shows, cut to 2 us of simulated time on the coarse grid: the
    pair settles, the laser starts, and a run's outputs are written."""
    run = next(words for words in _commands(README) if words[0] == "run")
    assert run[1] == "cases/power25W_resolved.toml"
    monkeypatch.chdir(ROOT)
    out = tmp_path / "main"
    short = ["grid.spacing_um=4", "time.stop=end", "time.end_s=2e-6", "output.gif=false"]
    argv = [*run, "--no-progress", "--out", str(out), *(a for s in short for a in ("--set", s))]
    assert main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "complete" and summary["settle"]["neck_um"] > 0
    assert (out / "outcome.png").is_file() and (out / "timeseries.csv").is_file()
