"""A layer that ends molten restarts molten (issue #40, a second layer at machine settings): on a
bed inside the sintering window the melt of the first layer stays amorphous at the bed
temperature, so its layer file carries each point's solid fraction and the next case restarts
those points at the bed temperature with that fraction and the enthalpy H(T, xi) that goes with
it. A file without the fraction (written before it was carried) restarts every point at the
phase of its temperature."""

import numpy as np
import pytest
from helpers import make_case

from taichi_sls.config.layer_file import read_layer
from taichi_sls.jobs.observers.layer_file import write_layer_file
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


@pytest.mark.slow  # two 3D simulations built: 30 s beside other runs
def test_a_3d_layer_round_trip_carries_its_points_and_state(tmp_path):
    """3D: a sphere on the plate, its left half molten and its points' deformation set to a
    shear, written as a layer file (x (N, 3), um^3), read by a 3D bed of two spheres: the
    layer's points restart where they were, with their seeded volumes, deformation gradient
    (float32 in the file: 1e-7) and solid fraction, at the bed temperature."""
    case = make_case(
        {
            "grid": {"spacing_um": 4.0},
            "domain": {"dim": 3, "width_um": 40.0, "height_um": 40.0, "depth_um": 40.0},
            "bodies": [{"shape": "disc", "center_um": [20.0, 10.0, 20.0], "radius_um": 10.0}],
            "materials": PROCESS,
            "thermal": {"initial_C": BED_C},
            "physics": {"gravity_m_s2": [0.0, 0.0, 0.0]},
            "output": {"png": False, "gif": False},
        }
    )
    sim = Simulation(case)
    pts = sim.point_arrays(("x", "volume0", "solid_fraction", "F"))
    xi = np.where(pts["x"][:, 0] < 20e-6, 0.0, pts["solid_fraction"])
    F = pts["F"].copy()
    F[:, 0, 1] = 0.01  # a shear the next run must find again
    struct_copy.from_numpy(sim.state.points, {"solid_fraction": xi, "F": F})
    path = tmp_path / "layer.npz"
    write_layer_file(path, sim, "complete")
    layer = read_layer(str(path))
    assert layer.dim == 3 and layer.x_um.shape == (len(xi), 3)
    second = make_case(
        {
            "grid": {"spacing_um": 4.0},
            "domain": {"dim": 3, "width_um": 40.0, "depth_um": 40.0},
            "bed": {
                "previous_layer": str(path),
                "count": 2,
                "median_diameter_um": 12.0,
                "seed": 1,
            },
            "materials": PROCESS,
            "thermal": {"initial_C": BED_C},
            "physics": {"gravity_m_s2": [0.0, 0.0, 0.0]},
            "output": {"png": False, "gif": False},
        }
    )
    assert [b.shape for b in second.bodies] == ["points", "disc", "disc"]
    again = Simulation(second)
    n = len(xi)
    got = again.point_arrays(("x", "volume0", "solid_fraction", "F", "T"))
    assert np.allclose(got["x"][:n], pts["x"], rtol=0, atol=1e-15)
    assert np.allclose(got["volume0"][:n], pts["volume0"], rtol=1e-12, atol=0)
    assert np.allclose(got["F"][:n], F, rtol=0, atol=1e-7)
    assert np.array_equal(got["solid_fraction"][:n], xi)
    assert np.allclose(got["T"][:n] - 273.15, BED_C)
