"""Mirror walls (``boundary.<side>.mechanical = "mirror"``, physics/mirror.py): a sphere pair
under a centred beam run as a quarter (mirrors at x = W/2 and z = D/2) gives the full domain's
neck and peak temperature (studies/symmetry.py). The mirror is exact up to rounding (the folded
sums add in another order than the full run's), so the default suite holds the quarter to
1e-6 of the full run at R/h = 4 (measured ~1e-9; a surface cut that is not mirror symmetric,
Kuhn's tetrahedra in every cube, is 4e-4 off within 24 steps). The slow test is the issue's
case, R/h = 8, at its 0.5 % bar."""

import pytest

from taichi_sls.config import CaseError
from taichi_sls.config.loading import case_from_dict, case_to_dict
from taichi_sls.studies import symmetry

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
