"""The initial neck as the grid reads it: a prescribed fillet outline reads the same at every
h (the point contact reads 18.4 / 13.6 / 9.6 um at h = 4 / 2 / 1 um). Read on the raw colour
(contact.neck_colour = "raw"), the seeded outline; the filtered colour the process results read
widens a concave neck by less than kappa h^2."""

import math

import pytest

import taichi_sls
from taichi_sls.solver.contacts import fillet
from taichi_sls.solver.simulation import Simulation


def _neck_um(name: str, h: float, *sets: str) -> float:
    """The seeded outline's neck: the section across the centres on the raw colour (the
    filtered one, the default reading, is wider at a concave neck: the last test)."""
    sets = (
        f"grid.spacing_um={h}",
        "solver.optimize=false",
        "contact.neck_section=centres",
        "contact.neck_colour=raw",
        *sets,
    )
    case = taichi_sls.load_case(name, list(sets))
    return Simulation(case).monitors()["contact_line_um"]


@pytest.mark.parametrize("h", [2.0, pytest.param(1.0, marks=pytest.mark.slow)])
def test_a_prescribed_8um_neck_reads_8um(h):
    """The bundled contact_neck case: discs 45.25 um apart joined by 4 um fillets, an 8 um neck.
    Tolerance 5 % (the issue's): the colour's c = 1/2 outline sits within a few tenths of a
    point spacing of a concave fillet of radius 2h or more (measured: +1.1 % at h = 2 um,
    +0.04 % at 1 um; +37 % at h = 4 um, where the neck is two cells)."""
    assert _neck_um("contact_neck", h) == pytest.approx(8.0, rel=0.05)


@pytest.mark.slow  # ~55 s at h = 1 um; the prescribed 8 um neck at h = 2 um stays in default
def test_the_paper_pair_with_a_fillet_reads_its_neck_at_h_2_and_1():
    """The paper's touching discs joined by 2 um fillets: neck 2 (sqrt(rho^2 + 2 R rho) - rho)
    = 14.33 um; read within 2 % at h = 2 and 1 um (measured +0.5 % and +0.3 %)."""
    exact = fillet([20.0, 20.0], 20.0, [60.0, 20.0], 20.0, 2.0).neck_width
    assert exact == pytest.approx(2 * (math.sqrt(4.0 + 80.0) - 2.0))
    sets = ("contact.initial=fillet", "contact.fillet_radius_um=2")
    for h in (2.0, 1.0):
        assert _neck_um("nolaser", h, *sets) == pytest.approx(exact, rel=0.02)


def test_the_resolved_case_reads_its_fillet_neck():
    """cases/power25W_resolved.toml as bundled (h = 2 um, 4 um fillets, area seeding): the
    neck 2 (sqrt(rho^2 + 2 R rho) - rho) = 18.53 um, read within 1 % (measured +0.4 %; centre
    seeding reads -0.6 % here and +2.5 % at h = 1 um, the staircase the case avoids)."""
    exact = fillet([20.0, 20.0], 20.0, [60.0, 20.0], 20.0, 4.0).neck_width
    assert exact == pytest.approx(2 * (math.sqrt(16.0 + 160.0) - 4.0))
    # the neck at t = 0 is the seeded outline's: explicit steps (the hybrid's implicit kernels
    # need not compile to read it)
    sets = ("time.integrator=explicit", "contact.settle_steps=explicit")
    neck = _neck_um("power25W_resolved", 2.0, *sets)
    assert neck == pytest.approx(exact, rel=0.01)


@pytest.mark.parametrize(
    "name, extra, rho",
    [
        ("contact_neck", (), 4.0),
        ("power25W_resolved", ("time.integrator=explicit", "contact.settle_steps=explicit"), 4.0),
    ],
)
def test_the_filtered_colour_widens_a_concave_neck_by_less_than_kappa_h2(name, extra, rho):
    """The default reading (contact.neck_colour = "filtered", the outline the force moves) of a
    fillet neck of curvature kappa = 1 / rho is wider than the raw colour's, by less than
    kappa h^2 (the [1 2 1] / 4 pass has variance h^2 / 2 per direction; 1 um here). Measured
    +0.64 um (8.09 -> 8.73) and +0.69 um (18.61 -> 19.31) at h = 2 um."""
    h = 2.0
    sets = ("solver.optimize=false", "contact.neck_section=centres", "contact.neck_colour=raw")
    sim = Simulation(taichi_sls.load_case(name, [*sets, *extra]))
    assert sim.state.cfg.h == pytest.approx(h * 1e-6)
    raw = sim.necks.necks_m()[0] * 1e6
    sim.case.contact.neck_colour = "filtered"
    filtered = sim.necks.necks_m()[0] * 1e6
    assert 0.0 < filtered - raw < h * h / rho
