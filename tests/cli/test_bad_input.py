"""The command lines themselves, as a user starts them: a bad case file ends with one line and
exit status 2, never a traceback."""

from pathlib import Path

import pytest
from helpers import run_command

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(
    "module, content, says",
    [
        (["taichi_sls.run"], b"", "the case file is empty"),
        (["taichi_sls", "run"], b"\xff\xfe[\x00c\x00", "a binary file"),
        (["taichi_sls.run"], "x = 'é'".encode("latin-1"), "not UTF-8 text"),
    ],
    ids=["empty", "utf16_binary", "latin1"],
)
def test_python_m_bad_file_one_line(tmp_path, module, content, says):
    p = tmp_path / "bad.toml"
    p.write_bytes(content)
    r = run_command(module, p, tmp_path / "o")
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2, r.stderr
    assert len(lines) == 1 and lines[0].startswith(f"error: {p}: ") and says in lines[0]
    assert "Traceback" not in r.stderr and r.stdout == ""


def test_a_pair_that_never_settles_ends_with_its_error(tmp_path, capsys):
    """contact.settle failing before the first frame (time.max_s too short) ends the run as
    failed with the settle's one error line and the failed exit status, not a KeyError."""
    from taichi_sls.cli import EXIT_CODES, main

    code = main(
        [
            "run",
            str(ROOT / "cases" / "power25W_resolved.toml"),
            "--out",
            str(tmp_path / "o"),
            "--no-progress",
            "--set",
            "grid.spacing_um=4",
            "--set",
            "time.max_s=3e-5",
            "--set",
            "output.gif=false",
        ]
    )
    err = capsys.readouterr().err
    assert code == EXIT_CODES["failed"] != 0
    assert "error: contact.settle: the bodies had not settled by time.max_s = 3e-05 s" in err
    assert "Traceback" not in err and "KeyError" not in err
    assert "raise time.max_s" in err  # the pair is solid: the kinetic energy had not decayed


def test_settling_a_scene_above_its_crystallisation_names_the_cause(tmp_path, capsys):
    """A pair held above its crystallisation temperature (initial 150 C against the paper's
    146 C) is never solid, so contact.settle cannot end however still it is: the error says
    so, with the temperatures, instead of blaming the kinetic energy."""
    from taichi_sls.cli import EXIT_CODES, main

    sets = ["grid.spacing_um=4", "time.max_s=3e-5", "output.gif=false"]
    sets += ["thermal.initial_C=150", "boundary.bottom.temperature_C=150"]
    args = ["run", str(ROOT / "cases" / "power25W_resolved.toml"), "--out", str(tmp_path / "o")]
    code = main(args + ["--no-progress"] + [a for s in sets for a in ("--set", s)])
    err = capsys.readouterr().err
    assert code == EXIT_CODES["failed"] != 0
    assert "had not settled" in err and "not solid: peak 150.00 C" in err, err
    assert "crystallisation at 146 C" in err and "Traceback" not in err


def test_a_missing_temperature_table_is_one_line(tmp_path):
    """thermal.imposed_temperature_csv naming no file: one line with the key, the value (made
    absolute, relative to the case file) and what is allowed; exit status 2."""
    p = tmp_path / "held.toml"
    p.write_text(
        "[[bodies]]\ncenter_um = [40.0, 20.0]\nradius_um = 20.0\n"
        '[boundary.bottom]\nthermal = "insulated"\n'
        '[thermal]\nimposed_temperature_csv = "T.csv"\n'
    )
    r = run_command(["taichi_sls.run"], p, tmp_path / "o")
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2, r.stderr
    assert len(lines) == 1 and "Traceback" not in r.stderr
    assert f"thermal.imposed_temperature_csv = '{tmp_path / 'T.csv'}': no such file" in lines[0]
    assert "allowed: a CSV file with columns t_s, T_C" in lines[0]
