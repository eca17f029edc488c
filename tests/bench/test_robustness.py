"""A small version of the robustness matrix (``taichi-sls bench robustness`` runs the whole one)."""

import pytest

from bench.robustness import matrix, run_row

QUICK = [r for r in matrix() if r.quick]


@pytest.mark.parametrize("row", QUICK, ids=[r.name for r in QUICK])
def test_robustness_row_is_stable_or_caught(row):
    r = run_row(row, frames=4)
    assert r["result"] in ("stable", "caught"), r["message"]
    if row.dt_factor is not None and row.dt_factor >= 4:
        assert r["result"] == "caught" and "likely cause" in r["message"]
    if row.dt_factor is not None and row.dt_factor <= 0.5:
        assert r["result"] == "stable"


@pytest.mark.slow
def test_full_robustness_matrix_has_no_uncaught_failures(tmp_path):
    from taichi_sls.cli import main

    assert main(["bench", "robustness", "--out", str(tmp_path)]) == 0
