"""Overlapping [[bodies]] discs (config/overlap.py): an error naming both bodies and the depth,
unless contact.allow_overlap says they are meant to overlap."""

import pytest

from taichi_sls.config import CaseError, case_from_dict
from taichi_sls.solver.scene import build_scene


def _discs(*discs, **contact):
    data = {
        "domain": {"width_um": 200.0, "height_um": 100.0},
        "bodies": [{"shape": "disc", "center_um": c, "radius_um": r} for c, r in discs],
    }
    if contact:
        data["contact"] = contact
    return data


def test_overlapping_discs_are_an_error_naming_both_and_the_depth():
    # the pair: centres 10 um apart, radii 20 um: 30 um deep
    with pytest.raises(CaseError) as err:
        case_from_dict(_discs(([50.0, 50.0], 20.0), ([60.0, 50.0], 20.0)))
    msg = str(err.value)
    assert "bodies[0] and bodies[1]" in msg
    assert "overlap by 30 um" in msg
    assert "contact.allow_overlap = true" in msg
    assert "\n" not in msg


def test_the_first_overlapping_pair_is_named_among_others():
    data = _discs(([30.0, 50.0], 20.0), ([80.0, 50.0], 20.0), ([110.0, 50.0], 15.0))
    with pytest.raises(CaseError, match=r"bodies\[1\] and bodies\[2\]: the discs overlap by 5 um"):
        case_from_dict(data)


def test_touching_and_apart_discs_load():
    case = case_from_dict(_discs(([50.0, 50.0], 20.0), ([90.0, 50.0], 20.0), ([150.0, 50.0], 5.0)))
    assert len(case.bodies) == 3


def test_allow_overlap_keeps_the_overlap_with_the_first_body():
    data = _discs(([50.0, 50.0], 20.0), ([60.0, 50.0], 20.0), allow_overlap=True)
    case = case_from_dict(data)
    assert case.contact.allow_overlap
    scene = build_scene(case)
    n0, n1 = (int((scene.body == b).sum()) for b in (0, 1))
    assert n0 > 1.4 * n1  # the second disc lost the lens it shares with the first


def test_allow_overlap_must_be_a_boolean():
    with pytest.raises(CaseError, match="allow_overlap"):
        case_from_dict(_discs(([50.0, 50.0], 20.0), allow_overlap="sometimes"))
