"""A bed deposited on a previous layer (``bed.previous_layer``): a layer file's bodies become
``points`` bodies placed as they were, the new discs (spheres) land on its points (squares,
cubes), the fillet joins a sphere to a 3D layer, and each bad layer file or mismatch (a layer of
the other dimension among them) ends in one line naming the key (numpy only, no simulation)."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from taichi_sls.config import CaseError, bundled_case, case_from_dict, case_to_toml, load_case
from taichi_sls.config.layer_file import read_layer
from taichi_sls.io.layer_output import write_layer
from taichi_sls.solver.scene import build_scene

H_UM = 4.0  # grid of the cases below: points 2 um apart (2 x 2 per cell)


def _slab(path, width=120.0, height=30.0, spacing=2.0, bodies=3, material="PA12"):
    """A layer file of a flat slab of points (the top wavy, so that discs have valleys to sit
    in), cut into ``bodies`` vertical strips."""
    g = np.arange(spacing / 2, width, spacing)
    X, Y = np.meshgrid(g, np.arange(spacing / 2, height + 8.0, spacing), indexing="ij")
    keep = Y < height + 4.0 * np.sin(2 * np.pi * X / 40.0)
    x = np.stack([X[keep], Y[keep]], axis=1)
    body = np.minimum((x[:, 0] / width * bodies).astype(int), bodies - 1)
    write_layer(
        path,
        x_um=x,
        volume=np.full(len(x), spacing**2),
        body=body,
        material=np.zeros(len(x), dtype=int),
        material_names=[material],
        T_C=np.full(len(x), 150.0),
        info={"case": "slab"},
    )
    return x


def _case(path, **bed):
    return case_from_dict(
        {
            "grid": {"spacing_um": H_UM},
            "bed": {
                "previous_layer": str(path),
                "count": 6,
                "median_diameter_um": 30.0,
                "seed": 3,
                "x_range_um": [0.0, 120.0],
                **bed,
            },
            "contact": {"initial": "fillet"},
        }
    )


@pytest.mark.parametrize("dim", [2, 3])
def test_new_particles_rest_on_the_layer_points(tmp_path, dim):
    """The layer's bodies come first, as points bodies at the bed temperature, then the new
    discs (spheres); none overlaps a layer point's disc (sphere: radius half its spacing) by
    more than round-off, each rests on a layer point, another new particle or the plate, the
    domain holds the new top, and the report names the layer. 3D: every sphere rests on the
    8-12 um slab, none on the plate."""
    slab, case_of, below, n = (_slab, _case, 3, 6) if dim == 2 else (_slab3d, _case3d, 2, 5)
    x = slab(tmp_path / "layer.npz")
    case = case_of(tmp_path / "layer.npz")
    assert [b.shape for b in case.bodies] == ["points"] * below + ["disc"] * n
    assert all(b.temperature_C is None for b in case.bodies[:below])  # thermal.initial_C
    s = np.array([[*b.center_um, b.radius_um] for b in case.bodies[below:]])
    c, r = s[:, :dim], s[:, dim]
    gap = np.linalg.norm(c[:, None] - x[None], axis=2) - r[:, None] - 1.0  # points 2 um apart
    assert gap.min() > -1e-6
    pair = (
        np.linalg.norm(c[:, None] - c[None], axis=2) - r[:, None] - r + np.diag(np.full(n, np.inf))
    )
    assert ((gap.min(axis=1) < 1e-6) | (pair.min(axis=1) < 1e-6)).all()
    if dim == 3:
        assert (c[:, 1] - r).min() > 7.0  # on the slab, not the plate
    assert case.domain.height_um >= (c[:, 1] + r).max()
    rep = case.bed_report
    assert rep["previous_layer_bodies"] == below and rep["previous_layer_points"] == len(x)
    assert np.isnan(rep["envelope"])  # the layer below is not void


def test_the_scene_holds_the_layer_points_as_they_were(tmp_path):
    """The layer's points enter the scene unchanged (positions, volumes), and no disc or
    fillet point is seeded inside a layer point's cell."""
    x = _slab(tmp_path / "layer.npz")
    sc = build_scene(_case(tmp_path / "layer.npz"))
    layer = read_layer(str(tmp_path / "layer.npz"))
    mine = sc.body < 3
    placed = np.isin(np.round(sc.x[mine] * 1e6, 9).view("f8,f8"), np.round(x, 9).view("f8,f8"))
    assert placed.sum() == len(x)
    assert np.isclose(sc.vol[mine][placed.ravel()].sum() * 1e12, layer.volume.sum())
    from scipy.spatial import cKDTree

    d, _ = cKDTree(x).query(sc.x[~mine] * 1e6, p=np.inf)
    assert d.min() > 0.5 * H_UM / 2 - 1e-9


def test_a_layer_run_on_another_grid_is_refused(tmp_path):
    _slab(tmp_path / "layer.npz", spacing=1.0)
    with pytest.raises(CaseError, match=r"bed.previous_layer = .*1 um apart.*2 um apart"):
        _case(tmp_path / "layer.npz")


def test_a_layer_of_an_undefined_material_is_refused(tmp_path):
    _slab(tmp_path / "layer.npz", material="PEEK")
    with pytest.raises(CaseError, match=r"bed.previous_layer = .*'PEEK', not defined here"):
        _case(tmp_path / "layer.npz")


@pytest.mark.parametrize(
    "content, what",
    [
        (b"x_um,y_um,radius_um\n1,2,3\n", "not readable as a layer file"),
        ("npz without the arrays", "not a layer file \\(lacks"),
    ],
)
def test_a_file_that_is_not_a_layer_names_the_key(tmp_path, content, what):
    path = tmp_path / "layer.npz"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        np.savez(path, x_um=np.zeros((2, 2)))
    with pytest.raises(CaseError, match=rf"bed.previous_layer = .*layer.npz'?: {what}"):
        _case(path)


def test_a_points_body_of_a_missing_index_names_it(tmp_path):
    _slab(tmp_path / "layer.npz")
    with pytest.raises(
        CaseError, match=r"bodies\[0\].body = 7: the layer file .* has no such body"
    ):
        case_from_dict(
            {
                "domain": {"width_um": 120.0, "height_um": 60.0},
                "bodies": [{"shape": "points", "file": str(tmp_path / "layer.npz"), "body": 7}],
            }
        )


def test_bundled_second_layer_and_its_resolved_case_loads_back(tmp_path):
    """cases/bed_track_layer2.toml: bed_track's refrozen layer (its 62 bodies, from the bundled
    layer file) under about 60 new discs that reach above it; the resolved case (every body
    listed, the layer's as points bodies) loads back to the same bodies."""
    case = load_case(bundled_case("bed_track_layer2"))
    first = load_case(bundled_case("bed_track"))
    shapes = [b.shape for b in case.bodies]
    n_below = shapes.count("points")
    assert n_below == len(first.bodies) and 50 <= shapes.count("disc") <= 100
    below_top = max(b.extent()[1][1] for b in case.bodies[:n_below])
    new_top = max(b.extent()[1][1] for b in case.bodies[n_below:])
    assert new_top > below_top + 40.0  # at least a particle higher
    path = tmp_path / "case.toml"
    path.write_text(case_to_toml(case))
    again = load_case(path)
    assert [b.model_dump() for b in again.bodies] == [b.model_dump() for b in case.bodies]


def test_bundled_machine_second_layer_restarts_molten():
    """cases/machine_layer2.toml: machine_layer's layer at the end of its layer time, carried
    with its solid fraction (the 172 C melt has not crystallised), under a new layer of discs
    that reaches above it; the layer file's points restart partly molten."""
    import numpy as np

    from taichi_sls.config.layer_file import read_layer
    from taichi_sls.config.loading import bundled_root

    case = load_case(bundled_case("machine_layer2"))
    shapes = [b.shape for b in case.bodies]
    n_below = shapes.count("points")
    assert n_below > 0 and shapes.count("disc") >= 20
    below_top = max(b.extent()[1][1] for b in case.bodies[:n_below])
    new_top = max(b.extent()[1][1] for b in case.bodies[n_below:])
    assert new_top > below_top + 20.0
    layer = read_layer(bundled_root() / "layers" / "machine_layer.npz")
    solid = np.asarray(layer.state["solid_fraction"])
    assert 0.2 < np.mean(solid < 0.5) < 0.9  # a part of the layer is still melt


# --------------------------------------------------------------------------- 3D layers

SIDE = 2.0  # 3D: the layer's points 2 um apart (2 per cell along each axis)


def _slab3d(path, width=60.0, height=10.0, depth=60.0, bodies=2):
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


def _case3d(path, dim=3, **bed):
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


def test_the_3d_scene_holds_the_layer_and_bridges_to_it(tmp_path):
    """The layer's points enter the scene unchanged (positions to 1e-9 um, volumes summing to
    the file's); no sphere or fillet point (of either side) is seeded inside a layer point's
    cube; and with
    ``contact.initial = "fillet"`` each sphere resting on the layer owns points outside its own
    ball within 2 rho of the layer (the closing of sphere and cubes), which a case of touching
    contacts does not."""
    x = _slab3d(tmp_path / "layer.npz")
    case = _case3d(tmp_path / "layer.npz")
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
    plain = _case3d(tmp_path / "layer.npz")
    plain.contact.initial = "point"
    assert bridged(build_scene(plain), plain) == 0


@pytest.mark.parametrize("dim", [2, 3])
def test_a_layer_of_the_other_dimension_is_refused(tmp_path, dim):
    """A 3D layer under a 2D bed, and a 2D layer under a 3D bed: one line naming the key."""
    path = tmp_path / "layer.npz"
    if dim == 2:
        _slab3d(path)
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
        _case3d(path, dim=dim)
    msg = str(err.value)
    assert msg.startswith("bed.previous_layer =") and "\n" not in msg
    assert f"a {5 - dim}D layer" in msg and f"domain.dim = {dim}" in msg


def test_bundled_3d_second_layer_loads_and_round_trips(tmp_path):
    """cases/machine_layer2_3d.toml: machine_layer3d's layer at the end of its layer time
    (bundled layers/machine_layer3d.npz, 3D, carried with its solid fraction: most of the thin
    layer is still melt at 172 C) under 48 new spheres that reach above it; the resolved case
    (the layer's bodies listed as points bodies) loads back to the same bodies."""
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
