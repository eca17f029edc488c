"""``time.refactorize = "when_slow"`` (solver/linear_solve.py, LinearSolver._mapped): the
implicit step's factorization kept across tangents and steps, as CG's preconditioner over the
unknowns that old and new systems share, gives the steps the reference (a factorization a
tangent) gives, to the solves' tolerance, with fewer factorizations."""

import numpy as np
import pytest

from taichi_sls.config import CaseError, case_from_dict
from taichi_sls.solver.simulation import Simulation


def _pair(refactorize: str) -> dict:
    """Two molten process-PA12 discs of R = 20 um touching at h = 4 um, surface tension on,
    adaptive implicit steps from 1 us: the contact zips, nodes enter and leave the system."""
    return {
        "grid": {"spacing_um": 4.0},
        "domain": {"width_um": 120.0, "height_um": 60.0},
        "bodies": [
            {"center_um": [x, 30.0], "radius_um": 20.0, "temperature_C": 200.0}
            for x in (40.0, 80.0)
        ],
        "materials": {"PA12": {"preset": "pa12_process"}},
        "physics": {"thermal": False, "gravity_m_s2": [0.0, 0.0]},
        "time": {
            "integrator": "implicit",
            "adaptive": True,
            "dt_s": 1e-6,
            "end_s": 1.0,
            "linear_solver": "direct",
            "refactorize": refactorize,
        },
        "output": {"frames": 1},
    }


def test_kept_factorization_takes_the_reference_steps():
    """Twelve adaptive steps: every point within 1e-6 of a cell of the reference (Newton to
    time.newton_tolerance = 1e-6 of the force scale either way; the CG solves to 1e-6 relative
    residual move the iterate by about that), the same steps taken (their sizes, set by the
    changes, within 1e-6), fewer factorizations (the
    reference factorizes every tangent, at least one a step) and CG iterations in their place."""
    runs = {}
    for how in ("each_tangent", "when_slow"):
        sim = Simulation(case_from_dict(_pair(how)))
        for _ in range(12):
            sim.adaptive.step()
        runs[how] = (sim.state.points.x.to_numpy(), sim.t, sim.implicit.linear.stats)
    (x_ref, t_ref, ref), (x_kept, t_kept, kept) = runs["each_tangent"], runs["when_slow"]
    assert abs(t_kept - t_ref) <= 1e-6 * t_ref  # the steps the changes choose, nearly equal
    assert np.abs(x_kept - x_ref).max() <= 1e-6 * 4e-6
    assert ref.factorizations >= 12 and ref.cg_iterations == 0
    assert kept.factorizations < ref.factorizations / 2
    assert kept.cg_iterations > 0


def test_refused_where_no_factorization_is_kept():
    """AMG and the matrix-free step keep no factorization: the option is refused, naming
    both keys."""
    for solver in ("amg", "matrix_free"):
        case = _pair("when_slow")
        case["time"]["linear_solver"] = solver
        with pytest.raises(CaseError, match=f'time.refactorize = "when_slow".*"{solver}"'):
            case_from_dict(case)
