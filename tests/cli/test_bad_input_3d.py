"""3D bad inputs at the command line (issue #39 item 12): each ends ``taichi-sls run`` with one
line naming the key and a non-zero exit status (2: refused before any work), never a
traceback. What config/dim.py and config/symmetry.py refuse is checked in depth in
tests/config/test_dim.py and tests/physics/test_mirror.py; here the user's path through the
command line."""

import pytest
from helpers import run_command

from taichi_sls.cli import main

SPHERE_3D = """
[domain]
dim = 3
width_um = 40.0
height_um = 40.0
depth_um = 32.0
[physics]
surface_tension = {tension}
{extra}
[[bodies]]
shape = "{shape}"
{body}
"""
CENTRE = "center_um = [20.0, 20.0, 16.0]\nradius_um = 10.0"
PAIR_2D = """
[domain]
width_um = 80.0
height_um = 48.0
{extra}
[[bodies]]
center_um = {centre}
radius_um = 20.0
"""


def sphere(extra: str = "", body: str = CENTRE, shape: str = "disc", tension: str = "false"):
    return SPHERE_3D.format(extra=extra, body=body, shape=shape, tension=tension)


BAD = [
    (
        "polygon",
        sphere(body="vertices_um = [[0, 0], [10, 0], [0, 10]]", shape="polygon"),
        'bodies[0].shape = "polygon"',
    ),
    ("csf", sphere('[surface_tension]\nmethod = "csf"', tension="true"), "surface_tension.method"),
    ("area_seeding_2d_only", sphere('[grid]\nseeding = "area"'), 'grid.seeding = "area"'),
    (
        "sphere_outside",
        sphere(body="center_um = [20.0, 20.0, 28.0]\nradius_um = 10.0"),
        "bodies[0]: extent",
    ),
    (
        "two_coordinates_in_3d",
        sphere(body="center_um = [20.0, 20.0]\nradius_um = 10.0"),
        "bodies[0].center_um",
    ),
    ("three_coordinates_in_2d", PAIR_2D.format(extra="", centre="[20, 20, 5]"), "center_um"),
    (
        "row_blocks_in_2d",
        PAIR_2D.format(
            extra='[time]\nintegrator = "implicit"\nimplicit_rows = "blocks"', centre="[20, 20]"
        ),
        'time.implicit_rows = "blocks"',
    ),
    (
        "front_wall_in_2d",
        PAIR_2D.format(extra='[boundary.front]\nthermal = "fixed"', centre="[20, 20]"),
        "boundary.front",
    ),
    (
        "mirror_fixed_temperature",
        sphere('[boundary.back]\nmechanical = "mirror"\nthermal = "fixed"'),
        'boundary.back.thermal = "fixed"',
    ),
    (
        "mirror_sphere_off_plane",
        sphere(
            '[boundary.back]\nmechanical = "mirror"',
            body="center_um = [20.0, 20.0, 30.0]\nradius_um = 10.0",
        ),
        "bodies[0]: crosses the mirror boundary.back",
    ),
    (
        "mirror_beam_off_plane",
        sphere(
            '[boundary.back]\nmechanical = "mirror"\n[[lasers]]\nx_start_um = 20.0\n'
            "z_start_um = 16.0",
            body="center_um = [20.0, 20.0, 22.0]\nradius_um = 10.0",
        ),
        "lasers[0].z_start_um = 16.0",
    ),
    (
        "mirror_with_musl",
        sphere('[boundary.right]\nmechanical = "mirror"\n[solver]\nupdate = "musl"'),
        'solver.update = "musl"',
    ),
    (
        "mirror_unknown_kind",
        sphere('[boundary.right]\nmechanical = "mirrored"'),
        "boundary.right.mechanical",
    ),
]


@pytest.mark.parametrize("text, says", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_a_bad_3d_input_ends_with_one_line(tmp_path, capsys, text, says):
    p = tmp_path / "bad.toml"
    p.write_text(text)
    code = main(["run", str(p), "--out", str(tmp_path / "o"), "--no-progress"])
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert code == 2, captured.err
    assert len(lines) == 1 and lines[0].startswith("error: ") and says in lines[0], lines
    assert "Traceback" not in captured.err
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").iterdir())


def test_the_command_itself_exits_2_on_a_sphere_outside_the_domain(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text(sphere(body="center_um = [20.0, 20.0, 28.0]\nradius_um = 10.0"))
    r = run_command(["taichi_sls", "run"], p, tmp_path / "o")
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2, r.stderr
    assert len(lines) == 1 and "bodies[0]: extent" in lines[0] and "z 18.0..38.0" in lines[0]
