"""The fusion outcome: frame schedules, the stop rule of a run to solidification, the verdict,
and small runs that stop by themselves."""

import json
import math

import imageio.v3 as iio
import numpy as np
import pytest
from helpers import PAPER_SCENE, deep_update, make_case

from taichi_sls.io.series import read_series
from taichi_sls.jobs.case_run import run_case
from taichi_sls.jobs.outcome import NeckHistory, describe, outcome
from taichi_sls.jobs.schedule import frame_steps, settled


def _case(extra: dict):
    base = deep_update(PAPER_SCENE, {"grid": {"spacing_um": 4.0}, "case": {"name": "t"}})
    return make_case(deep_update(base, extra))


def test_linear_frames_reach_the_end_time():
    case = _case({"time": {"end_s": 1e-4}, "output": {"frames": 7}})
    steps = list(frame_steps(case, 3e-8))
    assert len(steps) == 7 and steps[-1] * 3e-8 >= 1e-4
    assert len(set(np.diff([0, *steps]))) == 1  # equal chunks of whole steps


def test_log_frames_hit_1ms_and_stop_at_max_time():
    case = _case({"time": {"stop": "solidified", "max_s": 0.03}, "output": {"first_frame_s": 1e-6}})
    dt = 5e-8
    steps = list(frame_steps(case, dt))
    t = np.array(steps) * dt
    assert np.all(np.diff(steps) > 0)
    assert np.any(np.isclose(t, 1e-3, rtol=1e-9))  # the paper's 1 ms is a frame
    assert t[0] == pytest.approx(1e-6) and t[-1] == pytest.approx(0.03)
    assert len(steps) == 46  # 10 per decade from 1 us to 30 ms, plus the end


def test_a_laser_case_to_1ms_shows_its_transient_frame_by_frame():
    """The pair melts within 20 us and its neck is set within 0.1 ms: a laser case's frames are
    log-spaced by default, with 1 ms the last; spacing = "linear" or a number of frames keeps
    the old linear frames."""
    dt = 5e-8
    laser = {"lasers": [{"power_W": 25.0}], "time": {"end_s": 1e-3}}
    t = np.array(list(frame_steps(_case(laser), dt))) * dt
    assert len(t) == 31 and t[-1] == pytest.approx(1e-3)  # 10 per decade from 1 us
    assert np.sum(t <= 2e-5) >= 13 and np.sum(t <= 1e-4) >= 20
    linear = deep_update(laser, {"output": {"spacing": "linear"}})
    t = np.array(list(frame_steps(_case(linear), dt))) * dt
    assert len(t) == 20 and t[0] == pytest.approx(5e-5)
    # a case that asks for a number of frames keeps them linear under spacing = auto
    t = np.array(list(frame_steps(_case(deep_update(laser, {"output": {"frames": 4}})), dt)))
    assert len(t) == 4 and t[-1] * dt == pytest.approx(1e-3)


def test_settled_needs_lasers_off_solid_and_quiet():
    case = _case({"lasers": [{"power_W": 25.0, "off_s": 2e-5}], "time": {"stop": "solidified"}})
    quiet = {"molten_fraction": 0.0, "T_max_C": 145.0, "kinetic_ratio": 1e-9}
    assert settled(quiet, case, 3e-5)
    assert not settled(quiet, case, 1e-5)  # the beam is still on
    assert not settled({**quiet, "molten_fraction": 1e-6}, case, 3e-5)
    assert not settled({**quiet, "kinetic_ratio": 1e-2}, case, 3e-5)


def test_an_unheated_case_settles_only_once_its_neck_stops_moving():
    """Without a laser the pair is solid from t = 0 and its kinetic energy swings through the
    threshold while the adhesive contact still moves (the 4 um fillet pair at h = 4 um: two
    frames at 25 and 32 us caught the swing at one neck, 20.353 and 20.362 um, with 8.7e-5 of
    the surface energy)."""
    case = _case({"lasers": [], "time": {"stop": "solidified"}})
    quiet = {"molten_fraction": 0.0, "T_max_C": 140.0, "kinetic_ratio": 8.7e-5}
    last = {**quiet, "contact_line_um": 20.362}
    loud = {**quiet, "kinetic_ratio": 1.7e-4}
    swing = [{**loud, "contact_line_um": 20.236}, {**quiet, "contact_line_um": 20.353}]
    assert not settled(last, case, 3.2e-5)  # no frames before to compare with
    assert not settled(last, case, 3.2e-5, [{**loud, "contact_line_um": 20.40}, *swing])
    held = [{**quiet, "contact_line_um": n} for n in (20.350, 20.355, 20.360)]
    assert settled(last, case, 3.2e-5, held)
    assert not settled(last, case, 3.2e-5, [*held[:2], {**held[2], "contact_line_um": 20.0}])
    assert not settled({**last, "kinetic_ratio": 1e-3}, case, 3.2e-5, held)
    # a heated case is judged at refreezing as before: its creeping neck does not hold it
    heated = _case({"lasers": [{"power_W": 25.0, "off_s": 2e-5}], "time": {"stop": "solidified"}})
    assert settled({**last, "T_max_C": 145.0}, heated, 3e-5, swing)


def _history(necks, molten, times):
    h = NeckHistory()
    for n, m, t in zip(necks, molten, times, strict=True):
        h.add({"t_s": t, "contact_line_um": n, "molten_fraction": m})
    return h


LASER = {"lasers": [{"power_W": 25.0}]}


def test_verdict_follows_its_rule():
    case = _case({**LASER, "fusion": {"baseline": "initial"}})
    h = _history([8.0, 8.5, 9.0, 9.0], [0.0, 0.9, 0.0, 0.0], [0.0, 1e-3, 2e-2, 5e-2])
    final = {"contact_line_um": 9.0, "T_peak_C": 300.0}
    in_neck = np.array([True, True, False])
    melted = np.array([1e-3, 2e-3, 0.0])
    o = outcome(case, h, final, melted, in_neck, solidified=True)
    assert o["fused"] is True and o["neck_1ms_um"] == 8.5 and o["neck_refrozen_um"] == 9.0
    assert o["neck_growth"] == pytest.approx(0.125)
    assert o["time_above_melt_s"]["max"] == 2e-3
    # the neck region did not melt through: not fused, however the neck grew
    o = outcome(case, h, final, np.array([1e-3, 0.0, 0.0]), in_neck, solidified=True)
    assert o["fused"] is False and o["neck_region_melted_fraction"] == 0.5
    # still molten at the end: no verdict
    assert outcome(case, h, final, melted, in_neck, solidified=False)["fused"] is None
    # grew less than the margin
    small = {"contact_line_um": 8.2, "T_peak_C": 300.0}
    assert outcome(case, h, small, melted, in_neck, solidified=True)["fused"] is False


def test_verdict_against_the_unheated_neck():
    """The default baseline is the neck the same pair reaches unheated: a refrozen neck 12.5 %
    above the initial one but only 2.3 % above the unheated (adhesion) neck is not fused; the
    summary gives both growths, and a failed unheated run leaves no verdict."""
    case = _case(LASER)
    h = _history([8.0, 8.5, 9.0, 9.0], [0.0, 0.9, 0.0, 0.0], [0.0, 1e-3, 2e-2, 5e-2])
    final = {"contact_line_um": 9.0, "T_peak_C": 300.0}
    in_neck, melted = np.array([True, True]), np.array([1e-3, 2e-3])
    o = outcome(case, h, final, melted, in_neck, solidified=True, baseline_um=8.8)
    assert o["fused"] is False and o["baseline"] == "unheated"
    assert o["neck_growth"] == pytest.approx(0.125)
    assert o["neck_growth_over_unheated"] == pytest.approx(9.0 / 8.8 - 1.0)
    assert "unheated" in describe(o)
    o = outcome(case, h, final, melted, in_neck, solidified=True, baseline_um=8.4)
    assert o["fused"] is True
    o = outcome(case, h, final, melted, in_neck, solidified=True, baseline_um=float("nan"))
    assert o["fused"] is None and "unheated" in o["no_verdict"]


@pytest.mark.parametrize(
    "extra",
    [
        {},  # no [[lasers]] at all
        {"lasers": [{"power_W": 0.0}]},
        {**LASER, "physics": {"thermal": False}},  # an isothermal run: the beam heats nothing
    ],
)
def test_no_verdict_without_a_laser(extra):
    """A pair that coalesces with no laser (Hopper's isothermal discs) is neither fused nor not
    fused by a laser: the verdict is null and the summary and printout say why."""
    h = _history([8.0, 12.0], [0.0, 0.0], [0.0, 1e-3])
    o = outcome(
        _case(extra),
        h,
        {"contact_line_um": 12.0, "T_peak_C": 140.0},
        np.array([1e-3, 1e-3]),
        np.array([True, True]),
        solidified=True,
    )
    assert o["fused"] is None and o["no_verdict"] == "no laser in this case"
    assert describe(o).startswith("outcome: no verdict (no laser in this case)")
    assert "NOT FUSED" not in describe(o)
    with_laser = outcome(
        _case(LASER),
        h,
        {"contact_line_um": 12.0, "T_peak_C": 300.0},
        np.array([1e-3, 1e-3]),
        np.array([True, True]),
        solidified=True,
        baseline_um=8.0,
    )
    assert with_laser["fused"] is True and with_laser["no_verdict"] is None


# a run to solidification in seconds: coarse grid, the inertia scaled so that the step is the
# thermal one (the flow is quasi-static at these times), few frames
FAST = {
    "time": {"stop": "solidified", "max_s": 0.2},
    "solver": {"mass_scale": 1e4},
    "output": {"png": False, "gif": False, "frames_per_decade": 4},
}


def test_a_warmed_pair_is_not_fused_and_stops_soon_after_the_beam(tmp_path):
    case = _case(deep_update(FAST, {"lasers": [{"power_W": 2.0, "off_s": 2e-5}]}))
    s = run_case(case, tmp_path / "warm", progress=False)
    o = s["outcome"]
    print(json.dumps(o, indent=1), s["simulated_s"])
    assert s["status"] == "complete" and o["solidified"]
    assert o["fused"] is False and o["neck_region_melted_fraction"] == 0.0
    assert o["T_peak_C"] < 175.0  # below T_m: the beam only warms
    assert s["simulated_s"] < 0.05  # it stops by itself, long before max_s
    assert (tmp_path / "warm" / "outcome.png").is_file()
    # a pair keeps its pictures: the contact line and peak temperature side by side (the bed's
    # series and panels are a bed's only: tests/io/test_bed_plots.py)
    assert "relative_density" not in read_series(tmp_path / "warm" / "timeseries.csv")
    assert iio.imread(tmp_path / "warm" / "timeseries.png").shape[:2] == (320, 840)


# slow: a pair cooled to solid (~20 s); the stop rule stays in default
# (test_a_warmed_pair_is_not_fused_and_stops_soon_after_the_beam)
@pytest.mark.slow
def test_a_molten_pair_stops_when_everything_is_below_T_c(tmp_path):
    """A pair started fully molten at 200 C on the 140 C plate, no laser: the run ends by
    itself once every point is below T_c, and the energy balance holds to round-off over the
    whole run (enthalpy lost = heat out through the plate)."""
    case = _case(deep_update(FAST, {"thermal": {"initial_C": 200.0}}))
    s = run_case(case, tmp_path / "melt", progress=False)
    fin, ini = s["final"], s["initial"]
    assert s["status"] == "complete"
    assert fin["molten_fraction"] == 0.0 and fin["T_max_C"] <= 146.0
    assert ini["molten_fraction"] == 1.0
    loss = ini["enthalpy_J_per_m"] - fin["enthalpy_J_per_m"]
    assert loss == pytest.approx(fin["heat_out_J_per_m"], rel=1e-9)
    assert s["outcome"]["neck_region_melted_fraction"] == 1.0
    assert math.isfinite(s["outcome"]["neck_final_um"])


def test_max_time_is_marked_not_complete(tmp_path):
    case = _case(deep_update(FAST, {"thermal": {"initial_C": 200.0}, "time": {"max_s": 1e-3}}))
    s = run_case(case, tmp_path / "short", progress=False)
    assert s["status"] == "max_time" and s["outcome"]["fused"] is None
    assert any("max_s" in w for w in s["warnings"])


def test_the_progress_bar_of_an_adaptive_run_shows_its_step_not_a_guess(capsys):
    """The pace of an adaptive run's first steps (a thousandth of its later ones) says nothing
    of the time left: the bar shows the step instead; a fixed-step run estimates the time left
    from its pace."""
    from taichi_sls.jobs.progress import Progress

    for adaptive in (True, False):
        bar = Progress(1.0, 0.0, adaptive=adaptive)
        bar.note({"molten_fraction": 0.5, "t_s": 1e-3, "T_max_C": 300.0})
        bar.update(1e-3, 40.0, 2.5e-5)
        bar.close()
        err = capsys.readouterr().err
        assert ("dt 2.5e-05 s" in err) == adaptive
        assert ("s left" in err) != adaptive
