"""Powder beds: the deposition generator, its packing fraction against the published 2D value,
CSV beds, and one clear error for each kind of bad bed (numpy only, no simulation)."""

import math

import numpy as np
import pytest

from taichi_sls.config import CaseError, bundled_case, case_from_dict, case_to_dict, load_case
from taichi_sls.config.deposition import deposit, lognormal_diameters
from taichi_sls.config.packing import area_in_window, packing_fractions
from taichi_sls.solver.contacts import touching
from taichi_sls.solver.scene import build_scene

# Random sequential deposition with rolling of equal discs in 2D packs at about 0.82 (Visscher &
# Bolsterli 1972, Nature 239, 504); random close packing of discs, the densest random state, is
# 0.84 (Meer et al. 2024, arXiv:2404.02316: phi_0 = 0.840 at low skewness). Six seeds of the
# 1000-disc bed below read 0.818-0.827 in the bulk window; the band allows 0.82 +- 0.015.
DEPOSITION_2D = 0.82
RCP_2D = 0.84


def _bed(n: int, spread: float, seed: int, width: float = 30.0):
    rng = np.random.default_rng(seed)
    r = lognormal_diameters(rng, n, 1.0, spread) / 2
    x, y = deposit(r, (0.0, width), rng)
    return x, y, r


def _gaps(x, y, r):
    d = np.hypot(x[:, None] - x, y[:, None] - y) - (r[:, None] + r)
    d[np.diag_indices(len(x))] = np.inf
    return d


def test_same_seed_same_bed_and_another_seed_another():
    a, b, c = _bed(200, 0.2, 7), _bed(200, 0.2, 7), _bed(200, 0.2, 8)
    assert all(np.array_equal(u, v) for u, v in zip(a, b, strict=True))
    assert not np.allclose(a[0], c[0])


def test_packing_fraction_of_equal_discs_matches_deposition_and_stays_below_rcp():
    x, y, r = _bed(1000, 0.0, 3)
    pf = packing_fractions(x, y, r, (0.0, 30.0))
    print(pf)
    assert abs(pf["bulk"] - DEPOSITION_2D) < 0.015
    assert pf["bulk"] < RCP_2D
    # the envelope counts the rough top and the wall layers: a little looser than the bulk
    assert pf["envelope"] < pf["bulk"] and pf["envelope"] > 0.78


def test_mildly_polydisperse_bed_packs_in_the_same_band():
    x, y, r = _bed(1000, 0.1, 4)
    pf = packing_fractions(x, y, r, (0.0, 30.0))
    assert 0.79 < pf["bulk"] < RCP_2D


def _holds_up(normals: list[np.ndarray]) -> bool:
    """Some two contact normals (pointing from the support to the disc) span a cone holding
    (0, 1): the contact forces can balance gravity."""
    for a in range(len(normals)):
        for b in range(a + 1, len(normals)):
            n1, n2 = normals[a], normals[b]
            det = n1[0] * n2[1] - n1[1] * n2[0]
            if abs(det) > 1e-12 and -n2[0] / det >= -1e-12 and n1[0] / det >= -1e-12:
                return True
    return False


def test_no_overlap_and_every_disc_rests_on_supports():
    width = 15.0
    x, y, r = _bed(400, 0.3, 5, width=width)
    gap = _gaps(x, y, r)
    assert gap.min() > -1e-9
    tol = 1e-9
    for i in range(len(x)):
        if y[i] - r[i] < tol:
            continue  # on the plate
        # the discs placed before it that it touches, and the side walls
        normals = [
            np.array([x[i] - x[k], y[i] - y[k]]) / (r[i] + r[k])
            for k in np.nonzero(gap[i, :i] < tol)[0]
        ]
        normals += [np.array([1.0, 0.0])] if x[i] - r[i] < tol else []
        normals += [np.array([-1.0, 0.0])] if x[i] + r[i] > width - tol else []
        assert _holds_up(normals), f"disc {i} is not supported"


def test_lognormal_median_and_spread():
    d = lognormal_diameters(np.random.default_rng(0), 20000, 50.0, 0.3)
    assert abs(np.median(d) / 50.0 - 1) < 0.01
    assert abs(np.std(np.log(d)) / 0.3 - 1) < 0.03  # truncated at 3 sigma: 1.3 % narrower
    assert np.all(np.abs(np.log(d / 50.0)) <= 0.9 + 1e-12)


def test_sizes_drawn_from_a_csv_of_measured_diameters(tmp_path):
    (tmp_path / "sizes.csv").write_text("diameter_um\n38.5\n51.0\n# a comment\n62.25\n")
    case = _case(
        {"count": 12, "sizes_csv": str(tmp_path / "sizes.csv"), "x_range_um": [0.0, 300.0]}
    )
    diameters = {2 * b.radius_um for b in case.bodies}
    assert diameters <= {38.5, 51.0, 62.25} and len(diameters) > 1


def test_area_in_window_of_a_clipped_disc():
    # a unit disc cut through its centre by the window's edge: half its area
    a = area_in_window(np.array([0.0]), np.array([0.0]), np.array([1.0]), (0.0, 5.0), (-5, 5))
    assert abs(a - math.pi / 2) < 1e-4


def test_deposits_on_a_previous_layer():
    x0, y0, r0 = _bed(40, 0.2, 1, width=10.0)
    rng = np.random.default_rng(2)
    r = np.full(30, 0.4)
    x, y = deposit(r, (0.0, 10.0), rng, existing=(x0, y0, r0))
    gap = _gaps(np.r_[x0, x], np.r_[y0, y], np.r_[r0, r])
    assert gap.min() > -1e-9
    assert np.mean(y) > np.mean(y0)  # the new layer lies on top of the old


# ------------------------------------------------------------------------ the [bed] table

BED = {"grid": {"spacing_um": 4.0}, "contact": {"initial": "fillet"}}


def _case(bed: dict, **extra):
    return case_from_dict({**BED, **extra, "bed": bed})


def test_bed_becomes_disc_bodies_and_the_domain_fits_it():
    case = _case({"count": 30, "median_diameter_um": 40.0, "x_range_um": [0.0, 400.0]})
    assert len(case.bodies) == 30 and all(b.shape == "disc" for b in case.bodies)
    top = max(b.center_um[1] + b.radius_um for b in case.bodies)
    assert case.domain.width_um == 400.0
    assert top < case.domain.height_um <= top + 2 * 40.0 + 4.0
    rep = case.bed_report
    assert rep["discs"] == 30 and rep["contacts"] >= 30 and 0.6 < rep["envelope"] < 0.91
    # the resolved case lists the discs and no bed: it loads back to the same case
    data = case_to_dict(case)
    assert "bed" not in data
    assert case_to_dict(case_from_dict(data)) == data


def test_layers_sets_the_count_and_discs_land_on_body_discs():
    body = {"shape": "disc", "center_um": [100.0, 20.0], "radius_um": 20.0}
    case = _case(
        {"layers": 2.0, "median_diameter_um": 40.0},
        domain={"width_um": 200.0, "height_um": 200.0},
        bodies=[body],
    )
    assert len(case.bodies) == 1 + 10  # 2 x 200 / 40
    c = np.array([b.center_um for b in case.bodies])
    r = np.array([b.radius_um for b in case.bodies])
    assert _gaps(c[:, 0], c[:, 1], r).min() > -1e-9


def test_generated_contacts_are_the_solver_contacts():
    """Every touching pair of a generated bed is a contact of the seeded points (h = 4 um), and
    pairs clearly apart (gap beyond the fillet's reach and the 1.5-spacing search) are not."""
    case = _case({"count": 25, "median_diameter_um": 40.0, "spread": 0.2, "seed": 2,
                  "x_range_um": [0.0, 300.0]})  # fmt: skip
    sc = build_scene(case)
    pairs = set(touching(sc.x, sc.body, sc.h / case.grid.points_per_cell))
    c = np.array([b.center_um for b in case.bodies])
    r = np.array([b.radius_um for b in case.bodies])
    gap = _gaps(c[:, 0], c[:, 1], r)
    touch = {(i, j) for i, j in zip(*np.nonzero(gap < 1e-6), strict=True) if i < j}
    far = {(i, j) for i, j in zip(*np.nonzero(gap > 2 * 2.0 + 4.0), strict=True) if i < j}
    assert touch and touch <= pairs
    assert not (far & pairs)


def test_bundled_bed_track():
    case = load_case(bundled_case("bed_track"))
    rep = case.bed_report
    assert 50 <= rep["discs"] <= 100 and case.contact.initial == "fillet"
    assert 500 <= case.domain.width_um <= 1000 and case.lasers[0].speed_m_s > 0
    # two to three particles deep
    assert 2 <= rep["mean_top"] / 40.0 <= 3


# ------------------------------------------------------------------------------- CSV beds

GOOD = (
    "# three particles\nx_um, y_um, radius_um, id\n20, 20, 20, a\n60, 20, 20, b\n40, 54.64, 20, c\n"
)


def test_csv_bed_loads_relative_to_the_case_file(tmp_path):
    (tmp_path / "bed.csv").write_text(GOOD)
    (tmp_path / "case.toml").write_text('[bed]\ncsv = "bed.csv"\n')
    case = load_case(tmp_path / "case.toml")
    assert [b.center_um for b in case.bodies][2] == [40.0, 54.64]
    assert case.domain.width_um == 80.0  # sized to the bed, in whole cells of 2 um


def test_csv_bed_takes_a_generated_layer_on_top(tmp_path):
    (tmp_path / "bed.csv").write_text(GOOD)
    case = _case(
        {"csv": str(tmp_path / "bed.csv"), "count": 4, "median_diameter_um": 20.0},
        domain={"width_um": 80.0, "height_um": 120.0},
    )
    assert len(case.bodies) == 7 and "csv bed.csv + deposition of 4" in case.bed_report["source"]


CSV_BAD = [
    ("x_um, y_um\n1, 2\n", "line 1", "lacks radius_um"),
    ("x_um, y_um, radius_um\n20, 20, 20\n60, 20\n", "line 3", "2 fields"),
    ("x_um, y_um, radius_um\n20, twenty, 20\n", "line 2", "must be numbers"),
    ("x_um, y_um, radius_um\n20, 20, -1\n", "line 2", "radius_um > 0"),
    ("x_um, y_um, radius_um\n20, 20, 20\n50, 20, 20\n", "line 3", "overlaps line 2 by 10"),
    ("x_um, y_um, radius_um\n20, 20, 20\n60, 30, 20\n", "line 3", "floats"),
    ("x_um, y_um, radius_um\n20, 20, 20\n85, 20, 20\n", "line 3", "outside the domain"),
    ("# nothing\n", "no data rows", "x_um"),
]


@pytest.mark.parametrize("text, where, what", CSV_BAD, ids=[w for _, _, w in CSV_BAD])
def test_bad_csv_names_the_file_row_and_what_is_allowed(tmp_path, text, where, what):
    (tmp_path / "bad.csv").write_text(text)
    with pytest.raises(CaseError) as err:
        _case({"csv": str(tmp_path / "bad.csv")}, domain={"width_um": 100.0, "height_um": 80.0})
    msg = str(err.value)
    print(msg)
    assert "bed.csv" in msg and "bad.csv" in msg and where in msg and what in msg


BED_BAD = [
    ({"count": 200, "median_diameter_um": 40.0}, "hexagonal packing"),  # more than fit
    ({"count": 5, "median_diameter_um": 40.0}, "reach y = 105.7 um, above domain.height_um"),
    ({"count": 5, "median_diameter_um": 120.0}, "bed.x_range_um"),  # wider than the range
    ({"count": 5, "layers": 1.0}, "bed.layers"),
    ({"seed": 3}, "bed.count"),
    ({"count": 5, "material": "steel"}, "bed.material"),
    ({"count": 5, "spread": 2.0}, "bed.spread"),
    ({"csv": "no/such.csv"}, "bed.csv"),
    ({"count": 5, "x_range_um": [50.0, 10.0]}, "bed.x_range_um"),
    ({"count": 5, "x_range_um": [0.0, 150.0]}, "must lie within the domain"),
]


@pytest.mark.parametrize("bed, key", BED_BAD, ids=[k for _, k in BED_BAD])
def test_bad_bed_names_the_key(bed, key):
    with pytest.raises(CaseError) as err:
        _case(bed, domain={"width_um": 100.0, "height_um": 80.0})
    assert key in str(err.value)


def test_generator_without_a_width_asks_for_the_range():
    with pytest.raises(CaseError, match="bed.x_range_um: required"):
        _case({"count": 5})
