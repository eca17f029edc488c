"""Shared test helpers: small cases built from dicts, compiled without Taichi's advanced
optimisation (about 10x faster to compile; the tests measure accuracy, not speed)."""

from taichi_sls.config import case_from_dict, deep_update

PAPER_SCENE = {
    "domain": {"width_um": 80.0, "height_um": 48.0},
    "bodies": [
        {"shape": "disc", "center_um": [20.0, 20.0], "radius_um": 20.0},
        {"shape": "disc", "center_um": [60.0, 20.0], "radius_um": 20.0},
    ],
}

__all__ = ["PAPER_SCENE", "deep_update", "make_case"]


def make_case(data: dict):
    """A validated Case from raw data, with fast compilation unless the data says otherwise."""
    data = deep_update({"solver": {"optimize": False}}, data)
    return case_from_dict(data)


def material_field(m):
    """A one-element Taichi struct field of material ``m`` (after ti.init), as kernels see it."""
    import numpy as np

    from taichi_sls.physics.materials import material_struct
    from taichi_sls.solver.params import material_values

    f = material_struct().field(shape=1)
    f.from_numpy({k: np.array([v]) for k, v in material_values(m, 0.0).items()})
    return f
