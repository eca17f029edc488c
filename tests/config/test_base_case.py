"""A case file's ``base`` (config/base_case.py): the base's keys, the file's own over them."""

import pytest

from taichi_sls.config import CaseError, load_case

TABLE2 = ["power5W", "power15W", "radius30um", "radius70um", "scan4mps"]


def _dump(case) -> dict:
    out = case.model_dump()
    out.pop("case")
    return out


@pytest.mark.parametrize("coarse", [False, True])
def test_a_table2_file_is_its_base_with_the_keys_it_changes(coarse):
    sets = {
        "power5W": ["lasers.0.power_W=5"],
        "power15W": ["lasers.0.power_W=15"],
        "radius30um": ["lasers.0.power_W=15", "lasers.0.spot_radius_um=30"],
        "radius70um": ["lasers.0.power_W=15", "lasers.0.spot_radius_um=70"],
        "scan4mps": [
            "lasers.0.power_W=15",
            "lasers.0.x_start_um=0.0",
            "lasers.0.x_end_um=80.0",
            "lasers.0.speed_m_s=4.0",
            "lasers.0.off_s=1e-3",
        ],
    }
    grid = ["grid.spacing_um=4.0", "time.dt_s=auto"] if coarse else []
    for name in TABLE2:
        case = load_case(name + "_coarse" * coarse)
        assert case.case.name == name + "_coarse" * coarse
        assert _dump(case) == _dump(load_case("power25W", [*sets[name], *grid]))


def _write(folder, name: str, text: str):
    path = folder / f"{name}.toml"
    path.write_text(text)
    return path


BASE = """
[case]
name = "two"
description = "two discs"
[[bodies]]
center_um = [20.0, 20.0]
radius_um = 20.0
[[bodies]]
center_um = [60.0, 20.0]
radius_um = 20.0
[[lasers]]
power_W = 10
x_start_um = 30.0
"""


def test_tables_merge_a_list_by_index_or_whole_and_the_name_is_the_files(tmp_path):
    _write(tmp_path, "two", BASE)
    path = _write(tmp_path, "child", 'base = "two.toml"\n[lasers.0]\npower_W = 20\n')
    case = load_case(path)
    assert case.case.name == "child" and case.case.description == "two discs"
    assert case.lasers[0].power_W == 20 and case.lasers[0].x_start_um == 30.0
    assert [b.radius_um for b in case.bodies] == [20.0, 20.0]
    whole = _write(tmp_path, "whole", 'base = "two"\n[[lasers]]\npower_W = 5\n')
    assert load_case(whole).lasers[0].x_start_um != 30.0  # the list replaced, not merged


def test_a_base_names_a_bundled_case_and_its_base_in_turn(tmp_path):
    path = _write(tmp_path, "mine", 'base = "power15W_coarse"\n[time]\nend_s = 1e-4\n')
    case = load_case(path)
    assert case.lasers[0].power_W == 15 and case.grid.spacing_um == 4.0
    assert case.time.end_s == 1e-4 and case.case.name == "mine"


def test_a_missing_base_a_cycle_and_a_bad_index_are_one_line_errors(tmp_path):
    missing = _write(tmp_path, "missing", 'base = "no_such_case"\n')
    with pytest.raises(CaseError, match=r"base = 'no_such_case': no such case file") as e:
        load_case(missing)
    assert "\n" not in str(e.value)
    _write(tmp_path, "a", 'base = "b"\n')
    b = _write(tmp_path, "b", 'base = "a.toml"\n')
    with pytest.raises(CaseError, match=r"a cycle of bases \(b.toml -> a.toml -> b.toml\)"):
        load_case(b)
    _write(tmp_path, "two", BASE)
    bad = _write(tmp_path, "bad", 'base = "two"\n[lasers.1]\npower_W = 20\n')
    with pytest.raises(CaseError, match=r"lasers\.1: no such item; the base's lasers has 1"):
        load_case(bad)
