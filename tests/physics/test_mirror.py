"""Mirror walls (``boundary.<side>.mechanical = "mirror"``, physics/mirror.py): a sphere pair
under a centred beam run as a quarter (mirrors at x = W/2 and z = D/2) gives the full domain's
neck and peak temperature (bench/symmetry.py). The mirror is exact up to rounding (the folded
sums add in another order than the full run's), so the default suite holds the quarter to
1e-6 of the full run at R/h = 4 (measured ~1e-9; a surface cut that is not mirror symmetric,
Kuhn's tetrahedra in every cube, is 4e-4 off within 24 steps). The slow test is the issue's
case, R/h = 8, at its 0.5 % bar. The 2D path of the same fold: the paper's pair as a half,
the mirror on the right or the left wall."""

import numpy as np
import pytest

from bench import symmetry
from taichi_sls.config import CaseError
from taichi_sls.config.loading import case_from_dict, case_to_dict

ROUNDING = 1e-6  # the quarter is the full run's mirror image up to round-off


def test_quarter_matches_the_full_pair_at_r_over_h_4():
    result = symmetry.compare(4, end_s=4e-6, samples=2)
    s = result["summary"]
    assert s["points_full"] == 4 * s["points_quarter"]
    assert s["worst_neck_difference"] <= ROUNDING, result["rows"]
    assert s["worst_T_peak_difference"] <= ROUNDING, result["rows"]
    assert s["final_T_peak_C"] > 141.0  # the beam heated the contact: the check has content


@pytest.mark.slow
def test_quarter_matches_the_full_pair_at_r_over_h_8():
    s = symmetry.compare(8)["summary"]
    assert s["worst_neck_difference"] <= symmetry.TOLERANCE
    assert s["worst_T_peak_difference"] <= symmetry.TOLERANCE


def test_a_sphere_may_cross_a_mirror_only_centred_on_it():
    case = symmetry.pair_case(4, True)
    data = case_to_dict(case)
    data["bodies"][0]["center_um"][2] += 1.0
    with pytest.raises(CaseError, match=r"bodies\[0\]: crosses the mirror boundary.back"):
        case_from_dict(data)


def _pair_2d(side: str | None, end_s: float):
    """The paper's pair (R = 20 um, touching at x = 40 um) under the 25 W beam on their contact,
    or its half beside a mirror on the ``side`` wall (left: the right disc, shifted to x >= 0)."""
    from taichi_sls.solver.simulation import Simulation

    shift = 40.0 if side == "left" else 0.0
    centres = {None: [20.0, 60.0], "right": [20.0], "left": [60.0]}[side]
    data = {
        "domain": {"width_um": 80.0 if side is None else 40.0, "height_um": 48.0},
        "bodies": [{"center_um": [c - shift, 24.0], "radius_um": 20.0} for c in centres],
        "boundary": {} if side is None else {side: {"mechanical": "mirror"}},
        "lasers": [{"power_W": 25.0, "x_start_um": 40.0 - shift, "off_s": end_s}],
        "time": {"end_s": end_s},
        "solver": {"optimize": False},
    }
    sim = Simulation(case_from_dict(data))
    sim.advance_to(end_s)
    snap = sim.snapshot()
    x, T = snap["x_um"], snap["T_C"]
    plane = 40.0 - shift
    near = np.abs(x[:, 0] - plane) < 1.0
    if side != "left":
        near &= x[:, 0] < plane  # the left disc's side of the contact in the full pair
    return np.abs(x[near, 1] - 24.0).max(), T.max()


@pytest.mark.parametrize("side", ["right", "left"])
def test_a_2d_half_pair_matches_the_full_pair(side):
    """Either wall can mirror: the half pair's neck (the farthest point from the axis within
    1 um of the contact) and peak temperature match the full pair's to round-off (the 2D path
    of the same fold)."""
    end = 1e-5
    neck_full, T_full = _pair_2d(None, end)
    neck, T = _pair_2d(side, end)
    assert T_full > 200.0  # the beam heated the contact: the check has content
    assert abs(neck / neck_full - 1.0) <= ROUNDING
    assert abs(T / T_full - 1.0) <= ROUNDING
