"""3D powder beds, what only 3D has: the volume of spheres cut by a window, the [bed] table's
z range and depth, and its one-line errors (numpy only, no simulation). What 2D and 3D share
(deposition, packing, the [bed] table) is tested over dim in test_bed.py."""

import math
from pathlib import Path

import numpy as np
import pytest

from taichi_sls.config import CaseError, case_from_dict
from taichi_sls.config.packing import slab_volume, volume_in_box

ROOT_CASES = Path(__file__).resolve().parents[2] / "cases"


def test_volume_in_a_box_of_cut_spheres():
    c, r = np.array([[0.0, 0.0, 0.0]]), np.array([1.0])
    ball = 4.0 / 3.0 * math.pi
    assert volume_in_box(c, r, (-5, 5), (-5, 5), (-5, 5)) == pytest.approx(ball, rel=1e-12)
    # an octant (three cuts through the centre), and a cap of height 1/2 cut by the y slab
    # (exact) and by a side (the midpoint rules of 64 slices and 128 chords: 3e-6 measured)
    assert volume_in_box(c, r, (0, 5), (0, 5), (0, 5)) == pytest.approx(ball / 8, rel=1e-5)
    cap = math.pi * 0.5**2 * (3 - 0.5) / 3
    assert volume_in_box(c, r, (-5, 5), (0.5, 5), (-5, 5)) == pytest.approx(cap, rel=1e-12)
    assert volume_in_box(c, r, (0.5, 5), (-5, 5), (-5, 5)) == pytest.approx(cap, rel=1e-5)
    assert slab_volume(np.array([0.0]), r, -1.0, 1.0)[0] == pytest.approx(ball, rel=1e-14)


# ------------------------------------------------------------------------ the [bed] table

BED3D = {
    "domain": {"dim": 3},
    "grid": {"spacing_um": 5.0},
    "physics": {"surface_tension": False},
}


def _case(bed: dict, **extra):
    return case_from_dict({**BED3D, **extra, "bed": bed})


def _error(bed: dict, **extra) -> str:
    with pytest.raises(CaseError) as err:
        _case(bed, **extra)
    assert "\n" not in str(err.value)
    return str(err.value)


@pytest.mark.parametrize(
    "rows, says",
    [
        ("20,10,20,10\n25,10,20,10\n", "line 3: the sphere overlaps line 2 by 15 um"),
        ("20,10,20,10\n20,40,20,10\n", "line 3: the sphere at (20, 40, 20) um floats"),
        (
            "20,10,55,10\n",
            "line 2: the sphere at (20, 10, 55) um of radius 10 um lies "
            "outside the domain 0..60 x 0..60 x 0..60 um",
        ),
        ("20,10,20\n", "line 2: 3 fields, the header has 4"),
    ],
)
def test_bad_csv_spheres_are_one_line_errors(tmp_path, rows, says):
    path = tmp_path / "bed.csv"
    path.write_text("x_um,y_um,z_um,radius_um\n" + rows)
    msg = _error({"csv": str(path)}, domain={"dim": 3, "width_um": 60.0, "height_um": 60.0})
    assert msg.startswith(f"bed.csv = {str(path)!r}") and says in msg


def test_3d_bed_refusals_name_their_keys():
    from taichi_sls.config import bundled_case

    layer = bundled_case("machine_layer").parent / "layers" / "machine_layer.npz"  # a 2D layer
    msg = _error({"previous_layer": str(layer), "count": 3})
    assert msg.startswith("bed.previous_layer =") and "a 2D layer" in msg
    assert "domain.dim = 3" in msg
    msg = _error(
        {"count": 900, "median_diameter_um": 20.0, "x_range_um": [0, 60]},
        domain={"dim": 3, "width_um": 60.0, "height_um": 40.0, "depth_um": 60.0},
    )
    assert msg.startswith("bed: 900 spheres") and "domain.height_um = 40" in msg
    # z_range_um is 3D only
    with pytest.raises(CaseError) as err:
        case_from_dict({"bed": {"count": 3, "x_range_um": [0, 100], "z_range_um": [0, 50]}})
    assert str(err.value).startswith("bed.z_range_um = [0.0, 50.0]: 3D only")


def test_a_beam_left_at_mid_depth_follows_the_depth_the_bed_fits():
    """lasers.N.z_start_um unset: the mid-depth of the domain as the bed fitted it (120 um
    deep here: 60 um), not of the default depth (the width, 80 um) before the bed set it."""
    case = _case(
        {"count": 12, "median_diameter_um": 20.0, "x_range_um": [0, 60], "z_range_um": [0, 120]},
        lasers=[{"speed_m_s": 4.0, "x_start_um": 0.0}],
    )
    assert case.domain.depth() == pytest.approx(120.0)
    assert case.lasers[0].z_start_um == pytest.approx(60.0)


def test_the_gpu_layer_case_loads():
    """cases/bed3d_hatch_gpu.toml (the larger layer documented for a GPU, not run here) is a
    valid case: 400 spheres over 240 x 240 um at h = 2 um under three hatched tracks."""
    from taichi_sls.config import load_case

    case = load_case(ROOT_CASES / "bed3d_hatch_gpu.toml")
    assert case.domain.dim == 3 and len(case.bodies) == case.bed_report["spheres"] == 400
    assert case.grid.spacing_um == 2.0
    assert case.lasers[0].tracks == 3 and case.lasers[0].hatch_um == 80.0
