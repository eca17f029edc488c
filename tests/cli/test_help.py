"""The command line's own pages load nothing heavy: ``taichi-sls --help``, ``taichi-sls bench
--help`` and ``taichi-sls case`` import neither Taichi nor Dask (each subcommand's module is
imported only when the subcommand is named); every ``bench`` name reaches its module, and a
benchmark asked of a package without bench/ says where benchmarks live."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

from taichi_sls import cli

ROOT = Path(__file__).resolve().parents[2]
# runs the command line in a fresh interpreter, then names the heavy modules it imported
WRAPPER = """
import sys
from taichi_sls.cli import main
try:
    main(sys.argv[1:])
except SystemExit:
    pass
sys.stdout.flush()
print("LOADED:", *sorted(m for m in ("taichi", "dask", "distributed") if m in sys.modules))
"""


@pytest.mark.parametrize(
    "argv, says",
    [
        (["--help"], "SUBCOMMAND"),
        (["bench", "--help"], "developer's benchmarks"),
        (["sweep", "--help"], "--scheduler"),
        (["case"], "# Case file reference"),
    ],
)
def test_help_and_the_case_reference_load_no_taichi(argv, says):
    done = subprocess.run(
        [sys.executable, "-c", WRAPPER, *argv], capture_output=True, text=True, cwd=ROOT
    )
    assert says in done.stdout, done.stdout + done.stderr
    loaded = done.stdout.rsplit("LOADED:", 1)[1].split()
    assert loaded == [], f"taichi-sls {' '.join(argv)} imported {loaded}"


@pytest.mark.parametrize("name", [*cli.STUDIES, *cli.BENCHMARKS])
def test_every_bench_name_reaches_its_module(name, capsys):
    with pytest.raises(SystemExit) as e:
        cli.parser().parse_args(["bench", name, "--help"])
    assert e.value.code == 0
    assert f"usage: taichi-sls bench {name}" in capsys.readouterr().out


def test_the_benchmarks_listed_are_the_scripts_in_bench():
    scripts = {p.stem for p in (ROOT / "bench").glob("*.py") if "def add_parser(" in p.read_text()}
    assert scripts == set(cli.BENCHMARKS)


def test_a_benchmark_outside_a_checkout_says_where_benchmarks_live(monkeypatch, capsys):
    monkeypatch.setattr(cli, "bench_root", lambda: None)
    with pytest.raises(SystemExit) as e:
        cli.parser().parse_args(["bench", "speed"])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert re.search(r"bench/speed\.py in a checkout of the repository", err), err


def test_a_study_runs_from_the_installed_package(monkeypatch):
    monkeypatch.setattr(cli, "bench_root", lambda: None)  # no bench/: the studies still parse
    args = cli.parser().parse_args(["bench", "refinement", "--cases", "power25W_coarse"])
    assert args.command == "bench" and callable(args.func)
