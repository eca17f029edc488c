"""A 3D bed deposited on a previous 3D layer (``bed.previous_layer`` with ``domain.dim = 3``): the
layer file's bodies become ``points`` bodies placed as they were, new spheres land on their
cubes, the fillet joins a sphere to the layer, and a layer of the other dimension is refused in
one line naming the key (numpy only, no simulation)."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from taichi_sls.config import CaseError, case_from_dict
from taichi_sls.config.layer_file import read_layer
from taichi_sls.io.layer_output import write_layer
from taichi_sls.solver.scene import build_scene

H_UM = 4.0  # points 2 um apart (2 per cell along each axis)
SIDE = 2.0


def _slab(path, width=60.0, height=10.0, depth=60.0, bodies=2):
    """A 3D layer file: a slab of points 2 um apart whose top is wavy along x and z (valleys for
    the spheres), cut into ``bodies`` strips along x, with the state a run writes left out."""
    g = np.arange(SIDE / 2, width, SIDE)
    gz = np.arange(SIDE / 2, depth, SIDE)
    X, Y, Z = np.meshgrid(g, np.arange(SIDE / 2, height + 6.0, SIDE), gz, indexing="ij")
    top = height + 2.0 * np.sin(2 * np.pi * X / 30.0) * np.cos(2 * np.pi * Z / 30.0)
    keep = Y < top
    x = np.stack([X[keep], Y[keep], Z[keep]], axis=1)
    write_layer(
        path,
        x_um=x,
        volume=np.full(len(x), SIDE**3),
        body=np.minimum((x[:, 0] / width * bodies).astype(int), bodies - 1),
        material=np.zeros(len(x), dtype=int),
        material_names=["PA12"],
        T_C=np.full(len(x), 172.0),
        info={"case": "slab3d"},
    )
    return x


def _case(path, dim=3, **bed):
    domain = {"dim": 3, "width_um": 60.0, "depth_um": 60.0} if dim == 3 else {"width_um": 60.0}
    return case_from_dict(
        {
            "grid": {"spacing_um": H_UM},
            "domain": domain,
            "bed": {
                "previous_layer": str(path),
                "count": 5,
                "median_diameter_um": 20.0,
                "seed": 4,
                **bed,
            },
            "contact": {"initial": "fillet"},
        }
    )


def test_new_spheres_rest_on_the_3d_layer(tmp_path):
    """The layer's two bodies come first, as points bodies, then the five spheres; no sphere
    overlaps a layer point's sphere (radius half its side) by more than round-off, every sphere
    rests on a layer point or another sphere (none reaches the plate under the 8-12 um slab),
    and the domain holds the new top; the report names the layer."""
    x = _slab(tmp_path / "layer.npz")
    case = _case(tmp_path / "layer.npz")
    assert [b.shape for b in case.bodies] == ["points"] * 2 + ["disc"] * 5
    s = np.array([[*b.center_um, b.radius_um] for b in case.bodies[2:]])
    gap = np.linalg.norm(s[:, None, :3] - x[None], axis=2) - s[:, 3:4] - SIDE / 2
    assert gap.min() > -1e-6
    d = np.linalg.norm(s[:, None, :3] - s[None, :, :3], axis=2)
    pair = d - s[:, None, 3] - s[None, :, 3] + np.diag(np.full(5, np.inf))
    assert ((gap.min(axis=1) < 1e-6) | (pair.min(axis=1) < 1e-6)).all()
    assert (s[:, 1] - s[:, 3]).min() > 7.0  # on the slab, not the plate
    assert case.domain.height_um >= (s[:, 1] + s[:, 3]).max()
    rep = case.bed_report
    assert rep["previous_layer_bodies"] == 2 and rep["previous_layer_points"] == len(x)
    assert np.isnan(rep["envelope"])


def test_the_3d_scene_holds_the_layer_and_bridges_to_it(tmp_path):
    """The layer's points enter the scene unchanged (positions to 1e-9 um, volumes summing to
    the file's); no sphere or fillet point (of either side) is seeded inside a layer point's
    cube; and with
    ``contact.initial = "fillet"`` each sphere resting on the layer owns points outside its own
    ball within 2 rho of the layer (the closing of sphere and cubes), which a case of touching
    contacts does not."""
    x = _slab(tmp_path / "layer.npz")
    case = _case(tmp_path / "layer.npz")
    sc = build_scene(case)
    layer = read_layer(str(tmp_path / "layer.npz"))
    mine = sc.body < 2
    rows = np.round(sc.x[mine] * 1e6, 9).view("f8,f8,f8").ravel()
    placed = np.isin(rows, np.round(x, 9).view("f8,f8,f8").ravel())
    assert placed.sum() == len(x)  # the rest of the layer bodies' points: their fillet share
    assert sc.vol[mine][placed].sum() * 1e18 == pytest.approx(layer.volume.sum(), rel=1e-12)
    seeded = np.concatenate([sc.x[~mine], sc.x[mine][~placed]]) * 1e6
    d, _ = cKDTree(x).query(seeded, p=np.inf)
    assert d.min() > 0.5 * SIDE - 1e-9

    def bridged(scene, c):
        """Sphere points outside their ball within 2 rho of the layer's cubes."""
        spheres = c.bodies[2:]
        own = scene.body >= 2
        p = scene.x[own] * 1e6
        centre = np.array([spheres[k - 2].center_um for k in scene.body[own]])
        radius = np.array([spheres[k - 2].radius_um for k in scene.body[own]])
        outside = np.linalg.norm(p - centre, axis=1) > radius
        to_layer, _ = cKDTree(x).query(p, p=np.inf)
        return int((outside & (to_layer <= 2 * c.contact.fillet_radius_um + SIDE)).sum())

    assert bridged(sc, case) > 0
    plain = _case(tmp_path / "layer.npz")
    plain.contact.initial = "point"
    assert bridged(build_scene(plain), plain) == 0


@pytest.mark.parametrize("dim", [2, 3])
def test_a_layer_of_the_other_dimension_is_refused(tmp_path, dim):
    """A 3D layer under a 2D bed, and a 2D layer under a 3D bed: one line naming the key."""
    path = tmp_path / "layer.npz"
    if dim == 2:
        _slab(path)
    else:
        write_layer(
            path,
            x_um=np.array([[1.0, 1.0], [3.0, 1.0]]),
            volume=np.full(2, SIDE**2),
            body=np.zeros(2, dtype=int),
            material=np.zeros(2, dtype=int),
            material_names=["PA12"],
            T_C=np.full(2, 172.0),
            info={},
        )
    with pytest.raises(CaseError) as err:
        _case(path, dim=dim)
    msg = str(err.value)
    assert msg.startswith("bed.previous_layer =") and "\n" not in msg
    assert f"a {5 - dim}D layer" in msg and f"domain.dim = {dim}" in msg


def test_bundled_3d_second_layer_loads_and_round_trips(tmp_path):
    """cases/machine_layer2_3d.toml: machine_layer3d's layer at the end of its layer time
    (bundled layers/machine_layer3d.npz, 3D, carried with its solid fraction: most of the thin
    layer is still melt at 172 C) under 48 new spheres that reach above it; the resolved case
    (the layer's bodies listed as points bodies) loads back to the same bodies."""
    from taichi_sls.config import bundled_case, case_to_toml, load_case
    from taichi_sls.config.loading import bundled_root

    case = load_case(bundled_case("machine_layer2_3d"))
    shapes = [b.shape for b in case.bodies]
    n_below = shapes.count("points")
    assert n_below > 0 and shapes.count("disc") == 48
    below_top = max(b.extent()[1][1] for b in case.bodies[:n_below])
    new_top = max(b.extent()[1][1] for b in case.bodies[n_below:])
    assert new_top > below_top + 10.0  # at least half a sphere higher
    layer = read_layer(bundled_root() / "layers" / "machine_layer3d.npz")
    assert layer.dim == 3 and layer.state is not None
    assert np.mean(np.asarray(layer.state["solid_fraction"]) < 0.5) > 0.5  # mostly melt
    path = tmp_path / "case.toml"
    path.write_text(case_to_toml(case))
    again = load_case(path)
    assert [b.model_dump() for b in again.bodies] == [b.model_dump() for b in case.bodies]
