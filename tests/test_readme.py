"""The README is the front page: short, and everything it names exists and runs. test_docs.py
checks the commands of every page's code blocks and the case keys it names, the README among
them; here its first screen, its pictures, every case and sweep file it names, its inline
commands and overrides, and its main command, run cut short."""

import json
import re
import shlex

import pytest
from test_docs import ROOT, _commands

from taichi_sls.cli import main, parser
from taichi_sls.config import load_case

README = (ROOT / "README.md").read_text()
CASES = sorted(set(re.findall(r"cases/[A-Za-z0-9_/]+\.toml", README)))
SWEEPS = sorted(set(re.findall(r"sweeps/[A-Za-z0-9_]+\.toml", README)))
# commands quoted inline, in single backticks (the code blocks are test_docs.py's)
INLINE = re.findall(r"`((?:taichi-sls|python -m taichi_sls\.run) [^`]+)`", README)
SETS = sorted(set(re.findall(r"--set ([a-zA-Z_0-9.]+=[^\s`]+)", README)))


def test_the_readme_is_a_front_page():
    lines = README.splitlines()
    assert len(lines) <= 150, f"README.md has {len(lines)} lines (at most 150)"
    # its first screen names the question, the two set-up commands and the answer table
    first = "\n".join(lines[:50])
    assert "fuse" in first.split("## Set-up")[0]
    assert "```bash\npip install" in first and "python -m pytest" in first
    assert "| question | case | what the solver answers | how far to trust it |" in first


def test_the_pictures_it_shows_exist_and_are_small():
    pictures = re.findall(r"\]\((renders/[^)]+\.(?:png|gif))\)", README)
    assert pictures
    for name in pictures:
        assert (ROOT / name).is_file(), f"README.md shows {name}, which does not exist"
        assert (ROOT / name).stat().st_size < 2_000_000, f"{name} is 2 MB or more"


def test_it_names_cases_and_sweeps():
    assert "cases/power25W_resolved.toml" in CASES and len(CASES) >= 4
    assert SWEEPS and INLINE and SETS


@pytest.mark.parametrize("command", INLINE)
def test_every_inline_command_parses(command):
    words = shlex.split(command)
    words = ["run", *words[3:]] if words[0] == "python" else words[1:]
    try:
        parser().parse_args(words)
    except SystemExit as e:
        raise AssertionError(f"README.md: {command} does not parse") from e


@pytest.mark.parametrize("override", SETS)
def test_every_override_it_shows_applies_to_the_main_case(override):
    load_case(ROOT / "cases/power25W_resolved.toml", [override])


@pytest.mark.parametrize("name", CASES)
def test_every_case_it_names_loads(name):
    assert (ROOT / name).is_file(), f"README.md names {name}, which does not exist"
    load_case(ROOT / name)


@pytest.mark.parametrize("name", SWEEPS)
def test_every_sweep_it_names_loads(name):
    from taichi_sls.jobs.sweep.spec import load_sweep

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
