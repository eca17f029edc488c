"""The seconds a melt lives (cases/sinter_hold.toml, studies/sinter_hold.py): a laser-melted pair
held on a bed between PA12's crystallisation and melting ranges stays molten and sinters as
Hopper's solution says at the temperature the run records."""

import numpy as np
import pytest

from taichi_sls.config import load_case
from taichi_sls.jobs.case_run import run_case
from taichi_sls.studies import references as ref
from taichi_sls.studies.sinter_hold import compare, hopper_at_history


def test_hopper_at_a_constant_temperature_is_hoppers_clock():
    """At a constant temperature the integrated clock is gamma t / (eta_N R0): a neck history
    taken from Hopper's solution itself is predicted back to round-off from any alignment."""
    m = load_case("sinter_hold").materials["PA12"]
    R0 = 20.0
    eta_N = 0.5 * m.viscosity_A_Pas * np.exp(-m.viscosity_b_1_C * 170.0)
    t = np.linspace(0.0, 1.0, 201)
    tau = 0.1 + m.surface_tension_N_m * t / (eta_N * R0 * 1e-6)
    neck = 2.0 * R0 * ref.hopper_neck_at(tau)
    pred = hopper_at_history(t, np.full_like(t, 170.0), neck, m, R0, align_s=0.25)
    after = t >= 0.25
    assert np.isnan(pred[~after]).all()
    assert np.allclose(pred[after], neck[after], rtol=1e-9)


# the plastic control runs on request: the default suite keeps the bundled case's own control
@pytest.mark.parametrize(
    "strain_control",
    ["total", *(pytest.param(c, marks=pytest.mark.slow) for c in ("plastic", "error"))],
)
def test_a_laser_melted_pair_sinters_as_hopper_says_at_its_temperature(tmp_path, strain_control):
    """The bundled case for its second (the implicit integrator, adaptive steps, backward-Euler
    heat): the pulse melts the pair, it cools to the 170 C bed and stays molten (it crystallises
    only below 150 C), and its neck follows Hopper's at the recorded
    temperature within the issue's 3 % at 1 s (measured -0.5 to -1.2 % over four sets of step
    controls, docs/record/implicit.md), within 6 % from 0.1 s on (measured up to +5.1 %: the clock
    runs at the pair's mean temperature, and while the pair cools its neck is hotter than the mean);
    molten and at 170 C throughout the hold; the neck has grown by 2.5 times. The same with the
    step controlled by the plastic (viscous) strain increment instead of the total one (measured
    -0.6 % at 1 s, at most +3.1 %, in 211 steps against 542), and by that strain's local error
    (strain_control = "error", max_strain_error 2e-3: -0.7 % at 1 s, at most +2.8 %, in 186
    steps)."""
    sets = ["output.png=false", "output.gif=false", f"time.strain_control={strain_control}"]
    case = load_case("sinter_hold", sets)
    summary = run_case(case, tmp_path, progress=False)
    assert summary["status"] == "complete"
    rows = compare(tmp_path)
    last = rows[-1]
    assert last["t_s"] == pytest.approx(1.0)
    late = [r for r in rows if r["t_s"] >= 0.1 * (1 - 1e-9)]
    assert len(late) >= 5
    print("neck against Hopper:", [(r["t_s"], r["difference"]) for r in late])
    assert all(r["molten_fraction"] == 1.0 for r in late)
    assert all(abs(r["T_mean_C"] - 170.0) < 0.1 for r in late)
    assert abs(last["difference"]) < 0.03
    assert all(abs(r["difference"]) < 0.06 for r in late)
    assert last["neck_um"] > 2.5 * rows[0]["neck_um"]


@pytest.mark.slow  # ~30 s
def test_a_melt_with_crystallisation_kinetics_lives_through_the_hold(tmp_path):
    """cases/sinter_kinetics.toml: sinter_hold with PA12's crystallisation kinetics instead of
    the range. At 170 C the kinetics' half time is 7640 s, so for the run's second the melt
    stays molten (measured: molten fraction 1 - 1.4e-12 at 1 s) and sinters as Hopper says
    within the bounds of the range's test above (measured -0.7 % at 1 s, at most +3.2 % from
    0.1 s on; the adaptive steps differ from sinter_hold's from round-off on: 474 against 482)."""
    case = load_case("sinter_kinetics", ["output.png=false", "output.gif=false"])
    summary = run_case(case, tmp_path, progress=False)
    assert summary["status"] == "complete"
    rows = compare(tmp_path)
    late = [r for r in rows if r["t_s"] >= 0.1 * (1 - 1e-9)]
    print("neck against Hopper:", [(r["t_s"], r["difference"]) for r in late])
    assert all(1.0 - r["molten_fraction"] < 1e-9 for r in late)
    assert all(abs(r["T_mean_C"] - 170.0) < 0.1 for r in late)
    assert abs(late[-1]["difference"]) < 0.03
    assert all(abs(r["difference"]) < 0.06 for r in late)
