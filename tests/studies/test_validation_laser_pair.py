"""The laser-pulsed pair (studies/validation/laser_pair.py, cases/validation/pulse_pair_laser.toml):
the bisection's premise (the peak rises with the absorbed fraction) on two short runs, and the
cooling read beside the measured temperature."""

import numpy as np
import pytest

from taichi_sls.studies.validation.laser_pair import COOLING_S, cooling_rows, peak_C, run_laser
from taichi_sls.studies.validation.measured import load_pulse_temperature

# speed only: a coarse grid, no frames drawn, no kernel optimisation
FAST = ("grid.spacing_um=12.5", "output.png=false", "solver.optimize=false")


def test_more_absorbed_heat_gives_a_hotter_peak(tmp_path):
    """0.2 ms of the pulse at A = 0.25 and 0.5: the hottest point's rise above the 155 C
    chamber at least 1.5 times larger at twice the A (twice the heat; less than twice where
    the latent heat of melting takes some: 1.5 leaves room for it), and above the chamber."""
    low = run_laser(0.25, 2e-4, tmp_path / "a", FAST)
    high = run_laser(0.5, 2e-4, tmp_path / "b", FAST)
    rise_low, rise_high = peak_C(low) - 155.0, peak_C(high) - 155.0
    assert rise_low > 0.0
    assert rise_high > 1.5 * rise_low


def test_the_cooling_rows_read_between_points():
    t = np.array([0.0, 0.1, 0.3, 0.5])
    series = {"t_s": t, "T_max_C": 200.0 - 10 * t, "T_mean_C": 180.0 - 10 * t}
    rows = cooling_rows(series)
    measured = load_pulse_temperature()
    assert [r["t_s"] for r in rows] == list(COOLING_S)
    assert rows[1]["T_max_C"] == pytest.approx(198.0)
    m = float(np.interp(0.2, [p.t_s for p in measured], [p.T_C for p in measured]))
    assert rows[1]["measured_C"] == pytest.approx(m)
    assert rows[1]["error_mean_K"] == pytest.approx(178.0 - m)
