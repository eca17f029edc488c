"""contact.settle, time.stop = "solidified" and the fusion verdict in 3D (issue #39): a small
pair of spheres joined by the torus fillet (R = 8 um, h = 2 um) settles, then a brief weak
laser heats it without melting, and the run stops once solid and quiet with a verdict whose
necks are all read (no NaN). The settle rule is loosened (kinetic fraction 1, neck change
100 %) so that it holds within a few frames: the test checks that the 3D machinery runs and
reads its necks, not the settled state itself (docs/record/convergence.md for that, in 2D)."""

import csv
import math

from helpers import make_case

from taichi_sls.jobs.case_run import run_case
from taichi_sls.jobs.outcome import describe
from taichi_sls.solver.contacts import fillet
from taichi_sls.solver.simulation import Simulation

PAIR3D_T0 = 140.0  # the PA12 preheat (thermal.initial_C's default)
PAIR3D = {
    "case": {"name": "pair3d"},
    "grid": {"spacing_um": 2.0},
    "domain": {"dim": 3, "width_um": 40.0, "height_um": 24.0, "depth_um": 24.0},
    "bodies": [
        {"shape": "disc", "center_um": [12.0, 12.0, 12.0], "radius_um": 8.0},
        {"shape": "disc", "center_um": [28.0, 12.0, 12.0], "radius_um": 8.0},
    ],
    "contact": {"initial": "fillet", "fillet_radius_um": 2.0, "settle": True},
    "lasers": [
        {"power_W": 0.05, "spot_radius_um": 20.0, "x_start_um": 20.0, "on_s": 0.0, "off_s": 1e-6}
    ],
    "time": {
        "dt_s": "auto",
        "stop": "solidified",
        "max_s": 2e-5,
        "settled_kinetic_fraction": 1.0,
        "settled_neck_change": 1.0,
    },
    "output": {"first_frame_s": 1e-7},
}


def test_a_3d_pair_settles_heats_and_gets_its_verdict(tmp_path):
    # the seeded torus bridge reads about its fillet's neck 2 (t - rho) = 8 um (h = 2 um, the
    # filtered colour widens a concave neck: measured 8.71 um, +9 %; 15 % allowed)
    seeded = Simulation(make_case(PAIR3D)).monitors()["contact_line_um"]
    exact = fillet((0.0, 0.0), 8.0, (16.0, 0.0), 8.0, 2.0).neck_width
    assert abs(seeded / exact - 1.0) < 0.15
    s = run_case(make_case(PAIR3D), tmp_path, progress=False)
    o = s["outcome"]
    print(seeded, describe(o))
    # the settled contact has zipped open by adhesion from the seeded one
    assert s["settle"]["neck_um"] > seeded
    rows = list(csv.DictReader((tmp_path / "timeseries.csv").open()))
    assert rows and all(math.isfinite(float(r["contact_line_um"])) for r in rows)
    # the laser heated (a verdict is due), nothing melted, the run stopped solid and quiet
    assert o["solidified"] and o["T_peak_C"] > PAIR3D_T0 and o["molten_fraction_peak"] == 0.0
    assert o["fused"] is False and o["no_verdict"] is None
    assert o["neck_unheated_um"] == s["settle"]["neck_um"]
    for key in ("neck_initial_um", "neck_final_um", "neck_growth_over_unheated"):
        assert math.isfinite(o[key]), key
    assert "nan" not in describe(o).lower()
