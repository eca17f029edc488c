"""``domain.dim``: 2 by default and exactly as before, 3 allowed, anything else refused; the
coordinates' count checked against it; in 3D every feature not built refused by its key."""

import pytest
from helpers import PAPER_SCENE, deep_update

from taichi_sls.config import CaseError, case_from_dict, case_to_dict
from taichi_sls.solver.step_config import StepConfig

SPHERE = {
    "domain": {"dim": 3, "width_um": 40.0, "height_um": 40.0, "depth_um": 32.0},
    "bodies": [{"shape": "disc", "center_um": [20.0, 20.0, 16.0], "radius_um": 10.0}],
    "physics": {"surface_tension": False},
}


def _error(data: dict) -> str:
    with pytest.raises(CaseError) as err:
        case_from_dict(data)
    msg = str(err.value)
    assert "\n" not in msg  # one line
    return msg


def test_dim_defaults_to_2_and_3_loads():
    assert case_from_dict(PAPER_SCENE).domain.dim == 2
    case = case_from_dict(SPHERE)
    assert case.domain.dim == 3 and case.domain_um() == (40.0, 40.0, 32.0)
    assert case.boundary.walls(3)[4:] == (case.boundary.front, case.boundary.back)
    # the 2D output defaults hold in 3D (frames and GIF on, VTU off), and its dict loads back
    assert case.output.png and case.output.gif and not case.output.vtu
    assert case_from_dict(case_to_dict(case)).domain_um() == (40.0, 40.0, 32.0)
    # without depth_um the box is as deep as it is wide
    no_depth = deep_update(SPHERE, {"domain": {"depth_um": None}})
    del no_depth["domain"]["depth_um"]
    assert case_from_dict(no_depth).domain_um() == (40.0, 40.0, 40.0)


def test_step_config_carries_dim():
    assert "dim" in StepConfig.__dataclass_fields__


@pytest.mark.parametrize("value", [1, 4, 2.0, "3"])
def test_other_dims_are_refused(value):
    msg = _error(deep_update(PAPER_SCENE, {"domain": {"dim": value}}))
    assert msg.startswith(f"domain.dim = {value!r}:")
    assert "2, 3" in msg or "expected an integer" in msg


def test_coordinates_match_the_dimension():
    three_in_2d = deep_update(PAPER_SCENE, {"bodies": [{"center_um": [20.0, 20.0, 5.0]}]})
    assert _error(three_in_2d).startswith("bodies[0].center_um = [20.0, 20.0, 5.0]: 3 coordinates")
    two_in_3d = deep_update(SPHERE, {"bodies": [{"center_um": [20.0, 20.0]}]})
    assert "2 coordinates with domain.dim = 3; allowed: [x, y, z]" in _error(two_in_3d)
    box = deep_update(
        SPHERE, {"bodies": [{"shape": "rect", "min_um": [0, 0, 0], "max_um": [5, 5]}]}
    )
    assert _error(box).startswith("bodies[0].max_um = [5.0, 5.0]: 2 coordinates")
    four = deep_update(PAPER_SCENE, {"bodies": [{"center_um": [1.0, 2.0, 3.0, 4.0]}]})
    assert "expected [x, y] (2D) or [x, y, z] (3D)" in _error(four)
    g = deep_update(PAPER_SCENE, {"physics": {"gravity_m_s2": [0.0, -9.81, 0.0]}})
    assert _error(g).startswith("physics.gravity_m_s2 = [0.0, -9.81, 0.0]: 3 components")
    # a velocity or gravity may leave z out in 3D; a box must fit the depth too
    ok = deep_update(SPHERE, {"physics": {"gravity_m_s2": [0.0, -9.81]}})
    assert case_from_dict(ok).physics.gravity_m_s2 == [0.0, -9.81]
    deep = deep_update(SPHERE, {"bodies": [{"center_um": [20.0, 20.0, 25.0], "radius_um": 10.0}]})
    assert "z 15.0..35.0 um lies outside the domain 0..40.0 x 0..40.0 x 0..32.0 um" in _error(deep)


def test_surface_energy_loads_in_3d():
    """The surface-energy force runs in 3D (marching tetrahedra); only the CSF is refused."""
    case = case_from_dict(deep_update(SPHERE, {"physics": {"surface_tension": True}}))
    assert case.physics.surface_tension and case.surface_tension.method == "surface_energy"


def test_3d_keys_are_refused_in_2d():
    front = deep_update(PAPER_SCENE, {"boundary": {"front": {"thermal": "fixed"}}})
    assert _error(front).startswith("boundary.front: a wall in z, 3D only")
    depth = deep_update(PAPER_SCENE, {"domain": {"depth_um": 10.0}})
    assert _error(depth).startswith("domain.depth_um = 10.0: 3D only")


REFUSED_IN_3D = [
    (
        {"physics": {"surface_tension": True}, "surface_tension": {"method": "csf"}},
        "the paper's level-set CSF is 2D only",
    ),
    (
        {"bodies": [{"shape": "polygon", "vertices_um": [[0, 0], [10, 0], [0, 10]]}]},
        'bodies[0].shape = "polygon"',
    ),
    ({"solver": {"layout": "blocks"}}, 'solver.layout = "blocks"'),
    ({"lasers": [{"scan": "across", "speed_m_s": 5.0}]}, 'lasers[0].scan = "across"'),
    ({"grid": {"seeding": "area"}}, 'grid.seeding = "area"'),
]


@pytest.mark.parametrize("extra, says", REFUSED_IN_3D, ids=[s for _, s in REFUSED_IN_3D])
def test_what_3d_lacks_is_refused_by_its_key(extra, says):
    msg = _error(deep_update(SPHERE, extra))
    assert says in msg and "domain.dim = 3" in msg and "allowed" in msg
    # and the same keys stay allowed in 2D (the bodies and the bed need their own scenes)
    if "bodies" not in extra:
        case_from_dict(deep_update(PAPER_SCENE, extra))


def test_the_laser_loads_in_3d_with_its_keys():
    """A beam with power runs in 3D: z_start_um defaults to the mid-depth (and is dumped), the
    tracks lie in the bed (scan = "along" with tracks > 1), each ends at its end key."""
    beam = {"power_W": 25.0, "speed_m_s": 2.0, "direction": "z", "z_start_um": 0.0}
    hatch = {**beam, "tracks": 3, "hatch_um": 10.0, "return_s": 1e-5, "z_end_um": 8.0}
    hatch["off_s"] = 1.0
    case = case_from_dict(deep_update(SPHERE, {"lasers": [hatch]}))
    windows = case.lasers[0].track_windows_along_s()
    flat = [e for window in windows for e in window]
    assert flat == pytest.approx([0.0, 4e-6, 1e-5, 1.4e-5, 2e-5, 2.4e-5], rel=1e-12)
    assert case.lasers_off_s() == pytest.approx(2.4e-5, rel=1e-12)
    plain = case_from_dict(deep_update(SPHERE, {"lasers": [{"power_W": 25.0}]}))
    assert plain.lasers[0].z_start_um == 16.0  # the mid-depth of 32 um
    assert case_from_dict(case_to_dict(plain)).lasers[0].z_start_um == 16.0


LASER_REFUSED = [
    (3, {"tracks": 2}, "lasers[0].return_s = None: 2 tracks need the time between their starts"),
    (3, {"direction": "z", "x_end_um": 5.0}, 'lasers[0].x_end_um = 5.0 with direction = "z"'),
    (3, {"z_end_um": 5.0}, 'lasers[0].z_end_um = 5.0 with direction = "x"'),
    (2, {"direction": "z"}, "lasers[0].direction = 'z': 3D only"),
    (2, {"z_start_um": 4.0}, "lasers[0].z_start_um = 4.0: 3D only"),
    (2, {"z_end_um": 4.0}, "lasers[0].z_end_um = 4.0: 3D only"),
    (2, {"tracks": 2}, 'lasers[0].tracks = 2: hatches need scan = "across"'),
    (2, {"surface": "local", "top_um": 30.0}, 'lasers[0].top_um = 30.0: surface = "local"'),
]


@pytest.mark.parametrize("dim, laser, says", LASER_REFUSED, ids=[s for *_, s in LASER_REFUSED])
def test_laser_keys_refused_by_dimension(dim, laser, says):
    scene = SPHERE if dim == 3 else PAPER_SCENE
    msg = _error(deep_update(scene, {"lasers": [{"power_W": 25.0, **laser}]}))
    assert msg.startswith(says) and "allowed" in msg
