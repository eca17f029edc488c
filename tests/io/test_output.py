"""Tests for taichi_sls.output: files written, readable, atomic, and robust to odd input."""

from __future__ import annotations

import csv
import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import imageio.v3 as iio
import meshio
import numpy as np
import pytest

from taichi_sls.io.atomic import atomic_write_bytes, atomic_write_text
from taichi_sls.io.frame_panels import frame_time_label
from taichi_sls.io.frames import (
    MATERIAL_LEVEL,
    Frame2DPainter,
    material_raster,
)
from taichi_sls.io.series import plot_series
from taichi_sls.io.vtu import VtuWriter, point_data, stress_invariants
from taichi_sls.io.writer import OutputWriter

DOMAIN = (0.0, 80.0, 0.0, 48.0)
MELT_C = 180.0


def two_discs(h: float = 1.0, r: float = 12.0) -> np.ndarray:
    """Points on an h-spaced lattice inside two touching discs (like two powder grains)."""
    g = np.arange(-r, r + h / 2, h)
    xx, yy = np.meshgrid(g, g)
    disc = np.column_stack([xx.ravel(), yy.ravel()])
    disc = disc[(disc**2).sum(axis=1) <= r * r]
    return np.vstack([disc + (40.0 - r, r), disc + (40.0 + r, r)])


def synthetic(step: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    x = two_discs()
    # Hot spot on top of the left disc, growing with step: part of it is above melt.
    T = 25.0 + (170.0 + 30.0 * step) * np.exp(-((x[:, 0] - 28.0) ** 2 + (x[:, 1] - 24.0) ** 2) / 60)
    lf = np.clip((T - MELT_C) / 5.0, 0.0, 1.0)
    u = 0.1 * step * np.hypot(x[:, 0] - 40.0, x[:, 1]) / 40.0
    return x, T, u, lf


def disc_painter() -> Frame2DPainter:
    """The 2D frames of the synthetic discs."""
    return Frame2DPainter(DOMAIN, MELT_C, "displacement")


@pytest.fixture
def writer(tmp_path: Path) -> OutputWriter:
    return OutputWriter(tmp_path / "run", painter=disc_painter(), vtu=True)


def test_full_run(writer: OutputWriter) -> None:
    out = writer.out_dir
    assert (out / "frames").is_dir()
    writer.write_case('[case]\nname = "two_discs"\n')
    for i in range(3):
        x, T, u, lf = synthetic(i)
        assert (T > MELT_C).any() and (T < MELT_C).any()
        writer.frame(i, i * 25e-6, x, T, u, lf)
        writer.row({"t_s": i * 25e-6, "contact_line_um": 2.0 + i, "T_max_C": float(T.max())})
    writer.summary({"ok": True, "neck_um": np.float32(3.5), "bad": float("nan"), "n": np.int64(3)})
    writer.finish()

    assert writer.frames_written == 3
    assert (out / "case.toml").read_text() == '[case]\nname = "two_discs"\n'

    for i in range(3):
        png = out / "frames" / f"frame_{i:04d}.png"
        assert png.stat().st_size < 200_000
        im = iio.imread(png)
        assert im.ndim == 3 and im.shape[2] in (3, 4)
        assert im.shape[1] > im.shape[0] > 150  # two panels side by side
        assert im[..., :3].std() > 10  # not blank

    gif = iio.imread(out / "animation.gif", index=None)
    assert gif.shape[0] == 3
    assert (out / "animation.gif").stat().st_size < 2_000_000

    with (out / "timeseries.csv").open(newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["t_s", "contact_line_um", "T_max_C"]
    assert len(rows) == 4
    assert float(rows[2][0]) == 25e-6  # round-trip precision
    assert iio.imread(out / "timeseries.png").ndim == 3

    summary = json.loads((out / "summary.json").read_text())
    assert summary == {"ok": True, "neck_um": 3.5, "bad": None, "n": 3}

    files = [d.get("file") for d in ET.parse(out / "points.pvd").iter("DataSet")]
    times = [float(d.get("timestep")) for d in ET.parse(out / "points.pvd").iter("DataSet")]
    assert files == [f"vtu/points_{i:04d}.vtu" for i in range(3)]
    assert times == [0.0, 25e-6, 50e-6]
    mesh = meshio.read(out / files[1])
    x, T, u, _ = synthetic(1)
    assert mesh.points.shape == (len(x), 3)
    np.testing.assert_allclose(mesh.point_data["T_C"], T)
    # without the solver's point data the drawn deformation is named for what it is
    assert set(mesh.point_data) == {"T_C", "liquid_fraction", "displacement_magnitude_um"}
    np.testing.assert_allclose(mesh.point_data["displacement_magnitude_um"], u)
    assert not list(out.rglob(".*.tmp"))


def test_atomic_write(tmp_path: Path) -> None:
    p = tmp_path / "a.txt"
    atomic_write_text(p, "old")
    atomic_write_text(p, "new content")
    assert p.read_text() == "new content"
    atomic_write_bytes(tmp_path / "b.bin", b"\x00\x01")
    assert (tmp_path / "b.bin").read_bytes() == b"\x00\x01"
    assert sorted(f.name for f in tmp_path.iterdir()) == ["a.txt", "b.bin"]


def test_atomic_write_failure_keeps_old(tmp_path: Path) -> None:
    p = tmp_path / "a.txt"
    atomic_write_text(p, "old")
    with pytest.raises(TypeError):
        atomic_write_bytes(p, "not bytes")  # type: ignore[arg-type]
    assert p.read_text() == "old"
    assert [f.name for f in tmp_path.iterdir()] == ["a.txt"]


@pytest.mark.parametrize(
    "x, T",
    [
        (np.array([[40.0, 10.0]]), np.array([300.0])),  # one point, molten
        (two_discs()[:2], np.array([25.0, 25.0])),  # two points
        (two_discs(), np.full(len(two_discs()), MELT_C)),  # all equal, exactly at melt
        (np.zeros((5, 2)), np.full(5, 200.0)),  # coincident points
        (np.zeros((0, 2)), np.zeros(0)),  # no points
        (two_discs(), np.full(len(two_discs()), np.nan)),  # all NaN
    ],
)
def test_degenerate_frames(tmp_path: Path, x: np.ndarray, T: np.ndarray) -> None:
    w = OutputWriter(
        tmp_path,
        painter=Frame2DPainter(DOMAIN, MELT_C, "plastic_strain"),
        vtu=True,
        deformation="plastic_strain",
    )
    lf = (T > MELT_C).astype(float)
    w.frame(0, 0.0, x, T, np.zeros(len(x)), lf)
    w.frame(1, 1e-6, x, T, np.zeros(len(x)), np.ones(len(x)))
    w.finish()
    assert iio.imread(tmp_path / "animation.gif", index=None).shape[0] == 2
    assert (tmp_path / "vtu" / "points_0001.vtu").is_file()
    if len(x):  # meshio cannot read back a zero-point VTU (its own writer's output)
        assert meshio.read(tmp_path / "vtu" / "points_0001.vtu").points.shape == (len(x), 3)


def test_mismatched_lengths_raise(writer: OutputWriter) -> None:
    x, T, u, lf = synthetic(0)
    with pytest.raises(ValueError, match="T_C"):
        writer.frame(0, 0.0, x, T[:-1], u, lf)


def test_bad_deformation(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="deformation"):
        OutputWriter(tmp_path, painter=disc_painter(), deformation="strain")
    with pytest.raises(ValueError, match="deformation"):
        Frame2DPainter(DOMAIN, MELT_C, "strain")


def test_finish_without_rows_or_frames(tmp_path: Path) -> None:
    w = OutputWriter(tmp_path, painter=disc_painter())
    w.finish()  # nothing written: must not raise
    w.row({"t_s": 0.0, "T_max_C": 25.0})
    w.finish()  # one row: plot skipped
    assert not (tmp_path / "timeseries.png").exists()
    assert not (tmp_path / "animation.gif").exists()


def test_row_columns_and_values(tmp_path: Path) -> None:
    w = OutputWriter(tmp_path, painter=disc_painter())
    w.row({"t_s": 0.1, "a": 1, "b": float("inf")})
    w.row({"b": math.pi, "t_s": 0.2, "c": np.float32(0.5)})  # new key appended, order fixed
    with (tmp_path / "timeseries.csv").open(newline="") as f:
        rows = list(csv.reader(f))
    assert rows == [
        ["t_s", "a", "b", "c"],
        ["0.1", "1", "inf", ""],
        ["0.2", "", repr(math.pi), "0.5"],
    ]


def test_plot_series_missing_column(tmp_path: Path) -> None:
    w = OutputWriter(tmp_path, painter=disc_painter())
    for i in range(4):
        w.row({"t_s": i * 1e-6, "contact_line_um": float(i)})
    png = tmp_path / "p.png"
    assert plot_series(tmp_path / "timeseries.csv", png, ["contact_line_um", "T_max_C"])
    assert iio.imread(png).ndim == 3
    assert not plot_series(tmp_path / "timeseries.csv", png, ["missing"])


def test_gif_size_limit(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from taichi_sls.io import gif as output

    w = OutputWriter(tmp_path, painter=Frame2DPainter(DOMAIN, MELT_C, "displacement", dpi=40))
    for i in range(12):
        x, T, u, lf = synthetic(i % 4)
        w.frame(i, i * 1e-6, x + (i % 7, 0.0), T, u, lf)
    monkeypatch.setattr(output, "GIF_MAX_BYTES", 60_000)
    monkeypatch.setattr(output, "_GIF_BUDGET", 54_000)
    monkeypatch.setattr(output, "_GIF_MIN_FRAMES", 4)
    w.finish()
    gif = tmp_path / "animation.gif"
    assert gif.stat().st_size <= 60_000
    assert 2 <= iio.imread(gif, index=None).shape[0] < 12


def test_material_raster_closes_the_mid_plane_strip_and_keeps_the_outline() -> None:
    """Two coalescing bodies keep an empty strip along their symmetry line (their points two
    spacings apart across it): drawn as material it must not read as a crack, while a real gap
    stays open and the drawn area is the points' own."""
    d, pixel = 1.0, 0.25
    g = np.arange(0.0, 40.0) + 0.5
    xx, yy = np.meshgrid(g, g)
    block = np.column_stack([xx.ravel(), yy.ravel()])  # a 40 x 40 um square of points
    shape = (200, 240)  # 50 x 60 um of pixels from the corner (-5, -5)

    def fraction(gap: int) -> np.ndarray:
        """The raster of the block with ``gap`` columns emptied at x = 20 um."""
        keep = np.abs(block[:, 0] - 20.5) >= gap / 2
        f, (u,) = material_raster(block[keep], [block[keep, 0]], d, (-5.0, -5.0), shape, pixel)
        assert np.nanmax(u[f >= MATERIAL_LEVEL]) <= 40.0  # values are means of the points'
        return f

    row = (20.0 + 5.0) / pixel  # the pixel row across the middle of the block
    f = fraction(1)  # points 2 spacings apart across the strip
    assert f[int(row), int((20.5 + 5.0) / pixel)] >= MATERIAL_LEVEL
    middle = f[:, int((20.5 + 5.0) / pixel)]
    # no dash along the 40 um of the strip; only its ends, at the free surface, notch by ~d
    assert (middle >= MATERIAL_LEVEL).sum() * pixel >= 40.0 - 2 * d
    f = fraction(4)  # a real crack of 4 spacings stays open
    assert f[int(row), int((20.5 + 5.0) / pixel)] < MATERIAL_LEVEL
    # the outline of the full block on its true edge, half a spacing beyond the last points
    f = fraction(0)
    assert (f >= MATERIAL_LEVEL).sum() * pixel**2 == pytest.approx(40.0 * 40.0, rel=0.02)


def test_outcome_plot_fills_the_final_shape_under_the_initial_outline(tmp_path: Path) -> None:
    """outcome.png: the final material filled in one colour, each body's initial outline a line
    in another, so the two shapes can be told apart (pale dots of both could not)."""
    from matplotlib.colors import to_rgb

    from taichi_sls.io.outcome_plot import FINAL_COLOUR, INITIAL_COLOUR, plot_outcome

    (tmp_path / "timeseries.csv").write_text(
        "t_s,contact_line_um,molten_fraction\n0,8,0\n1e-5,10,0.5\n1e-3,12,0.9\n"
    )
    x = two_discs()
    body = (x[:, 0] > 40.0).astype(int)
    final = x + np.where(body == 0, 1.0, -1.0)[:, None] * [1.0, 0.0]  # the pair moved together
    path = plot_outcome(tmp_path, x * 1e-6, final * 1e-6, body)
    assert path is not None
    im = iio.imread(path)[..., :3].astype(int)
    for colour in (FINAL_COLOUR, INITIAL_COLOUR):
        rgb = np.round(np.array(to_rgb(colour)) * 255)
        assert (np.abs(im - rgb).sum(axis=-1) < 30).sum() > 200, colour


def solver_point_data(x: np.ndarray) -> dict[str, np.ndarray]:
    """Point data as a run hands it over: body by side, a velocity, a stress with every
    component distinct, plastic strain and J."""
    n = len(x)
    stress = np.zeros((n, 3, 3))
    stress[:, 0, 0], stress[:, 1, 1], stress[:, 2, 2] = -3e5, 1e5, 2e4
    stress[:, 0, 1] = stress[:, 1, 0] = 5e4 * np.arange(n) / n
    return point_data(
        body_id=(x[:, 0] > 40.0).astype(np.int64),
        velocity_m_s=np.column_stack([np.full(n, 0.25), -x[:, 1] * 1e-3]),
        displacement_um=np.column_stack([x[:, 0] * 1e-2, np.zeros(n)]),
        stress_Pa=stress,
        equivalent_plastic_strain=np.linspace(0.0, 0.1, n),
        J=np.full(n, 0.98),
    )


VTU_FIELDS = {  # name: components in the file
    "T_C": 1,
    "liquid_fraction": 1,
    "body_id": 1,
    "velocity_m_s": 3,
    "displacement_um": 3,
    "stress_xx_Pa": 1,
    "stress_yy_Pa": 1,
    "stress_zz_Pa": 1,
    "stress_xy_Pa": 1,
    "von_mises_Pa": 1,
    "pressure_Pa": 1,
    "equivalent_plastic_strain": 1,
    "J": 1,
}


def test_vtu_point_data_is_complete_and_valid(tmp_path: Path) -> None:
    x, T, u, lf = synthetic(1)
    extra = solver_point_data(x)
    w = OutputWriter(tmp_path, painter=disc_painter(), png=False, gif=False, vtu=True)
    w.frame(0, 0.0, x, T, u, lf, extra)
    path = tmp_path / "vtu" / "points_0000.vtu"

    # the XML as ParaView reads it: one Piece of N points; every point array named once, with
    # its components declared and its type (body_id an integer)
    root = ET.parse(path).getroot()
    assert root.get("type") == "UnstructuredGrid"
    piece = root.find("UnstructuredGrid/Piece")
    assert piece is not None and int(piece.get("NumberOfPoints")) == len(x)
    arrays = {a.get("Name"): a for a in piece.find("PointData").iter("DataArray")}
    assert set(arrays) == set(VTU_FIELDS)
    for name, k in VTU_FIELDS.items():
        assert int(arrays[name].get("NumberOfComponents", "1")) == k, name
    assert arrays["body_id"].get("type").startswith("Int")
    assert arrays["von_mises_Pa"].get("type") == "Float64"

    # every array holds one tuple per point, with the values given
    mesh = meshio.read(path)
    for name, k in VTU_FIELDS.items():
        v = mesh.point_data[name]
        assert v.shape == ((len(x),) if k == 1 else (len(x), k)), name
    np.testing.assert_array_equal(mesh.point_data["body_id"], (x[:, 0] > 40.0).astype(int))
    np.testing.assert_allclose(mesh.point_data["velocity_m_s"][:, 1], -x[:, 1] * 1e-3)
    assert not mesh.point_data["velocity_m_s"][:, 2].any()  # in plane: z = 0
    np.testing.assert_allclose(mesh.point_data["stress_xy_Pa"], extra["stress_xy_Pa"])
    np.testing.assert_allclose(mesh.point_data["stress_zz_Pa"], 2e4)
    np.testing.assert_allclose(mesh.point_data["pressure_Pa"], (3e5 - 1e5 - 2e4) / 3)
    np.testing.assert_allclose(mesh.point_data["J"], 0.98)


def test_stress_invariants_of_known_states() -> None:
    s = 2e5
    states = np.zeros((4, 3, 3))
    states[0, 0, 0] = s  # uniaxial tension
    states[1] = -s * np.eye(3)  # hydrostatic compression
    states[2, 0, 1] = states[2, 1, 0] = s  # pure shear
    states[3] = np.diag([s, s, 0.0])  # equibiaxial
    vm, p = stress_invariants(states)
    np.testing.assert_allclose(vm, [s, 0.0, np.sqrt(3.0) * s, s], atol=1e-9 * s)
    np.testing.assert_allclose(p, [-s / 3, s, 0.0, -2 * s / 3], atol=1e-9 * s)


def test_point_data_of_no_points(tmp_path: Path) -> None:
    """A frame with no point left (all flown off the grid) still writes every field."""
    data = solver_point_data(np.zeros((0, 2)))
    assert set(data) == set(VTU_FIELDS) - {"T_C", "liquid_fraction"}
    assert data["velocity_m_s"].shape == (0, 3) and data["von_mises_Pa"].shape == (0,)
    w = OutputWriter(tmp_path, painter=disc_painter(), png=False, gif=False, vtu=True)
    w.frame(0, 0.0, np.zeros((0, 2)), np.zeros(0), np.zeros(0), np.zeros(0), data)
    names = {
        a.get("Name") for a in ET.parse(tmp_path / "vtu" / "points_0000.vtu").iter("DataArray")
    }
    assert set(VTU_FIELDS) <= names


def test_vtu_refuses_an_array_of_the_wrong_length(tmp_path: Path) -> None:
    x = two_discs()
    with pytest.raises(ValueError, match="J has 3 tuples"):
        VtuWriter(tmp_path).write(0, 0.0, x, {"T_C": np.zeros(len(x)), "J": np.ones(3)})
    assert not (tmp_path / "vtu" / "points_0000.vtu").exists()


@pytest.mark.parametrize(
    ("t_s", "label"),
    [(0.0, "t = 0.0 us"), (2.5e-4, "t = 250.0 us"), (5.623e-3, "t = 5.623 ms"), (10.0, "t = 10 s")],
)
def test_frame_titles_read_in_the_unit_of_their_time(t_s: float, label: str) -> None:
    """A frame of a pulse reads in us, a layer time's in ms or s (not 10000000.0 us)."""
    assert frame_time_label(t_s) == label
