"""A bed deposited on a previous layer (``bed.previous_layer``): a layer file's bodies become
``points`` bodies, the new discs land on its points, and each bad layer file or mismatch ends in
one line naming the key (numpy only, no simulation)."""

import numpy as np
import pytest

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


def test_new_discs_rest_on_the_layer_points(tmp_path):
    """The layer's bodies come first, as points bodies at the bed temperature, then the discs;
    no disc overlaps a layer point's disc (half its spacing) by more than round-off, each rests
    on a layer point, another disc or the plate, and the domain holds the new top."""
    x = _slab(tmp_path / "layer.npz")
    case = _case(tmp_path / "layer.npz")
    shapes = [b.shape for b in case.bodies]
    assert shapes == ["points"] * 3 + ["disc"] * 6
    assert all(b.temperature_C is None for b in case.bodies[:3])  # thermal.initial_C
    discs = np.array([[*b.center_um, b.radius_um] for b in case.bodies[3:]])
    gap = np.hypot(*(discs[:, None, :2] - x[None]).transpose(2, 0, 1)) - discs[:, 2:3] - 1.0
    assert gap.min() > -1e-6
    d = np.hypot(*(discs[:, None, :2] - discs[None, :, :2]).transpose(2, 0, 1))
    pair_gap = d - discs[:, None, 2] - discs[None, :, 2] + np.diag(np.full(6, np.inf))
    rests = (gap.min(axis=1) < 1e-6) | (pair_gap.min(axis=1) < 1e-6)
    assert rests.all()
    assert case.domain.height_um >= (discs[:, 1] + discs[:, 2]).max()
    rep = case.bed_report
    assert rep["previous_layer_bodies"] == 3 and rep["previous_layer_points"] == len(x)
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
