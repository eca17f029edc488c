"""The process cycle as a case (issue 40 item 3): cases/machine_layer.toml and the hold."""

import math

import pytest

from taichi_sls.config import load_case
from taichi_sls.jobs.progress import Progress


def test_machine_layer_is_a_hatched_layer_at_a_machine_setting():
    """The bundled layer: a 172 C bed (powder, plate, chamber), hatches across the plane at an
    incident energy density of 0.031 J/mm^2, held 10 s after the scan, contacts settled."""
    case = load_case("machine_layer")
    las = case.lasers[0]
    assert las.scan == "across" and las.tracks == 4
    andrew_J_mm2 = las.power_W / (las.speed_m_s * 1e3 * las.hatch_um * 1e-3)
    assert andrew_J_mm2 == pytest.approx(0.03125)
    assert case.thermal.initial_C == 172.0 == case.thermal.chamber_temperature_C()
    assert case.boundary.bottom.thermal == "fixed" and case.boundary.bottom.temperature_C == 172.0
    assert case.thermal.top_surface == "chamber"
    assert case.contact.settle
    scan_end = case.lasers_off_s()
    assert scan_end == pytest.approx(3 * 2e-3 + 6 * 50e-6 / 8.0)
    assert case.time.end_s > 1000 * scan_end  # the layer time is the hold


def test_machine_layer3d_is_the_machine_cycle_on_spheres():
    """The 3D layer: machine_layer's bed, chamber, setting and layer time on deposited spheres,
    hatched in the bed plane (two tracks along x, 0.1 mm apart), contacts settled."""
    case, flat = load_case("machine_layer3d"), load_case("machine_layer")
    las, las_2d = case.lasers[0], flat.lasers[0]
    assert case.domain.dim == 3 and len(case.bodies) == case.bed_report["spheres"] == 48
    assert las.direction == "x" and las.tracks == 2 and las.hatch_um == las_2d.hatch_um
    assert (las.power_W, las.speed_m_s) == (las_2d.power_W, las_2d.speed_m_s)
    for key in ("initial_C", "top_surface", "chamber_C", "emissivity", "convection_W_m2K"):
        assert getattr(case.thermal, key) == getattr(flat.thermal, key), key
    assert case.boundary.bottom.temperature_C == 172.0 and case.contact.settle
    assert case.materials["PA12"].crystallization_kinetics is not None
    assert case.time.end_s == flat.time.end_s == 10.0


def test_the_progress_bar_shows_the_scan_then_the_hold(capsys):
    for t, phase in ((1e-3, "scan, "), (2.0, "hold, ")):
        bar = Progress(10.0, 0.0, adaptive=True, lasers_off_s=6e-3)
        bar.update(t, 5.0, 1e-2)
        bar.close()
        assert phase in capsys.readouterr().err
    bar = Progress(10.0, 0.0, adaptive=True, lasers_off_s=math.nan)
    bar.update(2.0, 5.0, 1e-2)
    bar.close()
    err = capsys.readouterr().err
    assert "hold" not in err and "scan" not in err


@pytest.mark.slow
def test_machine_layer_runs_its_first_pass(tmp_path):
    """A short run of the bundled layer: settled, the first pass melts powder (about 1 min)."""
    from taichi_sls.jobs.case_run import run_case

    case = load_case("machine_layer", ["time.end_s=1e-4"])
    s = run_case(case, tmp_path, progress=False)
    assert s["status"] == "complete"
    assert s["settle"]["steps"] > 0
    assert s["bed"]["contacts"] > 0
    assert s["final"]["molten_fraction"] > 0.0
