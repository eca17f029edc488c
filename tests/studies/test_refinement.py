"""The refinement study's arithmetic (observed order, Richardson estimate, relative change), its
table from a hand-made refinement.csv, and (slow) a tiny study end to end."""

import csv
import math

import pytest

from taichi_sls.config import load_case
from taichi_sls.studies.refinement import COLUMNS, _step_scaling, plan
from taichi_sls.studies.refinement_report import plot, read_csv, rel_change, richardson, write_table


@pytest.mark.parametrize(
    "vals, order, estimate",
    [
        ((10.0, 6.0, 5.0), 2.0, 5.0 - 1.0 / 3.0),  # differences 4, 1: p = 2, 5 + (5 - 6) / 3
        ((1.0, 1.5, 1.75), 1.0, 2.0),  # rising: -0.5, -0.25: p = 1, 1.75 + 0.25 / 1
        ((10.0, 9.0, 8.99), math.log2(100.0), 8.99 - 0.01 / 15.0),  # p 6.64 clamped to 4
        ((10.0, 9.0, 8.2), math.log2(1.25), 8.2 - 0.8 / (math.sqrt(2.0) - 1.0)),  # 0.32 -> 0.5
    ],
)
def test_richardson_against_hand_computed_numbers(vals, order, estimate):
    e = richardson(*vals)
    assert e.order == pytest.approx(order, rel=1e-12)
    assert e.estimate == pytest.approx(estimate, rel=1e-12)
    assert ("clamped" in e.note) == (order > 4 or order < 0.5)


def test_richardson_other_ratio():
    # ratio 3: differences 9, 1 -> p = 2, estimate 1 + (1 - 2) / (9 - 1)
    e = richardson(11.0, 2.0, 1.0, ratio=3.0)
    assert e.order == pytest.approx(2.0) and e.estimate == pytest.approx(1.0 - 1.0 / 8.0)


@pytest.mark.parametrize(
    "vals, estimate, note",
    [
        ((10.0, 8.0, 9.0), math.nan, "not monotone"),
        ((8.0, 8.0, 9.0), math.nan, "f_4h = f_2h"),
        ((10.0, 8.0, 8.0), 8.0, "converged"),  # the finest difference vanishes: f_h stands
        ((10.0, 9.5, 8.5), math.nan, "do not shrink"),  # p = -1: diverging
        ((10.0, 9.0, 8.0), math.nan, "do not shrink"),  # p = 0: equal steps, no limit
        ((10.0, math.nan, 8.5), math.nan, "missing"),
    ],
)
def test_richardson_without_an_order(vals, estimate, note):
    e = richardson(*vals)
    assert math.isnan(e.order) or e.order <= 0
    assert (math.isnan(e.estimate) and math.isnan(estimate)) or e.estimate == estimate
    assert note in e.note


def test_rel_change():
    assert rel_change(20.0, 21.0) == pytest.approx(0.05)
    assert rel_change(-20.0, -21.0) == pytest.approx(-0.05)
    assert math.isnan(rel_change(0.0, 1.0)) and math.isnan(rel_change(math.nan, 1.0))


def test_plan_runs_every_spacing_at_the_default_dt_and_the_dt_factors_at_one_spacing():
    runs = plan(["a"], [4.0, 2.0, 1.0], [1.0, 0.5, 0.25], 2.0)
    assert runs == [
        ("a", 4.0, 1.0),
        ("a", 2.0, 1.0),
        ("a", 1.0, 1.0),
        ("a", 2.0, 0.5),
        ("a", 2.0, 0.25),
    ]


def _csv(path, rows):
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS, restval="")
        w.writeheader()
        w.writerows(rows)


def test_table_from_a_hand_made_csv(tmp_path):
    def row(case, h, f, neck, T, status="complete", refrozen=""):
        return {
            "case": case,
            "h_um": h,
            "dt_factor": f,
            "dt_s": 2.5e-8 * h * f,
            "status": status,
            "neck_1ms_um": neck,
            "neck_refrozen_um": refrozen,
            "T_peak_C": T,
        }

    rows = [
        # "A": neck 18, 22, 21, 20.75 -> three finest 22 / 21 / 20.75: p = 2, 20.75 - 0.25 / 3
        row("A", 4, 1, 18.0, 300.0),
        row("A", 2, 1, 22.0, 320.0),
        row("A", 1, 1, 21.0, 326.0),
        row("A", 0.5, 1, 20.75, 329.0),
        row("A", 2, 0.5, 22.0 * 1.02, 321.0),  # +2 % when dt halves
        row("A", 2, 0.25, 22.0 * 1.02 * 0.99, 321.0),  # -1 % when it halves again
        # "B": its finest run failed: the values say so and there is no estimate
        row("B", 4, 1, 15.0, 200.0, refrozen=15.5),
        row("B", 2, 1, 14.0, 210.0, refrozen=14.5),
        row("B", 1, 1, "", "", status="failed"),
    ]
    _csv(tmp_path / "refinement.csv", rows)
    text = write_table(tmp_path / "refinement.csv", tmp_path / "refinement_table.md", at=2.0)
    assert (tmp_path / "refinement_table.md").read_text() == text
    lines = {tuple(c.strip() for c in line.split("|")[1:3]): line for line in text.splitlines()}
    a = lines[("A", "neck at 1 ms (um)")].split("|")
    assert a[3].strip() == "2 / 1 / 0.5" and a[4].strip() == "22 / 21 / 20.75"
    assert a[5].strip() == "2.00" and a[6].strip() == f"{20.75 - 0.25 / 3:.4g}"
    assert a[7].strip() == f"{abs(22 / (20.75 - 0.25 / 3) - 1):.1%}"  # h = 2 um off the estimate
    assert a[8].strip() == "+2.0%" and a[9].strip() == "-1.0%"
    t = lines[("A", "peak T (C)")].split("|")
    assert t[5].strip() == "1.00"  # differences -6, -3: first order
    assert t[6].strip() == "332"  # 329 + 3 / (2 - 1)
    assert ("A", "neck refrozen (um)") not in lines  # no run refroze: no row
    b = lines[("B", "neck refrozen (um)")].split("|")
    assert b[3].strip() == "4 / 2 / 1" and b[4].strip() == "15.5 / 14.5 / failed"
    assert b[5].strip() == "nan" and b[6].strip() == "nan (h = 1 um failed)"
    assert read_csv(tmp_path / "refinement.csv")[-1]["status"] == "failed"
    plot(read_csv(tmp_path / "refinement.csv"), tmp_path / "refinement.png")
    assert (tmp_path / "refinement.png").stat().st_size > 0


@pytest.mark.slow
def test_refinement_study_end_to_end(tmp_path):
    from taichi_sls.cli import main

    args = ["bench", "refinement", "--out", str(tmp_path), "--cases", "power25W_coarse"]
    args += ["--spacings", "8", "4", "--dt-factors", "1", "0.5", "--at", "8"]
    args += ["--set", "time.end_s=1e-5"]
    assert main(args) == 0
    rows = read_csv(tmp_path / "refinement.csv")
    assert [(r["h_um"], r["dt_factor"]) for r in rows] == [
        ("8.0", "1.0"),
        ("4.0", "1.0"),
        ("8.0", "0.5"),
    ]
    assert all(r["status"] == "complete" for r in rows)
    assert float(rows[2]["dt_s"]) == pytest.approx(1e-7)  # 2.5e-8 s per um x 8 um x 1/2
    assert all(float(r["neck_initial_um"]) > 0 and float(r["T_peak_C"]) > 140 for r in rows)
    for name in ("refinement_table.md", "refinement.png"):
        assert (tmp_path / name).is_file()
    # a second study reads the finished runs instead of running them again
    before = (tmp_path / "power25W_coarse" / "h8um_dt1" / "summary.json").stat().st_mtime_ns
    assert main(args) == 0
    assert (tmp_path / "power25W_coarse" / "h8um_dt1" / "summary.json").stat().st_mtime_ns == before


def test_a_dt_factor_scales_a_step_the_case_chooses_itself():
    # the study sets time.dt_s per h; a --set time.dt_s=auto after it would leave a dt factor
    # without effect (the "dt/2" run the same as dt's): the factor moves to what sets the step
    fixed = load_case("power25W", ["time.dt_s=5e-8"])
    assert _step_scaling(fixed, 0.5) == []
    explicit = load_case("power25W", ["time.dt_s=auto"])
    assert _step_scaling(explicit, 0.5) == [f"time.safety={explicit.time.safety * 0.5:.6g}"]
    hybrid = load_case("power25W", ["time.dt_s=auto", "time.integrator=hybrid"])
    halved = load_case("power25W", ["time.dt_s=auto", *_step_scaling(hybrid, 0.5)])
    t, h = hybrid.time, halved.time
    assert h.safety == pytest.approx(t.safety / 2)
    assert h.max_temperature_change_K == pytest.approx(t.max_temperature_change_K / 2)
    assert h.max_motion_cells == pytest.approx(t.max_motion_cells / 2)
    assert h.max_strain_increment == pytest.approx(t.max_strain_increment / 2)
