"""Bundled materials (config/presets.py): ``[materials.NAME] preset = "pa12_process"`` loads
every value of taichi_sls/materials/pa12_process.toml, the table of docs/record/pa12_process.md is
rendered from that file, and a bad name is one line."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from taichi_sls.config import CaseError, Material, case_to_toml, load_case
from taichi_sls.config.loading import case_from_dict
from taichi_sls.config.presets import preset_names, preset_table, read_preset

DOCS = Path(__file__).resolve().parents[2] / "docs" / "record" / "pa12_process.md"
PRESET = "pa12_process"
BEGIN, END = f"<!-- preset {PRESET} -->\n", f"<!-- /preset {PRESET} -->"


def _value_of(m: Material, key: str):
    node = m
    for part in key.split("."):
        node = getattr(node, part)
    return node


def test_the_preset_loads_every_value_of_its_file():
    """Each material entry of the file is the loaded material's value; the keys not in the
    file keep Table 3's defaults; every entry names a source."""
    case = load_case("power25W", [f"materials.PA12.preset={PRESET}"])
    m = case.materials["PA12"]
    entries = read_preset(PRESET)["material"]
    for key, entry in entries.items():
        assert _value_of(m, key) == entry["value"], key
        assert entry["source"].strip(), key
    assert m.preset == PRESET
    assert m.solvent_viscosity_Pa_s == Material().solvent_viscosity_Pa_s


def test_case_keys_override_the_preset_and_the_resolved_case_loads_back():
    case = load_case(
        "power25W",
        [f"materials.PA12.preset={PRESET}", "materials.PA12.crystallization_kinetics.n=2.0"],
    )
    m = case.materials["PA12"]
    assert m.crystallization_kinetics.n == 2.0
    assert (
        m.crystallization_kinetics.K_g_K2
        == read_preset(PRESET)["material"]["crystallization_kinetics.K_g_K2"]["value"]
    )
    import tomllib

    again = case_from_dict(tomllib.loads(case_to_toml(case)))
    assert again.materials["PA12"] == m


def test_the_paper_material_is_unchanged_without_a_preset():
    m = load_case("power25W").materials["PA12"]
    assert m.preset is None and m == Material()
    assert (m.viscosity_model, m.youngs_solid_Pa, m.surface_tension_N_m) == (
        "exponential",
        1e5,
        36.3e-3,
    )


def test_a_dumped_case_without_a_preset_loads_back():
    """model_dump keeps ``preset = None``: no preset, the material as it was."""
    case = load_case("power25W")
    again = case_from_dict(case.model_dump())
    assert again.materials["PA12"] == case.materials["PA12"] == Material()


def test_an_unknown_preset_is_one_line_naming_key_value_and_names():
    with pytest.raises(CaseError) as e:
        load_case("machine_layer", ["materials.PA12.preset=pa13"])
    msg = str(e.value)
    assert "\n" not in msg
    assert "materials.PA12.preset = 'pa13'" in msg
    assert all(n in msg for n in preset_names())


def test_the_docs_table_is_rendered_from_the_preset_file():
    """docs/record/pa12_process.md holds the preset's table as config.presets.preset_table renders
    it (regenerate: see the docs page)."""
    text = DOCS.read_text()
    found = re.search(re.escape(BEGIN) + "(.*?)" + re.escape(END), text, re.S)
    assert found, f"docs/record/pa12_process.md has no {BEGIN.strip()} block"
    assert found.group(1) == preset_table(PRESET)


def test_machine_layer_uses_the_preset_and_its_process_values():
    """cases/machine_layer.toml names the preset, crystallises by kinetics, and sets the
    process keys (bed temperature, emissivity, absorptivity, beam depth) to the file's."""
    case = load_case("machine_layer")
    m = case.materials["PA12"]
    assert m.preset == PRESET
    assert m.crystallization_kinetics is not None and m.crystallization_range_C is None
    proc = read_preset(PRESET)["process"]
    las = case.lasers[0]
    assert case.thermal.initial_C == proc["thermal.initial_C"]["value"]
    assert case.thermal.emissivity == proc["thermal.emissivity"]["value"]
    assert las.absorptivity == proc["lasers.absorptivity"]["value"]
    assert las.penetration_depth_um == proc["lasers.penetration_depth_um"]["value"]
