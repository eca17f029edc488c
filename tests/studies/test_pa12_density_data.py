"""The bundled PA12 density / energy-density points: every row attributed and physical."""

from __future__ import annotations

import csv
from importlib import resources


def _rows() -> list[dict[str, str]]:
    path = resources.files("taichi_sls.studies.references") / "data" / "pa12_density_energy.csv"
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


def test_every_point_names_its_source_and_is_a_physical_density():
    rows = _rows()
    assert rows
    for row in rows:
        assert row["source"].strip() and row["where"].strip(), row
        rho, ref = float(row["density_g_cm3"]), float(row["relative_to_g_cm3"])
        assert 0.0 < rho <= ref <= 1.1, row
        if row["energy_density_J_mm2"]:
            assert float(row["energy_density_J_mm2"]) >= 0.0, row
