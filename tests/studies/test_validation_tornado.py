"""The tornado of the held pulsed pair (studies/validation/tornado.py): the measured a / R read
between points, the rows of a run, a short variant run against the case, and the plot."""

import math

import numpy as np
import pytest

from taichi_sls.studies.validation.measured import NeckPoint, load_pulse_neck
from taichi_sls.studies.validation.tornado import (
    REPORT_S,
    VARIANTS,
    measured_at,
    plot_tornado,
    rows_of,
    run_variant,
)

# speed only: a coarse grid, no frames drawn, no kernel optimisation
FAST = ("grid.spacing_um=12.5", "output.png=false", "solver.optimize=false")


def test_measured_at_reads_between_points_and_not_outside():
    pts = [NeckPoint("s", 125.0, t, a, "src", "") for t, a in ((0.1, 0.2), (0.3, 0.6))]
    assert measured_at(pts, 0.2) == pytest.approx(0.4)
    assert measured_at(pts, 0.1) == pytest.approx(0.2)
    assert math.isnan(measured_at(pts, 0.05)) and math.isnan(measured_at(pts, 0.31))


def test_every_input_has_a_low_and_a_high_end_with_a_source():
    params = {v.parameter for v in VARIANTS if v.end != "case"}
    for p in params:
        ends = sorted(v.end for v in VARIANTS if v.parameter == p)
        assert ends == ["high", "low"], p
    assert all(v.source for v in VARIANTS)
    assert [v.end for v in VARIANTS].count("case") == 1


def test_rows_leave_times_past_the_run_empty():
    measured = load_pulse_neck()
    t, a = np.array([0.0, 0.2, 0.6]), np.array([0.2, 0.3, 0.5])
    rows = rows_of(VARIANTS[0], t, a, measured)
    assert [r["t_s"] for r in rows] == list(REPORT_S)
    assert rows[0]["computed"] == pytest.approx(0.25)  # linear between frames at 0.1 s
    assert rows[0]["error"] == pytest.approx(0.25 - measured_at(measured, 0.1))
    assert math.isnan(rows[2]["computed"])  # 0.9682 s: past the run's 0.6 s


def test_half_the_viscosity_grows_the_neck_faster(tmp_path):
    """The case and its low-viscosity end to 0.05 s on a coarse grid: both start from the same
    seeded neck (the same points), and the melt half as viscous has grown its neck more (a
    Newtonian pair's growth rate goes as 1 / eta: strictly more, no tolerance needed)."""
    by_name = {v.name: v for v in VARIANTS}
    t0, a0 = run_variant(by_name["case"], tmp_path, 0.05, FAST)
    t1, a1 = run_variant(by_name["viscosity_low"], tmp_path, 0.05, FAST)
    assert t0[-1] == pytest.approx(0.05) and t1[-1] == pytest.approx(0.05)
    assert a1[0] == pytest.approx(a0[0], abs=1e-12)
    assert a1[-1] - a1[0] > a0[-1] - a0[0] > 0.0


def test_the_plot_is_drawn_and_small(tmp_path):
    rows = []
    for i, v in enumerate(VARIANTS):
        for ts in REPORT_S:
            rows.append(
                {
                    "name": v.name,
                    "parameter": v.parameter,
                    "end": v.end,
                    "t_s": ts,
                    "computed": 0.3 + 0.01 * i,
                    "measured": 0.5,
                }
            )
    path = tmp_path / "t.png"
    plot_tornado(rows, path)
    assert 0 < path.stat().st_size < 2_000_000
