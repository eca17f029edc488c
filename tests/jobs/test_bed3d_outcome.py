"""The bed outcome in 3D (issue #39 item 9): a handful of deposited spheres on a coarse grid,
briefly heated, report every contact with a finite neck read by the 3D section, the layer's
relative density under its top surface and the fused count; the bundled cases/bed3d_track.toml
loads as the 3D layer under a track it describes."""

import csv
import math
from pathlib import Path

from helpers import make_case

from taichi_sls.config import load_case
from taichi_sls.jobs.case_run import run_case

ROOT = Path(__file__).resolve().parents[2]

TINY_BED3D = {
    "case": {"name": "tiny_bed3d"},
    "grid": {"spacing_um": 4.0},
    "domain": {"dim": 3},
    "bed": {
        "generator": "deposition",
        "count": 5,
        "median_diameter_um": 16.0,
        "spread": 0.1,
        "seed": 2,
        "x_range_um": [0.0, 32.0],
        "z_range_um": [0.0, 32.0],
    },
    "contact": {"initial": "fillet", "neck_colour": "raw"},
    "lasers": [
        {
            "power_W": 25.0,
            "spot_radius_um": 50.0,
            "direction": "x",
            "x_start_um": 0.0,
            "speed_m_s": 4.0,
            "on_s": 0.0,
            "off_s": 1e-5,
        }
    ],
    "time": {"dt_s": "auto", "end_s": 1e-5},
    "output": {"frames": 2},
}


def test_a_tiny_3d_bed_reports_its_contacts_density_and_fused_count(tmp_path):
    case = make_case(TINY_BED3D)
    generated = case.bed_report
    s = run_case(case, tmp_path, progress=False)
    bed = s["bed"]
    print(bed)
    assert bed["contacts"] >= generated["contacts"] > 0  # the fillet joins near pairs too
    rows = list(csv.DictReader((tmp_path / "contacts.csv").open()))
    assert len(rows) == bed["contacts"] and "z_um" in rows[0]
    for r in rows:  # every contact's neck read by the 3D section, finite and open
        assert float(r["neck_initial_um"]) > 0.0 and float(r["neck_final_um"]) > 0.0
    d = bed["relative_density"]
    # the grid's reading of the seeded layer against the generator's envelope fraction: on
    # 4 cells across a sphere the colour's c = 1/2 outline differs by up to a few tenths of a
    # cell, a few % of the volume per sphere; 0.1 allowed
    assert abs(d["initial"] - generated["envelope"]) < 0.1
    assert 0.0 < d["final"] < 1.0 and math.isfinite(d["mean_top_final_um"])
    assert 0 <= bed["fused"] <= bed["contacts"] and bed["melt_depth_um"] > 0.0


def test_the_bundled_3d_track_case_loads():
    case = load_case(ROOT / "cases" / "bed3d_track.toml")
    assert case.domain.dim == 3 and len(case.bodies) == case.bed_report["spheres"] == 48
    assert case.time.integrator == "hybrid" and case.time.stop == "solidified"
    assert case.lasers[0].direction == "x" and case.contact.initial == "fillet"
