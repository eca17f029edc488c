"""The neck a validation compares converges in h on the default measure (issue #54, item 5):
the resolved pair (cases/power25W_resolved.toml, settled by implicit steps as bundled) read on
the default colour, the points' kernel sum closed by a one-cell disc (solver/kernel_colour.py),
at h = 2 and 1 um; the force's filtered colour, the default before, kept by its key."""

import pytest

from taichi_sls.config import load_case
from taichi_sls.jobs.settle import settle
from taichi_sls.solver.simulation import Simulation


def _settled_necks_um(h: float) -> dict[str, float]:
    """The settled pair's neck at h on each colour (the settle itself read the default)."""
    case = load_case("power25W_resolved", [f"grid.spacing_um={h}", "solver.optimize=false"])
    sim = Simulation(case)
    settle(sim, case, progress=False)
    necks = {}
    for colour in ("kernel", "filtered"):
        sim.case.contact.neck_colour = colour
        necks[colour] = sim.necks.necks_m("colour")[0] * 1e6
    return necks


@pytest.mark.slow  # ~2 min: the settle at h = 1 um (13,191 implicit steps)
def test_the_resolved_pairs_settled_neck_converges_on_the_default_measure():
    """Within 1 % (the issue's bar) between h = 2 and 1 um: measured 19.788 / 19.729 um
    (+0.30 %). The filtered colour, which widens the 4 um fillet's concave neck by about
    kappa h^2 / 4, reads 20.417 / 19.789 um (+3.2 %): asserted beyond 2 %, the failure this
    default mends."""
    coarse, fine = _settled_necks_um(2.0), _settled_necks_um(1.0)
    print("settled neck (um) at h = 2 / 1 um:", {k: (coarse[k], fine[k]) for k in coarse})
    assert load_case("power25W_resolved").contact.neck_colour == "kernel"
    assert coarse["kernel"] == pytest.approx(fine["kernel"], rel=0.01)
    assert coarse["filtered"] / fine["filtered"] - 1.0 > 0.02
