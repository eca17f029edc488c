"""A neck grows alike at every angle to the grid (docs/record/verification.md, "Neck growth at
any angle", issue #55 open): Hopper's fluid pair joined by a fillet, turned about its neck, its
per-contact neck r_n / R0 at the same times. The bars are those the isotropy was asked to meet:
5 % between angles at the beds' resolution (R0/h = 5, a 2 um fillet under a 4 um cell), 2 % at
R0/h = 20 (a 1 um fillet) and 3 % from Hopper there. With each point's own dilatation (the
default) they are not met: strict xfails. With one dilatation per cell
(``solver.dilatation = "cell"``, an option of the explicit and implicit steps) the tests below
hold what it meets. And the trend grows with how nearly incompressible the fluid is
(volumetric locking)."""

import numpy as np
import pytest

from taichi_sls.config import CaseError, deep_update
from taichi_sls.studies.verification.isotropy import fillet_pair, hopper_errors, neck_history

TIMES = np.linspace(0.0, 150e-6, 9)  # 0 to 150 us: from the fillet to r_n / R0 near 0.9
# accuracy, not speed: the quick compile. Read on the force's filtered colour, the colour the
# record's rows were measured on (docs/record/verification.md): at R0/h = 5 the 2 um fillet is
# sub-cell, and the default kernel colour's one-cell closing reads the pair along x, whose
# mid-plane lies on a node line, up to 17 % narrower than at 30 and 45 deg (filtered: 4.6 %;
# raw: 12.6 %), a measure of the unresolved contact, not of the growth these tests compare
FAST = {"solver": {"optimize": False}, "contact": {"neck_colour": "filtered"}}


def _histories(angles, R0_over_h, fillet_um, sets=None):
    return [
        neck_history(fillet_pair(a, R0_over_h, fillet_um, deep_update(FAST, sets or {})), TIMES)
        for a in angles
    ]


CELL = {"solver": {"dilatation": "cell"}}
WORST_R20_CELL = 0.02  # the bar asked of the pair at R0/h = 20


def _worst_ratio(histories):
    along_x = histories[0].neck
    return max(float(np.max(np.abs(h.neck / along_x - 1.0))) for h in histories[1:])


@pytest.mark.slow
def test_the_angle_trend_grows_with_the_poisson_ratio():
    """R0/h = 10, a 2 um fillet: the 45 deg pair's lead over the pair along x grows as the
    fluid nears incompressibility (0.30, the case's 0.45, 0.49), the signature of volumetric
    locking; the neck itself slows (the 45 deg pair is compared at the same Poisson ratio)."""
    lead, end = [], []
    for nu in (0.30, 0.45, 0.49):
        runs = _histories((0.0, 45.0), 10.0, 2.0, {"materials": {"fluid": {"poisson": nu}}})
        lead.append(_worst_ratio(runs))
        end.append(runs[0].neck[-1])
    print("worst 45 / 0 deg ratio - 1:", np.round(lead, 4), "r_n / R0 at 150 us:", np.round(end, 4))
    assert lead[0] < lead[1] < lead[2]
    assert end[0] > end[1] > end[2]


@pytest.mark.slow
@pytest.mark.xfail(
    strict=True,
    reason="issue #55 open: at R0/h = 5 the 45 deg pair runs up to 6.3 % ahead of the pair "
    "along x (mid-plane on a node line)",
)
def test_neck_grows_alike_at_0_30_45_deg_at_the_beds_resolution():
    runs = _histories((0.0, 30.0, 45.0), 5.0, 2.0)
    print([np.round(h.neck, 4) for h in runs])
    assert _worst_ratio(runs) < 0.05


def test_cell_dilatation_grows_the_neck_alike_at_0_30_45_deg_at_the_beds_resolution():
    runs = _histories((0.0, 30.0, 45.0), 5.0, 2.0, CELL)
    for h in runs:
        print(h.angle_deg, np.round(h.neck, 4))
        assert h.neck[-1] > 1.5 * h.neck[0]  # the neck grows through the window compared
    assert _worst_ratio(runs) < 0.05


IMPLICIT = {"time": {"integrator": "implicit"}}  # dt "auto": 50 explicit steps, 0.66 us here


@pytest.mark.slow  # ~30 s; the explicit step's counterpart stays in the default suite
def test_cell_dilatation_grows_the_neck_alike_under_implicit_steps_at_the_beds_resolution():
    """The same pair and bar (5 %, the beds' resolution) under implicit steps, as every bed case
    grows its necks: measured 4.5 % (30 deg, its t = 0 reading) and 3.5 % (45 deg), one Newton
    iteration a step; each point's own dilatation reads 8.1 % at 45 deg (the test below)."""
    runs = _histories((0.0, 30.0, 45.0), 5.0, 2.0, deep_update(CELL, IMPLICIT))
    for h in runs:
        print(h.angle_deg, np.round(h.neck, 4))
        assert h.neck[-1] > 1.5 * h.neck[0]
    assert _worst_ratio(runs) < 0.05


@pytest.mark.slow
@pytest.mark.xfail(
    strict=True,
    reason="issue #55 with each point's own dilatation: under implicit steps the 45 deg pair "
    "at R0/h = 5 runs up to 8.1 % ahead of the pair along x",
)
def test_neck_grows_alike_under_implicit_steps_at_the_beds_resolution():
    runs = _histories((0.0, 45.0), 5.0, 2.0, IMPLICIT)
    print([np.round(h.neck, 4) for h in runs])
    assert _worst_ratio(runs) < 0.05


@pytest.mark.parametrize(
    "sets",
    [{"solver": {"update": "musl"}}, {"boundary": {"right": {"mechanical": "mirror"}}}],
)
def test_cell_dilatation_refused_where_it_is_not_taken(sets):
    with pytest.raises(CaseError, match="solver.dilatation"):
        fillet_pair(0.0, 5.0, 2.0, deep_update(CELL, sets))


@pytest.mark.parametrize("integrator", ["implicit", "hybrid"])
def test_cell_dilatation_is_taken_by_the_implicit_and_hybrid_steps(integrator):
    vc = fillet_pair(0.0, 5.0, 2.0, deep_update(CELL, {"time": {"integrator": integrator}}))
    assert vc.case.solver.dilatation == "cell"


@pytest.mark.slow
def test_cell_dilatation_follows_hopper_and_grows_alike_at_R0_h_20():
    runs = _histories((0.0, 45.0), 20.0, 1.0, CELL)
    worst = _worst_ratio(runs)
    print(f"worst 45 / 0 deg ratio - 1: {worst:.4f}")
    for h in runs:
        errors = hopper_errors(h, (0.5, 0.75, 1.0), 0.35)
        print(h.angle_deg, np.round(h.neck, 4), {k: round(v, 4) for k, v in errors.items()})
        assert all(abs(e) < 0.03 for e in errors.values())
    assert worst < WORST_R20_CELL


@pytest.mark.slow
def test_cell_dilatation_follows_hopper_and_grows_alike_under_implicit_steps_at_R0_h_20():
    """The R0/h = 20 bars (2 % between 0 and 45 deg, 3 % from Hopper with clocks aligned) under
    implicit steps of 50 explicit ones, the cell's gradient floored at light corners (measured
    1.9 %; +0.5 / -0.2 / -0.1 % and +1.6 / +0.9 / +0.5 % at tau = 0.5 / 0.75 / 1; about 3 min)."""
    runs = _histories((0.0, 45.0), 20.0, 1.0, deep_update(CELL, IMPLICIT))
    worst = _worst_ratio(runs)
    print(f"worst 45 / 0 deg ratio - 1: {worst:.4f}")
    for h in runs:
        errors = hopper_errors(h, (0.5, 0.75, 1.0), 0.35)
        print(h.angle_deg, np.round(h.neck, 4), {k: round(v, 4) for k, v in errors.items()})
        print(f"  {h.steps} steps, {h.wall_s:.0f} s")
        assert all(abs(e) < 0.03 for e in errors.values())
    assert worst < WORST_R20_CELL


@pytest.fixture(scope="module")
def pairs_r20():
    """The pair along x and at 45 deg at R0/h = 20 from a 1 um fillet (two runs of minutes,
    read by the two tests below)."""
    return _histories((0.0, 45.0), 20.0, 1.0)


@pytest.mark.slow
@pytest.mark.xfail(
    strict=True,
    reason="issue #55 open: the pair along x lags Hopper by up to 6.9 % (tau = 0.5), the "
    "45 deg pair is within 1.1 %",
)
def test_neck_follows_hopper_at_0_and_45_deg_at_R0_h_20(pairs_r20):
    for h in pairs_r20:
        errors = hopper_errors(h, (0.5, 0.75, 1.0), 0.35)
        print(h.angle_deg, {k: round(v, 4) for k, v in errors.items()})
        assert all(abs(e) < 0.03 for e in errors.values())


@pytest.mark.slow
@pytest.mark.xfail(
    strict=True,
    reason="issue #55 open: the 45 deg pair runs up to 10 % ahead of the pair along x",
)
def test_neck_grows_alike_at_0_and_45_deg_at_R0_h_20(pairs_r20):
    worst = _worst_ratio(pairs_r20)
    print(f"worst 45 / 0 deg ratio - 1: {worst:.4f}")
    assert worst < 0.02


def test_contact_angles_are_folded_and_the_trend_fitted(tmp_path):
    """contact_growth_by_angle on a constructed run: a contact along x, one at 30 deg, one at
    135 deg (folded to 45), one up the y axis (folded to 0) and one that never melted."""
    from taichi_sls.io.contacts_table import write_contacts
    from taichi_sls.studies.verification.isotropy import angle_trend, contact_growth_by_angle

    c30 = [100.0 * np.cos(np.radians(30.0)), 100.0 * np.sin(np.radians(30.0))]
    centres = [[0.0, 0.0], [100.0, 0.0], c30, [-100.0, 100.0], [0.0, 100.0]]
    (tmp_path / "resolved.toml").write_text(
        "".join(f"[[bodies]]\ncenter_um = [{x}, {y}]\n" for x, y in centres)
    )
    growth = {1: 1.1, 2: 1.1 + 0.2 * 30.0 / 45.0, 3: 1.3, 4: 1.1}
    rows = [
        {
            "body_a": 0,
            "body_b": b,
            "x_um": 0.0,
            "y_um": 0.0,
            "neck_initial_um": 10.0,
            "neck_melt_um": 11.0,
            "melt_end_s": 1e-3,
            "neck_final_um": 10.0 * g,
            "neck_region_melted_fraction": 1.0,
            "melted_through": 1,
            "refrozen": 1,
            "fused": 1,
        }
        for b, g in growth.items()
    ]
    rows.append({**rows[0], "body_b": 2, "neck_melt_um": float("nan")})  # never melted
    write_contacts(tmp_path / "contacts.csv", rows)
    got = contact_growth_by_angle(tmp_path)
    assert [round(r["angle_deg"], 9) for r in got] == [0.0, 30.0, 45.0, 0.0]
    assert [r["growth"] for r in got] == pytest.approx(list(growth.values()))
    slope, err = angle_trend(got)
    # growth = 1.1 + 0.2 (angle / 45) exactly: the fitted slope is 0.2 with no residual
    assert slope == pytest.approx(0.2) and err == pytest.approx(0.0, abs=1e-12)
