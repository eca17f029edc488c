"""Shared helpers: small cases built from dicts, compiled without Taichi's advanced optimisation
(about 10x faster to compile; the tests measure accuracy, not speed)."""

import copy

import pytest

from taichi_sls.case import case_from_dict

PAPER_SCENE = {
    "domain": {"width_um": 80.0, "height_um": 48.0},
    "bodies": [
        {"shape": "disc", "center_um": [20.0, 20.0], "radius_um": 20.0},
        {"shape": "disc", "center_um": [60.0, 20.0], "radius_um": 20.0},
    ],
}


def deep_update(base: dict, extra: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in extra.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = deep_update(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def make_case(data: dict):
    """A validated Case from raw data, with fast compilation unless the data says otherwise."""
    data = deep_update({"solver": {"optimize": False}}, data)
    return case_from_dict(data)


@pytest.fixture
def paper_scene() -> dict:
    return copy.deepcopy(PAPER_SCENE)
