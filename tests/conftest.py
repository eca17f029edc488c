"""Shared helpers: small cases built from dicts, compiled without Taichi's advanced optimisation
(about 10x faster to compile; the tests measure accuracy, not speed)."""

import copy

import pytest

from taichi_sls.case import case_from_dict
from taichi_sls.verification import deep_update

PAPER_SCENE = {
    "domain": {"width_um": 80.0, "height_um": 48.0},
    "bodies": [
        {"shape": "disc", "center_um": [20.0, 20.0], "radius_um": 20.0},
        {"shape": "disc", "center_um": [60.0, 20.0], "radius_um": 20.0},
    ],
}


def make_case(data: dict):
    """A validated Case from raw data, with fast compilation unless the data says otherwise."""
    data = deep_update({"solver": {"optimize": False}}, data)
    return case_from_dict(data)


@pytest.fixture
def paper_scene() -> dict:
    return copy.deepcopy(PAPER_SCENE)
