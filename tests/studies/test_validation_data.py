"""The measured PA12 data of the package: the files load with their columns and units, and
every point names its source (taichi_sls/data/pa12/README.md)."""

import shutil

import pytest

from taichi_sls.studies.validation.measured import (
    MeasuredDataError,
    data_folder,
    load_densities,
    load_hot_stage,
    load_pulse_neck,
    load_pulse_temperature,
)


def test_data_shipped_with_readme_and_sources():
    folder = data_folder()
    for name in (
        "README.md",
        "sources.toml",
        "pulse_pair_R125_neck.csv",
        "pulse_pair_R125_temperature.csv",
        "hot_stage_pairs.csv",
        "part_and_powder_density.csv",
    ):
        assert (folder / name).is_file(), name
    readme = (folder / "README.md").read_text()
    assert "digitised" in readme and "Hejmady" in readme and "Westphal" in readme


def test_pulse_pair_neck():
    points = load_pulse_neck()
    assert len(points) == 13
    assert points[0].t_s == pytest.approx(0.0258) and points[0].neck_over_radius == 0.1954
    assert points[-1].t_s == pytest.approx(0.9682) and points[-1].neck_over_radius == 0.7140
    assert all(p.radius_um == 125.0 for p in points)
    assert all(0.0 < p.neck_over_radius < 2 ** (1 / 3) for p in points)
    assert all("Hejmady" in p.source and p.digitised for p in points)


def test_pulse_pair_temperature():
    points = load_pulse_temperature()
    assert points[0].t_s == 0.0 and points[0].T_C == 155.0
    assert max(p.T_C for p in points) == pytest.approx(211.19)  # C, not K
    assert all(150.0 < p.T_C < 215.0 for p in points)
    assert all("Hejmady" in p.source and "thermal imaging" in p.source for p in points)


def test_hot_stage_pairs():
    series = load_hot_stage()
    assert len(series) == 11
    radii = sorted(s[0].radius_um for s in series.values())
    assert radii[0] == 25.84 and radii[-1] == 37.90  # um
    assert "Zhao" in series["Zhao"][0].source
    assert all("Twente" in p.source for name, s in series.items() if name != "Zhao" for p in s)
    for s in series.values():  # each ends near one sphere, 2^(1/3) = 1.26
        assert s[0].t_s < 0.2 and 1.0 < s[-1].neck_over_radius < 1.35


def test_densities():
    records = load_densities()
    assert len(records) == 13
    assert all(r.source for r in records)
    units = {r.unit for r in records}
    assert units == {"g/cm3", "%", "kg/m3"}
    spread = next(r for r in records if r.quantity == "powder density as spread")
    assert (spread.value, spread.unit) == (463.0, "kg/m3")


def _copy(tmp_path):
    folder = tmp_path / "pa12"
    shutil.copytree(data_folder(), folder)
    return folder


def test_bad_files_are_named(tmp_path):
    folder = _copy(tmp_path)
    path = folder / "pulse_pair_R125_neck.csv"
    path.write_text(path.read_text().replace("0.1310,", "0.0100,"))
    with pytest.raises(MeasuredDataError, match="increasing"):
        load_pulse_neck(folder)
    path = folder / "hot_stage_pairs.csv"
    path.write_text(path.read_text().replace("Zhao,", "Other,"))
    with pytest.raises(MeasuredDataError, match="'Other' has no source"):
        load_hot_stage(folder)
    path = folder / "pulse_pair_R125_temperature.csv"
    path.write_text(path.read_text().replace("211.19", "hot"))
    with pytest.raises(MeasuredDataError, match="T_C = 'hot'"):
        load_pulse_temperature(folder)
    sources = folder / "sources.toml"
    sources.write_text(sources.read_text().replace('["pulse_pair_R125_neck.csv"]', "[x]"))
    with pytest.raises(MeasuredDataError, match="no source"):
        _ = load_pulse_neck(folder)
