"""A pair in the sintering window against Hopper (cases/pair_window.toml, studies/pair_window.py;
issue #40 item 5): a laser-melted PA12 pair on a 172 C bed coalesces past its initial diameter,
its neck on Hopper's clock at the viscosity of the temperature the run records."""

import pytest

from taichi_sls.config import load_case
from taichi_sls.jobs.case_run import run_case
from taichi_sls.studies.pair_window import TAU_END, window_rows
from taichi_sls.studies.references.crystallization import PA12_CRYSTALLIZATION

KELVIN = 273.15


def test_the_melt_outlives_the_run_at_the_bed_temperature():
    """The case's premise: on the 172 C bed the crystallisation kinetics' isothermal half time
    (5.4 h by the PA12 defaults) is thousands of times the 2.6 s run, and the case uses them."""
    case = load_case("pair_window")
    m = case.materials["PA12"]
    assert m.crystallization_kinetics is not None and m.yield_liquid_Pa == 0.0
    assert case.boundary.bottom.temperature_C == case.thermal.initial_C == 172.0
    assert PA12_CRYSTALLIZATION.half_time(172.0 + KELVIN) > 1e3 * case.time.end_s


@pytest.mark.slow  # ~90 s on two shared cores, each colour
@pytest.mark.parametrize(
    "colour",
    [
        pytest.param(
            "kernel",
            marks=pytest.mark.xfail(
                strict=True,
                reason="issue #54 item 5: on the default kernel colour the neck lags Hopper by "
                "up to 5.5 % at tau = 0.8 (R0/h = 10), beyond the 5 %; the filtered colour's "
                "widening of the concave neck (about kappa h^2 / 4) read it within 3.1 %",
            ),
        ),
        "filtered",
    ],
)
def test_a_pair_in_the_window_follows_hopper_at_its_recorded_viscosity(tmp_path, colour):
    """The bundled case as it is: the pulse melts the pair (mean 287 C), it cools to the bed in
    ~0.1 s and stays molten, and its neck (the per-contact section on ``colour``) follows
    Hopper's at tau = int gamma dt / (eta_N(T) R0), aligned 1 ms after the pulse (tau 0.33),
    within the issue's 5 % at every recorded tau up to 2. Measured on the filtered colour: at
    most +3.1 % at 16 ms, while the pair cools and its neck is hotter than the mean the clock
    runs on; -0.9 % at tau 2.1. On the kernel colour (the default since issue #54 item 5): at
    most -5.5 % at tau 0.81 (-4.2 % at tau 1.07, -1.0 % at 2.11); on points seeded inside
    Hopper's exact outline at R0/h = 10 that colour reads +1.1 % / +0.4 % at tau 0.75 / 1, not
    narrow: the lag is the run's at this coarse grid, and the clock's, aligned where every
    colour reads the neck's sub-cell tip wide (+3.8 % on the exact outline at tau 0.5). The
    neck grows past the discs' initial diameter."""
    sets = ["output.png=false", "output.gif=false", f"contact.neck_colour={colour}"]
    case = load_case("pair_window", sets)
    summary = run_case(case, tmp_path, progress=False)
    assert summary["status"] == "complete"
    rows = window_rows(tmp_path)
    print("neck against Hopper:", [(round(r["tau"], 3), r["difference"]) for r in rows])
    assert rows[0]["tau"] < 0.5 and rows[-1]["tau"] >= TAU_END
    late = [r for r in rows if r["t_s"] >= 0.1 * (1 - 1e-9)]
    assert all(1.0 - r["molten_fraction"] < 1e-9 for r in late)
    assert all(abs(r["T_mean_C"] - 172.0) < 0.1 for r in late)
    R0 = case.bodies[0].radius_um
    assert rows[-1]["neck_um"] > 2.0 * R0 * 1.1
    assert all(abs(r["difference"]) < 0.05 for r in rows)
