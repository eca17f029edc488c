"""The hot-stage calibration (studies/validation/hot_stage.py): the rescaling recovers a known
viscosity from a series made at it, the calibrated series is met at the calibration neck, the
prediction scales with R, and the scaled pair runs self-similar."""

import math

import numpy as np
import pytest

from taichi_sls.studies.references.hopper import hopper_neck_at
from taichi_sls.studies.references.viscosity import arrhenius_viscosity
from taichi_sls.studies.validation.hot_stage import (
    CALIBRATION_NECK,
    PairRun,
    calibrate,
    first_crossing,
    measured_time,
    predict,
    run_pair,
    scaling_gap,
    shifted_tau,
)
from taichi_sls.studies.validation.measured import NeckPoint

GAMMA, ETA_REF, T_REF_C, E = 0.0343, 4175.0, 172.0, 32.5e3


def _hopper_run(R_um, T_C, tau0=0.2, n=1000):
    """A 'run' that follows Hopper's exact a / R from tau0 (a seeded neck) on."""
    eta = float(arrhenius_viscosity(T_C + 273.15, ETA_REF, T_REF_C + 273.15, E))
    tau = np.linspace(tau0, 3.0, n)
    t = (tau - tau0) * eta * R_um * 1e-6 / GAMMA
    return PairRun(R_um, T_C, eta, GAMMA, t, np.asarray(hopper_neck_at(tau)))


def _series(name, R_um, eta):
    taus = np.linspace(0.0, 2.5, 120)
    t = taus * eta * R_um * 1e-6 / GAMMA
    return [
        NeckPoint(name, R_um, float(ti), float(a), "src", "")
        for ti, a in zip(t, np.asarray(hopper_neck_at(taus)), strict=True)
    ]


def test_first_crossing_is_linear_between_samples():
    x, a = np.array([0.0, 1.0, 2.0]), np.array([0.1, 0.3, 0.7])
    assert first_crossing(x, a, 0.5) == pytest.approx(1.5)
    assert math.isnan(first_crossing(x, a, 0.8))


def test_the_shift_puts_tau_zero_at_a_point_contact():
    run = _hopper_run(30.0, 200.0, tau0=0.3)
    assert shifted_tau(run)[0] == pytest.approx(0.3, rel=1e-6)


def test_the_calibration_recovers_the_viscosity_a_series_was_made_at():
    """A series made from Hopper's curve at eta = 800 Pa s: the run (Hopper's curve at 200 C,
    from a seeded neck) rescaled gives 800 Pa s back (0.1 %: the interpolation between 1000
    samples), the law's temperature for it, and its time at the calibration neck exactly."""
    run = _hopper_run(32.0, 200.0)
    series = {"A": _series("A", 32.0, 800.0), "B": _series("B", 40.0, 800.0)}
    cal = calibrate(run, series["A"], ETA_REF, T_REF_C, E)
    assert cal.eta_Pas == pytest.approx(800.0, rel=1e-3)
    back = float(arrhenius_viscosity(cal.T_C + 273.15, ETA_REF, T_REF_C + 273.15, E))
    assert back == pytest.approx(cal.eta_Pas, rel=1e-9)
    rows = predict(run, cal, series)
    for r in rows:  # both radii predicted from R alone: the same law made them (0.2 %)
        assert r["error_s"] == pytest.approx(0.0, abs=2e-3 * r["t_measured_s"])
    a05 = next(r for r in rows if r["series"] == "A" and r["neck"] == CALIBRATION_NECK)
    assert a05["calibrated_on"] and a05["t_predicted_s"] == pytest.approx(
        measured_time(series["A"], CALIBRATION_NECK), rel=1e-9
    )


def test_the_scaling_gap_is_zero_for_one_law_and_not_for_another():
    same = scaling_gap(_hopper_run(32.0, 200.0), _hopper_run(25.0, 220.0, tau0=0.25))
    assert same["max_abs_a_over_R"] < 1e-3 and abs(same["tau_rel_at_1"]) < 1e-3
    slow = _hopper_run(25.0, 220.0)
    slow = PairRun(slow.radius_um, slow.T_C, slow.eta_Pas, GAMMA, 1.2 * slow.t_s, slow.a_over_R)
    assert scaling_gap(_hopper_run(32.0, 200.0), slow)["tau_rel_at_0.5"] > 0.05


@pytest.mark.slow  # ~60 s: two pair runs
def test_the_scaled_pair_seeds_the_same_neck_at_any_radius(tmp_path):
    """Every length of the case scales with R, so two radii seed the same points in units of R:
    the first a / R is the same (1e-9), whatever the temperature."""
    a = run_pair(25.84, 220.0, 2e-3, tmp_path)
    b = run_pair(37.9, 190.0, 2e-3, tmp_path)
    assert a.a_over_R[0] == pytest.approx(b.a_over_R[0], abs=1e-9)
    assert a.t_s[-1] == pytest.approx(2e-3)
    assert b.eta_Pas > a.eta_Pas  # 190 C: more viscous than 220 C


def test_the_overrides_scale_every_length_of_the_case_with_R(tmp_path):
    """At the case's own R = 125 um the scaled pair is the case; at R = 25 um every length is a
    fifth of it (to rounding)."""
    from taichi_sls.config import load_case
    from taichi_sls.config.loading import bundled_root
    from taichi_sls.studies.validation.hot_stage import CASE_PATH, pair_overrides

    base = load_case(bundled_root() / CASE_PATH)
    table = tmp_path / "held.csv"
    table.write_text("t_s,T_C\n0.0,200.0\n")
    same = load_case(bundled_root() / CASE_PATH, pair_overrides(125.0, 200.0, table, 1.0))
    small = load_case(bundled_root() / CASE_PATH, pair_overrides(25.0, 200.0, table, 1.0))
    for case, s in ((same, 1.0), (small, 0.2)):
        assert case.grid.spacing_um == pytest.approx(s * base.grid.spacing_um, rel=1e-12)
        assert case.domain.width_um == pytest.approx(s * base.domain.width_um, rel=1e-12)
        assert case.domain.height_um == pytest.approx(s * base.domain.height_um, rel=1e-12)
        assert case.contact.fillet_radius_um == pytest.approx(
            s * base.contact.fillet_radius_um, rel=1e-12
        )
        for b, b0 in zip(case.bodies, base.bodies, strict=True):
            assert b.radius_um == pytest.approx(s * b0.radius_um, rel=1e-12)
            assert list(b.center_um) == pytest.approx([s * c for c in b0.center_um], rel=1e-12)
