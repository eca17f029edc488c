"""The outcome of a bed run (jobs/bed_outcome.py, jobs/bed_layer.py): the contacts table, the
layer's relative density, the melt track, on a six-disc CSV bed at h = 4 um run for 30 us with
and without laser heat (about 25 s together), and the measures on synthetic fields."""

import csv
import json
import math
from types import SimpleNamespace

import numpy as np
import pytest
from helpers import PAPER_SCENE, deep_update, make_case

from taichi_sls.io.series import read_series
from taichi_sls.jobs.bed_layer import melt_extent, relative_density
from taichi_sls.jobs.bed_outcome import (
    BED_SERIES,
    ContactHistory,
    contact_geometry,
    neck_regions,
)
from taichi_sls.jobs.case_run import run_case
from taichi_sls.jobs.outcome import neck_region
from taichi_sls.solver.contacts import fillet, point_colour
from taichi_sls.solver.scene import build_scene
from taichi_sls.solver.simulation import Simulation

# three discs on the plate, two in their valleys, a small one on those two: every pair that
# touches does so exactly (9 tangencies), the walls at x = 0 and 120 um
H0 = 20.0 + math.sqrt(40.0**2 - 20.0**2)
DISCS = [
    (20.0, 20.0, 20.0),
    (60.0, 20.0, 20.0),
    (100.0, 20.0, 20.0),
    (40.0, H0, 20.0),
    (80.0, H0, 20.0),
    (60.0, H0 + math.sqrt(32.0**2 - 20.0**2), 12.0),
]
TANGENT = [(0, 1), (0, 3), (1, 2), (1, 3), (1, 4), (2, 4), (3, 4), (3, 5), (4, 5)]
H_UM = 4.0


def _bed_case(tmp, absorptivity: float, end_s: float = 3e-5, frames: int = 3):
    path = tmp / "bed.csv"
    path.write_text("x_um,y_um,radius_um\n" + "".join(f"{x},{y},{r}\n" for x, y, r in DISCS))
    return make_case(
        {
            "case": {"name": "bed6"},
            "grid": {"spacing_um": H_UM},
            "bed": {"csv": str(path)},
            "contact": {"initial": "fillet", "neck_colour": "raw"},  # as the bed cases
            "lasers": [
                {"power_W": 25.0, "x_start_um": 60.0, "off_s": 1e-3, "absorptivity": absorptivity}
            ],
            "time": {"end_s": end_s},
            "output": {"frames": frames, "png": False, "gif": False},
        }
    )


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """(case, out folder) of the bed under a 25 W beam and unheated (absorptivity 0)."""
    out = {}
    for name, a in (("laser", 0.85), ("dark", 0.0)):
        tmp = tmp_path_factory.mktemp(name)
        case = _bed_case(tmp, a)
        run_case(case, tmp / "out", progress=False)
        out[name] = (case, tmp / "out")
    return out


def _table(folder):
    return list(csv.DictReader((folder / "contacts.csv").open()))


def _bed(folder):
    return json.loads((folder / "summary.json").read_text())["bed"]


def test_one_row_per_contact_with_the_fillet_neck_at_the_start(runs):
    """Every tangency is a row, at its tangency point, with a finite initial neck. The fillet
    neck (rho = 2 um) is 14.33 um between the 20 um discs and 11.97 um to the 12 um disc; at
    h = 4 um the colour fills each cusp by up to a cell (the pair reads 17.40 for 14.33,
    docs/record/convergence.md), so the neck read lies between the fillet's and one cell more."""
    case, folder = runs["laser"]
    rows = _table(folder)
    assert [(int(r["body_a"]), int(r["body_b"])) for r in rows] == TANGENT
    assert _bed(folder)["contacts"] == len(TANGENT)
    for r in rows:
        (xa, ya, ra), (xb, yb, rb) = DISCS[int(r["body_a"])], DISCS[int(r["body_b"])]
        neck = fillet([xa, ya], ra, [xb, yb], rb, case.contact.fillet_radius_um).neck_width
        read = float(r["neck_initial_um"])
        assert neck - 0.5 <= read <= neck + H_UM, (r["body_a"], r["body_b"], read, neck)
        tangency = np.array([xa, ya]) + ra / (ra + rb) * np.array([xb - xa, yb - ya])
        # the equivalent radii of the seeded (staircase) discs: within a quarter cell
        assert np.hypot(float(r["x_um"]) - tangency[0], float(r["y_um"]) - tangency[1]) < 1.0


def test_density_before_is_the_beds_packing_and_the_melt_densifies(runs):
    """At the start the layer's relative density is the generator's envelope packing (0.890
    for these discs) read on the grid: the seeded material adds the fillet bridges (+1.5 %) and
    the staircase (+0.7 %), and the colour at h = 4 um fills each contact's cusps (+1.1 %): so
    it lies within [envelope, envelope + 0.04]. Heated, the layer sinks and densifies."""
    case, folder = runs["laser"]
    d = _bed(folder)["relative_density"]
    assert d["generator_envelope"] == pytest.approx(case.bed_report["envelope"])
    assert d["generator_envelope"] <= d["initial"] <= d["generator_envelope"] + 0.04
    assert d["final"] > d["initial"] and d["mean_top_final_um"] < d["mean_top_initial_um"]
    dark = _bed(runs["dark"][1])["relative_density"]
    assert dark["initial"] == pytest.approx(d["initial"], abs=1e-12)  # the same start


def test_melt_track_and_verdict_with_and_without_laser(runs):
    """Unheated nothing melts: no depth, no width, no contact melted through or fused, no neck
    at the end of melting. Heated from above the 91.6 um high bed melts: a track deeper than
    one particle and wider than the beam's spot radius, no deeper than the bed, and contacts
    still molten at 30 us are not (yet) fused."""
    dark, heated = _bed(runs["dark"][1]), _bed(runs["laser"][1])
    assert dark["melt_depth_um"] == 0.0 and dark["track_width_um"] == 0.0
    assert dark["fused"] == 0 and dark["fused_fraction"] == 0.0 and dark["melted_through"] == 0
    assert all(r["neck_melt_um"] == "" for r in _table(runs["dark"][1]))
    top = max(y + r for _, y, r in DISCS)
    assert 40.0 < heated["melt_depth_um"] <= top + H_UM / 4
    assert 50.0 < heated["track_width_um"] <= 120.0
    assert 0.0 <= heated["fused_fraction"] <= 1.0 and heated["melted_through"] > 0
    for r in _table(runs["laser"][1]):
        assert int(r["fused"]) <= int(r["refrozen"]) * int(r["melted_through"])
        if int(r["melted_through"]):
            assert math.isfinite(float(r["neck_melt_um"]))
    assert (runs["laser"][1] / "contacts.png").stat().st_size < 300_000


def test_the_time_series_holds_the_beds_quantities_at_every_frame(runs):
    """timeseries.csv has the bed's columns at every frame, the same measures as the outcome:
    the density at the first and last frames is the bed record's before and after, the last
    frame's median neck and contact counts those of the contacts table; the plots are the
    bed's (tests/io/test_bed_plots.py checks what they hold)."""
    for name in ("laser", "dark"):
        folder = runs[name][1]
        s, bed, rows = read_series(folder / "timeseries.csv"), _bed(folder), _table(folder)
        assert len(s["t_s"]) == 4  # frame 0 and the three output frames
        for col in BED_SERIES:
            assert np.isfinite(s[col]).all(), (name, col)
        d = bed["relative_density"]
        assert s["relative_density"][0] == pytest.approx(d["initial"], rel=1e-12)
        assert s["relative_density"][-1] == pytest.approx(d["final"], rel=1e-12)
        assert s["mean_top_um"][-1] == pytest.approx(d["mean_top_final_um"], rel=1e-12)
        assert s["neck_median_um"][-1] == pytest.approx(bed["neck_final_um"]["median"])
        assert (s["contacts"] == len(TANGENT)).all()
        assert s["contacts_fused"][-1] == bed["fused"]
        assert s["contacts_melted_through"][-1] == bed["melted_through"]
        assert s["contacts_molten"][-1] == sum(1 - int(r["refrozen"]) for r in rows)
        assert (folder / "timeseries.png").is_file() and (folder / "outcome.png").is_file()
    heated = read_series(runs["laser"][1] / "timeseries.csv")
    assert heated["contacts_molten"][-1] > 0 and heated["molten_fraction"][-1] > 0


def test_a_resumed_bed_run_keeps_its_contact_history(runs, tmp_path):
    """Stopped after the first of its three frames and resumed from the checkpoint, the run
    ends with the contacts table and bed record of the uninterrupted run (the necks and the
    density at the start come back from the checkpoint)."""
    run_case(
        _bed_case(tmp_path, 0.85, 1e-5, 1), tmp_path / "out", progress=False, checkpoint_every=1
    )
    run_case(
        _bed_case(tmp_path, 0.85),
        tmp_path / "out",
        progress=False,
        resume=tmp_path / "out" / "checkpoint.npz",
    )
    full = runs["laser"][1]
    assert _table(tmp_path / "out") == _table(full)
    assert _bed(tmp_path / "out") == _bed(full)


def test_pair_colour_is_the_steps_p2g(tmp_path):
    """The colour a pair's necks are read on is the step's P2G restricted to their points:
    over every point it is the solver's raw colour to round-off."""
    sim = Simulation(_bed_case(tmp_path, 0.85))
    cfg = sim.state.cfg
    x = sim.state.points.x.to_numpy()
    weight = sim.state.points.mass.to_numpy() / (cfg.rho_ref * cfg.cell_volume)
    mine = point_colour(x, weight, cfg.h, cfg.lp, cfg.off, (cfg.nx, cfg.ny))
    assert np.abs(mine - sim.necks.raw_colour()).max() < 1e-12
    assert len(sim.necks.pair_necks_m()) == len(TANGENT)
    # a subset of the contacts reads what the whole list reads for them (the monitors' contact
    # line reads the first alone)
    every = sim.necks.necks_m("colour")
    for k in (0, len(TANGENT) - 1):
        assert sim.necks.necks_m("colour", sim.contacts[k : k + 1]) == [every[k]]


def test_the_neck_regions_are_read_again_only_when_the_points_move_in_order(tmp_path):
    """The contact record keeps each contact's neck region while the points' start positions
    keep their order, and reads it again when they are put in another order."""
    sim = Simulation(_bed_case(tmp_path, 0.85))
    history = ContactHistory(sim)
    first = history.regions(sim)
    assert history.regions(sim) is first
    order = np.random.default_rng(0).permutation(len(sim.scene.body))
    sim._permute(order)
    moved = history.regions(sim)
    fresh = neck_regions(sim, history.points, history.normals)
    assert all(np.array_equal(a, b) for a, b in zip(moved, fresh, strict=True))
    assert all(np.array_equal(a[order], b) for a, b in zip(first, moved, strict=True))


@pytest.mark.parametrize("dim", [2, 3])
def test_relative_density_of_a_block_with_a_hole(dim):
    """A full block of material from the plate up to a flat top (c = 1 on its nodes, 0 above:
    the c = 1/2 crossing half a cell above the last full node row) reads 1; a hole of 4 x 4
    cells (4 x 4 x 4 in 3D) in it removes its area (volume)."""
    h, off = 1.0, 2
    depth = (0.0, 8.0)  # 3D: z over 0..8
    c = np.zeros((44, 30, 24)[:dim])
    across = (slice(off, off + 9),) if dim == 3 else ()
    c[(slice(off, off + 41), slice(None, off + 11), *across)] = 1.0  # x 0..40, y to 10
    ranges = [(0.0, 40.0), depth][: dim - 1]
    full = relative_density(c, h, off, ranges, 28.0)
    assert full["relative_density"] == pytest.approx(1.0)
    assert full["mean_top_m"] == pytest.approx(10.5, abs=0.13)
    # nodes x 10..13, y 3..6 (z 2..5) empty: c < 1/2 from half a cell before them to half after
    hole = (slice(off + 10, off + 14), slice(off + 3, off + 7), slice(off + 2, off + 6))
    c[hole[:dim]] = 0.0
    holed = relative_density(c, h, off, ranges, 28.0)
    envelope = 40.0 * 10.5 * (depth[1] if dim == 3 else 1.0)
    assert holed["relative_density"] == pytest.approx(1.0 - 4.0**dim / envelope, abs=0.005)


def test_melt_extent_counts_each_point_with_its_square():
    x0 = np.array([[10.0, 50.0], [20.0, 40.0], [30.0, 20.0], [90.0, 5.0]])
    tm = np.array([1e-6, 2e-6, 1e-6, 0.0])
    e = melt_extent(x0, tm, 60.0, 2.0)
    assert e["melt_depth_m"] == pytest.approx(60.0 - 19.0) and e["melt_bottom_m"] == 19.0
    assert e["track_width_m"] == pytest.approx(22.0) and e["molten_points"] == 3
    assert melt_extent(x0, np.zeros(4), 60.0, 2.0)["melt_depth_m"] == 0.0


def test_a_pairs_contact_region_is_the_pair_verdicts_neck_region():
    """For the paper's pair the per-contact neck region (the slab about the contact's radical
    line) holds the same points as the pair verdict's (about the mid-plane of bodies 0, 1)."""
    case = make_case(deep_update(PAPER_SCENE, {"contact": {"initial": "fillet"}}))
    sc = build_scene(case)
    m = sc.vol
    centres = np.array(
        [np.average(sc.x[sc.body == b], axis=0, weights=m[sc.body == b]) for b in (0, 1)]
    )
    area = np.bincount(sc.body, weights=sc.vol)
    sim = SimpleNamespace(
        case=case,
        contacts=[(0, 1)],
        scene=sc,
        necks=SimpleNamespace(
            body_radii_m=np.sqrt(area / np.pi), body_centres_m=lambda initial: centres
        ),
        point_arrays=lambda keys: {"x0": sc.x},
        state=SimpleNamespace(cfg=SimpleNamespace(h=case.grid.spacing_um * 1e-6)),
    )
    points, normals = contact_geometry(sim)
    assert points[0] == pytest.approx(0.5 * (centres[0] + centres[1]))
    (region,) = neck_regions(sim, points, normals)
    pair = neck_region(case, sc.x, sc.body, m)
    assert region.sum() > 0 and np.array_equal(region, pair)


def test_the_bed_printout_reads_a_summary_back_from_json():
    """A finished run's summary is printed again from summary.json, where NaN is null: the
    printout says '-' for what is not a number (no contact, nothing molten)."""
    import json

    from taichi_sls.jobs.bed_outcome import describe_bed

    nothing = {"count": 0, "median": None, "q25": None, "q75": None}
    bed = {
        "contacts": 0,
        "fused": 0,
        "fused_fraction": float("nan"),
        "melted_through": 0,
        "still_molten": 0,
        "rule": "per contact",
        "layer_top_um": 100.0,
        "melt_depth_um": 0.0,
        "melt_bottom_um": float("nan"),
        "track_width_um": 0.0,
        "molten_points": 0,
        "neck_initial_um": nothing,
        "neck_melt_um": nothing,
        "neck_final_um": nothing,
        "relative_density": {
            "initial": 0.8,
            "final": 0.8,
            "generator_envelope": 0.79,
            "generator_bulk": float("nan"),
            "mean_top_initial_um": 90.0,
            "mean_top_final_um": 90.0,
        },
    }
    text = json.dumps(bed).replace("NaN", "null")  # what the summary writer leaves
    lines = describe_bed(json.loads(text)).splitlines()
    assert lines[0] == "bed: 0 contacts, 0 fused (-), 0 melted through, 0 still molten"
    assert "bulk -" in lines[2] and "down to - above the plate" in lines[3]


def test_a_bed_run_writes_its_case_as_given_and_as_resolved(runs):
    """case.toml: the case as given, its [bed] a table (it loads back to the same case);
    resolved.toml: what ran, every disc a body and no [bed] (config/resolve.py)."""
    from taichi_sls.config import case_to_toml, load_case

    case, folder = runs["laser"]
    given = load_case(folder / "case.toml")
    assert given == case and "[bed]" in (folder / "case.toml").read_text()
    resolved = (folder / "resolved.toml").read_text()
    assert resolved == case_to_toml(case) and "[bed]" not in resolved
    assert resolved.count("[[bodies]]") == len(DISCS)
