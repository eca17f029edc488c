"""A pure case (#52): validating a case only checks it; config/resolve.py builds what derives
from it (the bed's bodies, the fitted domain, the 3D laser depths), the same each time."""

import copy

import pytest

from taichi_sls.config import (
    CaseError,
    ResolvedCase,
    bundled_case,
    case_from_dict,
    case_to_dict,
    load_case,
    read_toml,
    resolve,
    validate_case,
)
from taichi_sls.config.loading import resolve_files


def _raw(name: str) -> dict:
    path = bundled_case(name)
    data = read_toml(path, "case file")
    resolve_files(data, path.parent)
    return data


@pytest.mark.parametrize("name", ["bed_track", "bed3d_track"])
def test_validating_a_bed_case_twice_gives_equal_cases_and_leaves_the_dict(name):
    data = _raw(name)
    before = copy.deepcopy(data)
    a, b = validate_case(data), validate_case(data)
    assert data == before
    assert a == b and a is not b
    # the bed is still a table: nothing was deposited, no domain side fitted
    assert a.bed is not None and "width_um" not in a.domain.model_fields_set
    assert not isinstance(a, ResolvedCase)


@pytest.mark.parametrize("name", ["bed_track", "bed3d_track"])
def test_loading_a_bed_case_twice_gives_equal_resolved_cases(name):
    a, b = load_case(name), load_case(name)
    assert isinstance(a, ResolvedCase) and a == b
    assert a.bed is None and a.bed_report == b.bed_report
    assert len(a.bodies) == len(a.given.bodies) + a.bed_report.get(
        "discs", a.bed_report.get("spheres")
    )


def test_resolving_leaves_the_given_case_as_it_was():
    data = _raw("bed3d_track")
    for las in data["lasers"]:
        las.pop("z_start_um", None)  # left to its default, the mid-depth of the fitted domain
    given = validate_case(data)
    dump = given.model_dump()
    resolved = resolve(given)
    assert given.model_dump() == dump and resolved.given is given
    assert given.bed is not None and resolved.bed is None
    assert [las.z_start_um for las in given.lasers] == [None] * len(given.lasers)
    assert all(
        las.z_start_um == 0.5 * resolved.domain.depth() for las in resolved.lasers
    )  # set once the bed fitted the depth


def test_resolve_is_idempotent_and_its_dump_loads_back_to_the_same_case():
    resolved = load_case("bed_track")
    assert resolve(resolved) is resolved
    again = case_from_dict(case_to_dict(resolved))
    assert again.model_dump() == resolved.model_dump()
    assert again.bed_report is None  # no bed left to report on


def test_the_given_bed_case_dumps_without_the_fitted_sides_and_loads_back():
    given = load_case("bed_track").given
    data = case_to_dict(given)
    assert "width_um" not in data["domain"] and "bed" in data
    assert validate_case(data) == given


def test_a_bed_case_refused_once_resolved_names_the_key():
    data = _raw("bed_track")
    data["grid"] = {**data.get("grid", {}), "spacing_um": 1e-3}
    validate_case(data)  # the domain is not fitted yet: the cell count is checked on resolving
    with pytest.raises(CaseError, match=r"^grid\.spacing_um = 0\.001: .* cells"):
        case_from_dict(data)
