"""Powder beds: the deposition generator, its packing fraction against the published values,
the [bed] table, CSV beds, and one clear error for each kind of bad bed (numpy only, no
simulation). What holds in 2D and 3D alike is tested over ``dim``; 3D's own in test_bed3d.py."""

import math

import numpy as np
import pytest
from scipy.optimize import nnls

from taichi_sls.config import CaseError, bundled_case, case_from_dict, case_to_dict, load_case
from taichi_sls.config.deposition import deposit, lognormal_diameters
from taichi_sls.config.packing import area_in_window, packing_fractions
from taichi_sls.solver.contacts import touching
from taichi_sls.solver.scene import build_scene

# Random sequential deposition with rolling packs its bulk at about 0.82 with equal discs in 2D
# (Visscher & Bolsterli 1972, Nature 239, 504) and 0.58 with equal spheres in 3D (each sphere
# rolls to rest on three: the same paper, and Jullien & Meakin's "restructuring" model,
# Europhys. Lett. 4, 1385, 1987). Random close packing is 0.84 for discs (Meer et al. 2024,
# arXiv:2404.02316: phi_0 = 0.840 at low skewness) and 0.64 for spheres; random loose packing
# of spheres 0.55. 2D: six seeds of the 1000-disc bed below read 0.818-0.827 in the bulk
# window. 3D: six seeds of a 2000-sphere periodic bed read 0.577-0.583 (docs/record/beds.md); 0.015
# is the sampling scatter of a core of ~1100 spheres (a few 0.001) plus the spread of the
# published figures (0.58-0.59). Both bands are 0.015 wide.
DEPOSITION_2D, RCP_2D = 0.82, 0.84
DEPOSITION_3D, RLP_3D, RCP_3D = 0.58, 0.55, 0.64
# dim: (published bulk, random loose, random close, the bed that reads it: n, side, lateral)
PUBLISHED = {
    2: (DEPOSITION_2D, 0.0, RCP_2D, 1000, 30.0, "walls"),
    3: (DEPOSITION_3D, RLP_3D, RCP_3D, 2000, 12.0, "periodic"),
}
DIMS = [2, 3]


def _bed(dim: int, n: int, spread: float, seed: int, side: float, lateral: str = "walls"):
    """n particles of median diameter 1 over [0, side] (x; x and z in 3D): (centres, radii)."""
    rng = np.random.default_rng(seed)
    r = lognormal_diameters(rng, n, 1.0, spread) / 2
    return deposit(r, [(0.0, side)] * (dim - 1), rng, lateral=lateral), r


def _gaps(c, r, side=None):
    """Surface gaps of every pair (inf on the diagonal) and the centre differences; ``side``:
    periodic in x and z."""
    d = c[:, None] - c[None]
    if side is not None:
        d[..., [0, 2]] -= side * np.round(d[..., [0, 2]] / side)
    gap = np.linalg.norm(d, axis=2) - (r[:, None] + r)
    gap[np.diag_indices(len(r))] = np.inf
    return gap, d


@pytest.mark.parametrize("dim", DIMS)
def test_same_seed_same_bed_and_another_seed_another(dim):
    a, b, c = (_bed(dim, 150, 0.2, seed, 6.0) for seed in (7, 7, 8))
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    assert not np.allclose(a[0][:10], c[0][:10])


@pytest.mark.parametrize("dim", DIMS)
def test_packing_fraction_of_equal_particles_matches_sequential_deposition(dim):
    """The bulk window, 2 diameters clear of the walls (none in a periodic bed), the plate and
    the mean top, holds the published value and lies between random loose and close packing."""
    published, loose, close, n, side, lateral = PUBLISHED[dim]
    c, r = _bed(dim, n, 0.0, 3 if dim == 2 else 0, side, lateral)
    pf = packing_fractions(c, r, [(0.0, side)] * (dim - 1), periodic=lateral == "periodic")
    print(pf)
    assert abs(pf["bulk"] - published) < 0.015
    assert loose < pf["bulk"] < close
    if dim == 2:  # the envelope counts the rough top and the wall layers: looser than the bulk
        assert pf["bulk"] > pf["envelope"] > 0.78
    else:
        assert pf["core_y"][1] - pf["core_y"][0] > 7.0  # a core of at least 7 diameters


@pytest.mark.parametrize("dim", DIMS)
def test_walls_and_a_spread_keep_the_bulk_in_the_random_band(dim):
    _, loose, close, *_ = PUBLISHED[dim]
    n, spread, seed, side = (1000, 0.1, 4, 30.0) if dim == 2 else (700, 0.2, 1, 8.0)
    c, r = _bed(dim, n, spread, seed, side)
    pf = packing_fractions(c, r, [(0.0, side)] * (dim - 1))
    assert max(loose, 0.79 if dim == 2 else 0.0) < pf["bulk"] < close
    assert 0.5 < pf["envelope"] < close


@pytest.mark.parametrize("dim, lateral", [(2, "walls"), (3, "walls"), (3, "periodic")])
def test_no_overlap_and_every_particle_rests_on_the_plate_or_dim_supports(dim, lateral):
    """Each particle touches the plate, or particles placed before it (and walls) whose contact
    normals hold it up: gravity's reaction (0, 1[, 0]) is a non-negative sum of them (NNLS to
    round-off), with at least dim of them (two for a disc, three for a sphere), most exactly
    dim."""
    side = 10.0 if lateral == "periodic" else (15.0 if dim == 2 else 6.0)
    c, r = _bed(dim, 400 if dim == 2 else 300, 0.3, 5, side, lateral)
    gap, d = _gaps(c, r, side if lateral == "periodic" else None)
    assert gap.min() > -1e-9
    across = (0,) if dim == 2 else (0, 2)
    assert np.all(c[:, across] >= 0) and np.all(c[:, across] <= side)
    tol = 1e-8
    rests_on = []
    for i in range(len(r)):
        if c[i, 1] - r[i] < tol:
            rests_on.append(0)
            continue
        normals = [d[i, k] / np.linalg.norm(d[i, k]) for k in np.nonzero(gap[i, :i] < tol)[0]]
        if lateral == "walls":
            for axis in across:
                if c[i, axis] - r[i] < tol:
                    normals.append(np.eye(dim)[axis])
                if c[i, axis] + r[i] > side - tol:
                    normals.append(-np.eye(dim)[axis])
        mu, residual = nnls(np.array(normals).T, np.eye(dim)[1])
        assert residual < 1e-6, f"particle {i} is not held up"
        rests_on.append(int(np.sum(mu > 1e-9)))
    rests_on = np.array(rests_on)
    assert np.all((rests_on == 0) | (rests_on >= dim))
    assert np.sum(rests_on == dim) > 0.5 * len(r)


@pytest.mark.parametrize("dim", DIMS)
def test_deposits_on_existing_particles(dim):
    old, r0 = _bed(dim, 40 if dim == 2 else 60, 0.2, 1, 10.0 if dim == 2 else 5.0)
    side = 10.0 if dim == 2 else 5.0
    rng = np.random.default_rng(2)
    r = np.full(30 if dim == 2 else 40, 0.4)
    new = deposit(r, [(0.0, side)] * (dim - 1), rng, existing=np.column_stack([old, r0]))
    gap, _ = _gaps(np.r_[old, new], np.r_[r0, r])
    assert gap.min() > -1e-9
    assert np.mean(new[:, 1]) > np.mean(old[:, 1])  # the new layer lies on top of the old


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


# ------------------------------------------------------------------------ the [bed] table

BED = {"grid": {"spacing_um": 4.0}, "contact": {"initial": "fillet"}}


def _case(bed: dict, **extra):
    return case_from_dict({**BED, **extra, "bed": bed})


# the [bed] table in each dimension: the case around it, and a generated example
BASES = {
    2: BED,
    3: {"domain": {"dim": 3}, "grid": {"spacing_um": 5.0}, "physics": {"surface_tension": False}},
}
EXAMPLE = {  # dim: (count, median diameter, seed, x range)
    2: (30, 40.0, 0, [0.0, 400.0]),
    3: (25, 20.0, 3, [0.0, 80.0]),
}


def _dim_case(dim: int, bed: dict, domain: dict | None = None, **extra):
    base = BASES[dim]
    domain = {**base.get("domain", {}), **(domain or {})}
    return case_from_dict({**base, **extra, "domain": domain, "bed": bed})


def _particles(case) -> tuple[np.ndarray, np.ndarray]:
    c = np.array([b.center_um for b in case.bodies if b.shape == "disc"])
    return c, np.array([b.radius_um for b in case.bodies if b.shape == "disc"])


@pytest.mark.parametrize("dim", DIMS)
def test_bed_becomes_bodies_and_the_domain_fits_it(dim):
    n, median, seed, x_range = EXAMPLE[dim]
    case = _dim_case(
        dim, {"count": n, "median_diameter_um": median, "seed": seed, "x_range_um": x_range}
    )
    assert len(case.bodies) == n and all(b.shape == "disc" for b in case.bodies)
    c, r = _particles(case)
    assert c.shape == (n, dim)
    top = float(np.max(c[:, 1] + r))
    assert case.domain.width_um == x_range[1]
    assert top < case.domain.height_um <= top + 2 * median + case.grid.spacing_um
    across = [0] if dim == 2 else [0, 2]
    assert np.all(c[:, across] - r[:, None] >= -1e-9)
    assert np.all(c[:, across] + r[:, None] <= x_range[1] + 1e-9)
    if dim == 3:  # without depth_um: as deep as it is wide
        assert case.domain.depth_um == x_range[1]
    rep = case.bed_report
    assert rep["discs" if dim == 2 else "spheres"] == n and rep["contacts"] >= n
    assert rep["source"] == f"deposition of {n} (seed {seed})"
    assert 0.5 < rep["envelope"] < 0.91
    # the resolved case lists the particles and no bed: it loads back to the same case
    data = case_to_dict(case)
    assert "bed" not in data
    assert case_to_dict(case_from_dict(data)) == data


@pytest.mark.parametrize("dim", DIMS)
def test_layers_set_the_count_and_particles_land_on_body_particles(dim):
    """bed.layers monolayers: one particle per median diameter of width (2D), per median
    diameter squared of area (3D); the deposited particles land on a [[bodies]] particle."""
    body = {"shape": "disc", "center_um": [100.0, 20.0, 50.0][:dim], "radius_um": 20.0}
    domain = {"width_um": 200.0, "height_um": 200.0} | ({"depth_um": 100.0} if dim == 3 else {})
    case = _dim_case(dim, {"layers": 2.0, "median_diameter_um": 40.0}, domain, bodies=[body])
    per_layer = 200 / 40 if dim == 2 else 200 * 100 / 40**2
    assert len(case.bodies) == 1 + round(2.0 * per_layer)
    c, r = _particles(case)
    assert _gaps(c, r)[0].min() > -1e-9
    if dim == 3:
        assert np.max(c[:, 2] + r) <= 100.0 + 1e-9


CSV_ROWS = {  # two on the plate, one on them
    2: "x_um, y_um, radius_um, id\n20, 20, 20, a\n60, 20, 20, b\n40, 54.64, 20, c\n",
    3: "x_um,y_um,z_um,radius_um\n20,10,20,10\n40,10,20,10\n30,27.320508075688775,20,10\n",
}


@pytest.mark.parametrize("dim", DIMS)
def test_csv_bed_takes_a_generated_layer_on_top(tmp_path, dim):
    """The generated particles land on the CSV's: none overlaps another."""
    (tmp_path / "bed.csv").write_text(CSV_ROWS[dim])
    domain = {"width_um": 80.0, "height_um": 120.0} if dim == 2 else {"width_um": 60.0}
    csv_only = _dim_case(dim, {"csv": str(tmp_path / "bed.csv")}, domain | {"height_um": 120.0})
    assert len(csv_only.bodies) == 3
    if dim == 3:
        assert csv_only.bed_report["contacts"] == 3
    case = _dim_case(
        dim,
        {"csv": str(tmp_path / "bed.csv"), "count": 6, "median_diameter_um": 20.0},
        domain | {"height_um": 120.0},
    )
    assert len(case.bodies) == 9
    assert "csv bed.csv + deposition of 6" in case.bed_report["source"]
    c, r = _particles(case)
    assert _gaps(c, r)[0][3:].min() > -1e-9  # the CSV's own rows are rounded: 2 nm apart


def test_generated_contacts_are_the_solver_contacts():
    """Every touching pair of a generated bed is a contact of the seeded points (h = 4 um), and
    pairs clearly apart (gap beyond the fillet's reach and the 1.5-spacing search) are not."""
    case = _case({"count": 25, "median_diameter_um": 40.0, "spread": 0.2, "seed": 2,
                  "x_range_um": [0.0, 300.0]})  # fmt: skip
    sc = build_scene(case)
    pairs = set(touching(sc.x, sc.body, sc.h / case.grid.points_per_cell))
    c = np.array([b.center_um for b in case.bodies])
    r = np.array([b.radius_um for b in case.bodies])
    gap = _gaps(c, r)[0]
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
