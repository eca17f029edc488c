"""A periodic depth (3D, boundary.front / back mechanical = "periodic"; solver/periodic.py) and
the cylinder body: refused where they cannot run, and the wrap exact where they can."""

import tomllib

import numpy as np
import pytest
from helpers import advance_steps, make_case

from taichi_sls.config import CaseError, bundled_case
from taichi_sls.solver.scene import build_scene
from taichi_sls.solver.simulation import Simulation

# Hopper's viscous liquid (cases/verification/hopper.toml), its one material table
with open(bundled_case("verification/hopper"), "rb") as f:
    FLUID = dict(tomllib.load(f)["materials"]["fluid"])

PERIODIC = {"front": {"mechanical": "periodic"}, "back": {"mechanical": "periodic"}}
SIDES = ("left", "right", "bottom", "top")
OPEN = {w: {"mechanical": "open", "thermal": "insulated"} for w in SIDES}


def _blocks(z_ranges: list[tuple[float, float]]) -> dict:
    """A fluid block 6 x 5 um in x-y over the z ranges given (um), moving along z at 0.2 m/s in
    a 12 x 12 x 8 um box with a periodic depth, the surface-energy force on."""
    return {
        "grid": {"spacing_um": 1.0},
        "domain": {"dim": 3, "width_um": 12.0, "height_um": 12.0, "depth_um": 8.0},
        "bodies": [
            {
                "shape": "rect",
                "min_um": [3, 3, a],
                "max_um": [9, 8, b],
                "material": "fluid",
                "velocity_m_s": [0.0, 0.0, 0.2],
            }
            for a, b in z_ranges
        ],
        "materials": {"fluid": FLUID},
        "physics": {"gravity_m_s2": [0.0, 0.0, 0.0], "thermal": False},
        "surface_tension": {"method": "surface_energy", "initial_stress": "none"},
        "boundary": {**OPEN, **PERIODIC},
        "solver": {"transfer": "apic"},
    }


def _run(z_ranges, steps: int = 300):
    sim = Simulation(make_case(_blocks(z_ranges)))
    pt = sim.state.points
    m = pt.mass.to_numpy()
    p0 = (m[:, None] * pt.v.to_numpy()).sum(axis=0)
    advance_steps(sim, steps)
    x, v = pt.x.to_numpy(), pt.v.to_numpy()
    return x, v, p0, (m[:, None] * v).sum(axis=0)


def test_periodic_wrap_is_exact_across_the_seam():
    """The same block, once in the middle of the period (z 2..6 um) and once cut by the seam
    (z 6..8 and 0..2 um), moving along z under its surface tension for 300 steps: the second
    is the first shifted by D/2 (measured: positions to 3e-20 m, velocities to 2e-15 m/s of
    0.29 m/s; 1e-15 m and 1e-12 m/s allow the sums' order), its points stay in [0, D), and
    the momentum is kept (z exactly as in 2D's open boxes; x, y, zero at the start, to 1e-20
    kg m/s of the 2.4e-14 along z: the spread floor's round-off)."""
    xa, va, p0a, p1a = _run([(2.0, 6.0)])
    xb, vb, p0b, p1b = _run([(6.0, 8.0), (0.0, 2.0)])
    D = 8e-6
    assert xb[:, 2].min() >= 0.0 and xb[:, 2].max() < D
    xs = xb.copy()
    xs[:, 2] = np.mod(xb[:, 2] - 0.5 * D, D)
    ia = np.lexsort((xa[:, 2], xa[:, 1], xa[:, 0]))
    ib = np.lexsort((xs[:, 2], xs[:, 1], xs[:, 0]))
    assert np.abs(xa[ia] - xs[ib]).max() < 1e-15
    assert np.abs(va[ia] - vb[ib]).max() < 1e-12
    assert np.abs(va).max() > 0.25  # the block did move
    for p0, p1 in ((p0a, p1a), (p0b, p1b)):
        assert p1[2] == pytest.approx(p0[2], rel=1e-9)
        assert np.abs(p1[:2]).max() < 1e-20


def _case(**over) -> dict:
    d = _blocks([(0.0, 8.0)])
    for k, v in over.items():
        d[k] = v
    return d


@pytest.mark.parametrize(
    "data, key",
    [
        (
            {
                "domain": {"width_um": 12.0, "height_um": 12.0},
                "bodies": [{"shape": "disc", "center_um": [6.0, 6.0], "radius_um": 3.0}],
                "boundary": PERIODIC,
            },
            'boundary.front.mechanical = "periodic" with domain.dim = 2',
        ),
        (
            {
                "domain": {"width_um": 12.0, "height_um": 12.0},
                "bodies": [{"shape": "cylinder", "axis_um": [6.0, 6.0], "radius_um": 3.0}],
            },
            'bodies[0].shape = "cylinder" with domain.dim = 2',
        ),
        (
            {
                "domain": {"width_um": 12.0, "height_um": 12.0},
                "bodies": [{"shape": "prism", "vertices_um": [[3, 3], [9, 3], [6, 9]]}],
            },
            'bodies[0].shape = "prism" with domain.dim = 2',
        ),
        (_case(boundary={"front": {"mechanical": "periodic"}}), "boundary.back.mechanical"),
        (_case(boundary={"left": {"mechanical": "periodic"}}), "boundary.left.mechanical"),
        (
            _case(boundary={**PERIODIC, "back": {"mechanical": "periodic", "thermal": "fixed"}}),
            "boundary.back.thermal",
        ),
        (_case(boundary=PERIODIC, solver={"update": "musl"}), "solver.update"),
        (
            _case(boundary={**PERIODIC, "left": {"mechanical": "mirror"}}),
            'boundary.left.mechanical = "mirror" with a periodic depth',
        ),
    ],
)
def test_refused_with_its_key(data, key):
    with pytest.raises(CaseError) as e:
        make_case(data)
    assert key in str(e.value)


def test_a_cylinder_runs_across_the_depth():
    """A cylinder R = 3 um, axis (6, 6) um, over a depth of 4 um at h = 1 um, 2 x 2 x 2 points
    per cell: every z layer holds the same disc of points (the staircase of the 2D disc)."""
    cyl = {"shape": "cylinder", "axis_um": [6.0, 6.0], "radius_um": 3.0, "material": "fluid"}
    d = _case(bodies=[cyl])
    d["domain"] = {"dim": 3, "width_um": 12.0, "height_um": 12.0, "depth_um": 4.0}
    s = build_scene(make_case(d))
    x = s.x * 1e6
    assert np.hypot(x[:, 0] - 6.0, x[:, 1] - 6.0).max() < 3.0
    layers = np.unique(np.round(x[:, 2], 6))
    assert len(layers) == 8  # two point layers per cell
    count = [(np.abs(x[:, 2] - z) < 1e-6).sum() for z in layers]
    assert len(set(count)) == 1


def test_a_prism_is_the_polygon_in_every_layer():
    """A prism (a triangle's outline extruded along z, 4 um deep) seeds in each of its 8 z
    layers of points exactly the x-y points the 2D polygon seeds (same grid, same centre
    seeding); its outline for the energy scales is the triangle's perimeter times the depth,
    as a cylinder's is 2 pi R times it."""
    tri = [[3.0, 3.0], [9.0, 3.5], [5.0, 9.0]]
    d2 = _case(bodies=[{"shape": "polygon", "vertices_um": tri, "material": "fluid"}])
    d2["domain"] = {"width_um": 12.0, "height_um": 12.0}
    d2["boundary"] = OPEN
    d2["physics"]["gravity_m_s2"] = [0.0, 0.0]
    d3 = _case(bodies=[{"shape": "prism", "vertices_um": tri, "material": "fluid"}])
    d3["domain"] = {"dim": 3, "width_um": 12.0, "height_um": 12.0, "depth_um": 4.0}
    flat, prism = build_scene(make_case(d2)), build_scene(make_case(d3))
    xy = np.round(np.sort(flat.x[:, 0] * 1e6 + 1e3 * flat.x[:, 1] * 1e6), 9)
    layers = np.unique(np.round(prism.x[:, 2] * 1e6, 6))
    assert len(layers) == 8
    for z in layers:
        sel = np.abs(prism.x[:, 2] * 1e6 - z) < 1e-6
        layer = np.round(np.sort(prism.x[sel, 0] * 1e6 + 1e3 * prism.x[sel, 1] * 1e6), 9)
        np.testing.assert_array_equal(layer, xy)
    perimeter = float(np.sum(np.linalg.norm(np.diff(np.array(tri + tri[:1]), axis=0), axis=1)))
    assert make_case(d3).outline_um() == pytest.approx(perimeter * 4.0, rel=1e-12)
    cyl = _case(
        bodies=[{"shape": "cylinder", "axis_um": [6, 6], "radius_um": 3.0, "material": "fluid"}]
    )
    cyl["domain"] = d3["domain"]
    assert make_case(cyl).outline_um() == pytest.approx(2 * np.pi * 3.0 * 4.0, rel=1e-12)


def _heat_run(hot, cold):
    ins = {w: {"thermal": "insulated"} for w in SIDES}
    rows = [(r, 200.0) for r in hot] + [(r, 150.0) for r in cold]
    d = {
        "grid": {"spacing_um": 2.0},
        "domain": {"dim": 3, "width_um": 8.0, "height_um": 8.0, "depth_um": 16.0},
        "bodies": [
            {"shape": "rect", "min_um": [0, 0, a], "max_um": [8, 8, b], "temperature_C": T}
            for (a, b), T in rows
        ],
        "physics": {"surface_tension": False, "mechanics": False},
        "boundary": {**ins, **PERIODIC},
    }
    sim = Simulation(make_case(d))
    pt = sim.state.points
    H0 = (pt.enthalpy.to_numpy() * pt.mass.to_numpy()).sum()
    advance_steps(sim, 400)
    H1 = (pt.enthalpy.to_numpy() * pt.mass.to_numpy()).sum()
    return pt.x.to_numpy(), pt.T.to_numpy(), H0, H1


def test_periodic_heat_is_conserved_and_exact_across_the_seam():
    """Heat only: a hot slab at 200 C between cold ones at 150 C (z 4..12 um of 16), and the
    same shifted by D/2 so that the hot slab is cut by the seam; 400 steps: the enthalpy is
    kept to round-off (measured 2e-16; bound 1e-12 as the 2D tests) while the slabs exchange
    heat, and the two runs agree point by point (measured 1.7e-13 K; bound 1e-9 K)."""
    xa, Ta, H0a, H1a = _heat_run([(4, 12)], [(0, 4), (12, 16)])
    xb, Tb, H0b, H1b = _heat_run([(12, 16), (0, 4)], [(4, 12)])
    assert abs(H1a / H0a - 1.0) < 1e-12 and abs(H1b / H0b - 1.0) < 1e-12
    assert Ta.max() - Ta.min() < 10.0  # from 50 K apart: the heat did cross the seam
    D = 16e-6
    xs = xb.copy()
    xs[:, 2] = np.mod(xb[:, 2] - 0.5 * D, D)
    ia = np.lexsort((xa[:, 2], xa[:, 1], xa[:, 0]))
    ib = np.lexsort((xs[:, 2], xs[:, 1], xs[:, 0]))
    assert np.abs(xa[ia] - xs[ib]).max() < 1e-15
    assert np.abs(Ta[ia] - Tb[ib]).max() < 1e-9
