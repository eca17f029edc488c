"""A layer that ends molten restarts molten (issue #40, a second layer at machine settings): on a
bed inside the sintering window the melt of the first layer stays amorphous at the bed
temperature, so its layer file carries each point's solid fraction and the next case restarts
those points at the bed temperature with that fraction and the enthalpy H(T, xi) that goes with
it. A file without the fraction (written before it was carried) restarts every point at the
phase of its temperature."""

import numpy as np
from helpers import make_case

from taichi_sls.config.layer_file import read_layer
from taichi_sls.jobs.case_run import write_layer_file
from taichi_sls.solver import struct_copy
from taichi_sls.solver.simulation import Simulation

BED_C = 172.0  # inside PA12's window: below melting, above crystallisation on cooling
PROCESS = {"PA12": {"preset": "pa12_process"}}


def _first_layer(path):
    """One disc on the plate at the bed temperature, its left half set molten, written as a
    layer file; returns the points' x (um) and solid fractions as written."""
    case = make_case(
        {
            "grid": {"spacing_um": 4.0},
            "domain": {"width_um": 60.0, "height_um": 60.0},
            "bodies": [{"shape": "disc", "center_um": [30.0, 15.0], "radius_um": 15.0}],
            "materials": PROCESS,
            "thermal": {"initial_C": BED_C},
            "output": {"png": False, "gif": False},
        }
    )
    sim = Simulation(case)
    pts = sim.point_arrays(("x", "solid_fraction"))
    xi = np.where(pts["x"][:, 0] < 30e-6, 0.0, pts["solid_fraction"])
    struct_copy.from_numpy(sim.state.points, {"solid_fraction": xi})
    write_layer_file(path, sim, "complete")
    return pts["x"][:, 0] * 1e6, xi


def _second(path):
    case = make_case(
        {
            "grid": {"spacing_um": 4.0},
            "bed": {
                "previous_layer": str(path),
                "count": 2,
                "median_diameter_um": 16.0,
                "seed": 1,
                "x_range_um": [0.0, 60.0],
            },
            "materials": PROCESS,
            "thermal": {"initial_C": BED_C},
            "output": {"png": False, "gif": False},
        }
    )
    sim = Simulation(case)
    n = sum(len(b.points_um()[0]) for b in case.bodies if b.shape == "points")
    p = sim.point_arrays(("x", "T", "solid_fraction", "enthalpy"))
    return {k: v[:n] for k, v in p.items()}, sim


def test_a_molten_layer_restarts_molten_with_its_latent_heat(tmp_path):
    """The layer's points restart with the fraction they were written with; at one temperature,
    a molten point holds the latent heat more than a solid one (H = S(T) + l (1 - xi)), to
    round-off relative to the latent heat."""
    path = tmp_path / "layer.npz"
    _, xi = _first_layer(path)
    assert read_layer(str(path)).state["solid_fraction"].shape == xi.shape
    layer, sim = _second(path)
    assert np.allclose(layer["T"] - 273.15, BED_C)
    molten, solid = layer["solid_fraction"] == 0.0, layer["solid_fraction"] == 1.0
    assert molten.sum() == (xi == 0.0).sum() > 0 and solid.sum() == (xi == 1.0).sum() > 0
    latent = sim.case.materials["PA12"].latent_heat_J_kg
    gap = layer["enthalpy"][molten].mean() - layer["enthalpy"][solid].mean()
    assert abs(gap - latent) < 1e-9 * latent
    assert np.ptp(layer["enthalpy"][molten]) < 1e-9 * latent


def test_a_file_without_the_fraction_restarts_at_the_phase_of_its_temperature(tmp_path):
    """Files written before the fraction was carried load as before: every layer point at
    172 C starts solid."""
    path = tmp_path / "layer.npz"
    _first_layer(path)
    with np.load(path) as f:
        kept = {k: f[k] for k in f.files if k != "state_solid_fraction"}
    np.savez_compressed(path, **kept)
    layer, _ = _second(path)
    assert (layer["solid_fraction"] == 1.0).all()
