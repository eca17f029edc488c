"""What a user sees of a 3D run: the c = 1/2 surface (io/surface3d.py), the frames, the GIF
and the VTU files (points with three coordinates, the surface as triangles), kept on resume."""

import re

import imageio.v3 as iio
import meshio
import numpy as np
from helpers import deep_update, make_case

import taichi_sls as sls
from taichi_sls.io.frames import Frame2DPainter
from taichi_sls.io.frames3d import LIGHT, Frame3DPainter, View3D, shade, view_3d
from taichi_sls.io.painter import frame_painter
from taichi_sls.io.surface3d import colour_grid, surface
from taichi_sls.io.writer import OutputWriter
from taichi_sls.jobs.case_run import run_case


def _lattice_sphere(radius: float, spacing: float) -> np.ndarray:
    """The points a centre-seeded sphere gets: a lattice at half-spacing offsets, inside R."""
    n = int(radius / spacing) + 2
    axis = (np.arange(-n, n) + 0.5) * spacing
    p = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    return p[np.linalg.norm(p, axis=1) < radius]


def _edges_pair_up(tris: np.ndarray, n_verts: int) -> bool:
    """Closed and turned one way: each directed edge once, and its reverse in a neighbour."""
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    key, back = e[:, 0] * n_verts + e[:, 1], e[:, 1] * n_verts + e[:, 0]
    return len(np.unique(key)) == len(key) and bool(np.isin(back, key).all())


def test_sphere_surface_is_closed_outward_and_has_the_sphere_area():
    """A sphere of radius 10 um seeded at 1 um: area within 4 % of 4 pi R^2 (marching
    tetrahedra's facets overestimate a smooth surface's area: measured +2.1 %), enclosed
    volume within 1 % of 4/3 pi R^3 (measured -0.5 %), outward normals (positive volume)."""
    R = 10.0
    x = _lattice_sphere(R, 1.0)
    grid = colour_grid(x, {"T_C": np.full(len(x), 150.0)}, 1.0, ((-R, R),) * 3)
    s = surface(grid)
    assert _edges_pair_up(s.tris, len(s.verts))
    area = s.areas().sum()
    assert abs(area / (4 * np.pi * R**2) - 1.0) < 0.04
    v = s.verts[s.tris]
    volume = np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6.0
    assert abs(volume / (4.0 / 3.0 * np.pi * R**3) - 1.0) < 0.01
    # a uniform field reads the same on the surface; the normals point away from the centre
    assert np.allclose(s.values["T_C"], 150.0)
    centres = v.mean(axis=1)
    assert ((s.normals() * centres).sum(axis=1) >= -1e-9).mean() > 0.99
    # the lit side is the one facing the light
    lit = shade(s.normals())
    assert lit[s.normals() @ LIGHT > 0.9].min() > lit[s.normals() @ LIGHT < 0.0].max()


def _pvd_files(path) -> list[str]:
    return re.findall(r'file="([^"]+)"', path.read_text())


def test_3d_run_writes_frames_gif_and_vtu_and_resume_keeps_them(tmp_path):
    """cases/sphere3d_heat.toml, 20 us: one frame, checkpointed, then resumed to a second;
    the folder then holds frames 0..2, a GIF of them, and collections listing all three."""
    out = tmp_path / "run"
    keys = ["output.vtu=true", "output.dpi=50"]
    first = sls.load_case("sphere3d_heat", ["time.end_s=1e-5", "output.frames=1", *keys])
    run_case(first, out, progress=False, checkpoint_every=1)
    case = sls.load_case("sphere3d_heat", ["time.end_s=2e-5", "output.frames=2", *keys])
    s = run_case(case, out, progress=False, resume=out / "checkpoint.npz")
    assert s["status"] == "complete"
    frames = sorted((out / "frames").glob("frame_*.png"))
    assert [p.name for p in frames] == [f"frame_{i:04d}.png" for i in range(3)]
    im = iio.imread(frames[-1])[..., :3]
    assert im.std() > 10  # not blank
    assert iio.imread(out / "animation.gif").shape[0] == 3
    assert iio.imread(out / "outcome.png")[..., :3].std() > 10  # from the mid-depth layer
    for name in ("points", "surface"):
        assert _pvd_files(out / f"{name}.pvd") == [f"vtu/{name}_{i:04d}.vtu" for i in range(3)]
    pts = meshio.read(out / "vtu" / "points_0002.vtu")
    assert pts.points.shape == (552, 3)
    assert np.ptp(pts.points[:, 2]) > 15.0  # a sphere of 20 um diameter, not a plane
    pd = pts.point_data
    for name in ("T_C", "liquid_fraction", "body_id", "von_mises_Pa", "J", "stress_yz_Pa"):
        assert len(pd[name]) == 552 and np.isfinite(pd[name]).all(), name
    assert pd["velocity_m_s"].shape == (552, 3) and pd["displacement_um"].shape == (552, 3)
    surf = meshio.read(out / "vtu" / "surface_0002.vtu")
    tris = surf.get_cells_type("triangle")
    assert len(tris) > 500 and _edges_pair_up(tris, len(surf.points))
    T = surf.point_data["T_C"]
    assert 140.0 - 1e-6 <= T.min() and T.max() <= 200.0 + 1e-6  # between the plate and the melt
    assert set(surf.point_data) == {"T_C", "liquid_fraction"}


def test_section_is_at_the_track_of_a_laser_along_x_else_mid_depth():
    sphere = {
        "domain": {"dim": 3, "width_um": 40.0, "height_um": 40.0, "depth_um": 32.0},
        "bodies": [{"shape": "disc", "center_um": [20.0, 20.0, 16.0], "radius_um": 10.0}],
        "physics": {"surface_tension": False},
    }
    assert view_3d(make_case(sphere)).section_z_um == 16.0
    along_x = {"lasers": [{"power_W": 1.0, "z_start_um": 10.0}]}
    assert view_3d(make_case(deep_update(sphere, along_x))).section_z_um == 10.0
    v = view_3d(make_case(deep_update(sphere, {"grid": {"spacing_um": 4.0}})))
    assert v.point_spacing_um == 2.0  # 2 points per cell
    assert v.z_range_um[1] - v.z_range_um[0] > 32.0  # the ghost layer in z as in x


def test_the_frame_painter_is_picked_by_the_case_dimension():
    """io/painter.frame_painter: a 3D case gets the 3D frames at its view, a 2D case the 2D
    frames with its deformation and dpi; both over the domain and its ghost layer, to the top."""
    sphere = {
        "domain": {"dim": 3, "width_um": 40.0, "height_um": 40.0, "depth_um": 32.0},
        "bodies": [{"shape": "disc", "center_um": [20.0, 20.0, 16.0], "radius_um": 10.0}],
        "physics": {"surface_tension": False},
    }
    p3 = frame_painter(make_case(sphere), bed=True)
    assert isinstance(p3, Frame3DPainter) and p3.dim == 3
    assert p3.view == view_3d(make_case(sphere)) and p3.domain_um == (-2.0, 42.0, -2.0, 40.0)
    disc = {
        "domain": {"width_um": 40.0, "height_um": 30.0},
        "bodies": [{"shape": "disc", "center_um": [20.0, 15.0], "radius_um": 8.0}],
        "output": {"deformation": "plastic_strain", "dpi": 50},
    }
    p2 = frame_painter(make_case(disc))
    assert isinstance(p2, Frame2DPainter) and p2.dim == 2
    assert (p2.deformation, p2.dpi, p2.domain_um) == (
        "plastic_strain",
        50,
        (-2.0, 42.0, -2.0, 30.0),
    )


def test_3d_frames_of_no_point_one_point_and_flung_points_are_written(tmp_path):
    """A failed run's last frame may hold points flung off the grid or NaN: left out of the
    colour grid, the frame and the VTU are still written (the points VTU keeps them all)."""
    painter = Frame3DPainter((0, 20, 0, 20), View3D((0, 20), 1, 10), 175.0)
    w = OutputWriter(tmp_path, painter=painter, vtu=True)
    states = [
        np.zeros((0, 3)),
        np.array([[5.0, 5.0, 5.0]]),
        np.array([[np.nan, 5.0, 5.0], [1e30, 0.0, 0.0], [5.0, 5.0, 5.0]]),
    ]
    for i, x in enumerate(states):
        w.frame(i, 0.0, x, np.full(len(x), 150.0), np.zeros(len(x)), np.zeros(len(x)))
    w.finish()
    assert len(list((tmp_path / "frames").glob("frame_*.png"))) == 3
    assert meshio.read(tmp_path / "vtu" / "points_0002.vtu").points.shape == (3, 3)
    assert (tmp_path / "animation.gif").is_file()
