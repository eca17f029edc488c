"""The implicit step without assembled tangent rows (time.linear_solver = "matrix_free",
solver/multigrid.py): its operator is the assembled Newton matrix, its multigrid-preconditioned
CG solves it, and a run with it takes the steps the direct solver takes."""

import numpy as np
import pytest

from taichi_sls.config import CaseError, case_from_dict
from taichi_sls.solver.multigrid import MatrixFreeSolver
from taichi_sls.solver.simulation import Simulation


def pair(dim: int, h_um: float, solver: str, dt_s: float | None = None) -> dict:
    """Two molten process-PA12 discs (spheres) of R = 20 um touching, surface tension on."""
    centre = [30.0] * (dim - 1)
    time = {"integrator": "implicit", "linear_solver": solver, "end_s": 1.0}
    if dt_s is not None:
        time["dt_s"] = dt_s
    domain = {"dim": dim, "width_um": 120.0, "height_um": 60.0}
    if dim == 3:
        domain["depth_um"] = 60.0
    return {
        "grid": {"spacing_um": h_um},
        "domain": domain,
        "bodies": [
            {"center_um": [x, *centre], "radius_um": 20.0, "temperature_C": 200.0}
            for x in (40.0, 80.0)
        ],
        "materials": {"PA12": {"preset": "pa12_process"}},
        "physics": {"thermal": False, "gravity_m_s2": [0.0] * dim},
        "time": time,
        "output": {"frames": 1},
    }


def pair3d_steps(steps: int, **time) -> Simulation:
    """The molten 3D pair (h = 4 um, direct solves, a fixed 1 ms step) after ``steps`` steps,
    with the ``time`` keys given."""
    data = pair(3, 4.0, "direct", dt_s=1e-3)
    data["time"].update(time)
    sim = Simulation(case_from_dict(data))
    sim.advance_to(steps * sim.dt)
    return sim


def _newton_system(case: dict):
    sim = Simulation(case_from_dict(case))
    sys_ = sim.implicit.prepare()
    f_int, tangent = sim.implicit.internal(sys_, sys_.v0)
    return sim, sys_, tangent


@pytest.mark.parametrize("dim", [2, pytest.param(3, marks=pytest.mark.slow)])
def test_operator_is_the_assembled_newton_matrix(dim):
    """A x through the points equals the assembled (fixed + tangent) x: the same sums in
    another order, so to round-off (1e-12 relative)."""
    rng = np.random.default_rng(3)
    _, sys_, tangent = _newton_system(pair(dim, 4.0, "direct", dt_s=1e-3))
    x = rng.standard_normal(sys_.n)
    want = sys_.matrix(sys_.fixed + tangent) @ x
    sim, sys_mf, none = _newton_system(pair(dim, 4.0, "matrix_free", dt_s=1e-3))
    assert none is None  # no rows assembled
    solver = MatrixFreeSolver(sim.state, sys_mf)
    solver.set_tangent()
    mg = solver.multigrid
    got = mg.sparse(mg.apply(0, mg.dense(x)))
    assert np.linalg.norm(got - want) <= 1e-12 * np.linalg.norm(want)


@pytest.mark.slow  # ~16 s
def test_multigrid_iterations_do_not_grow_with_the_grid():
    """CG with the V-cycle reaches 1e-6 in about as many iterations on a grid twice as fine
    (a multigrid's property; unpreconditioned CG's count would double): within 1.5x, with a
    margin of 3 iterations for the coarsest level's reach. At a viscous step (dt = 10 ms:
    the hold's regime, inertia 1e-8 of the viscous stiffness)."""
    iterations = {}
    for h in (2.0, 1.0):
        sim, sys_, _ = _newton_system(pair(2, h, "matrix_free", dt_s=1e-2))
        solver = MatrixFreeSolver(sim.state, sys_)
        solver.set_tangent()
        b = np.random.default_rng(1).standard_normal(sys_.n)
        x = solver.solve(None, b)
        mg = solver.multigrid
        Ax = mg.sparse(mg.apply(0, mg.dense(x)))
        # CG stops on its updated residual (1e-6); the true one drifts from it by round-off
        # times the condition number (1.1e-6 measured): 1e-5 leaves room, 1e-3 would be a miss
        assert np.linalg.norm(Ax - b) <= 1e-5 * np.linalg.norm(b)
        iterations[h] = solver.stats.cg_iterations
        assert len(mg.levels) >= 2
    assert iterations[1.0] <= 1.5 * iterations[2.0] + 3, iterations


def test_steps_match_the_direct_solver():
    """Three implicit steps of the 3D pair: the points where the direct solver puts them, to
    1e-5 of a cell (both converge Newton to time.newton_tolerance = 1e-6 of the force scale;
    the rest is the linear solves' tolerance), and the run records the solver it used."""
    positions = {}
    for solver in ("direct", "matrix_free"):
        sim = Simulation(case_from_dict(pair(3, 4.0, solver, dt_s=1e-3)))
        sim.advance_to(3 * sim.dt)
        positions[solver] = sim.state.points.x.to_numpy()
        assert sim.implicit.last.solver == solver
    h = 4e-6
    assert np.abs(positions["direct"] - positions["matrix_free"]).max() <= 1e-5 * h


@pytest.mark.slow  # ~20 s: the 3D pair through 0.2 s of its hold, on either solver
def test_a_3d_pairs_neck_matches_the_direct_solvers():
    """The molten 3D pair held 0.2 s in steps of 50 ms (viscous steps, several Newton iterations
    each): its neck grows, and the matrix-free step puts it within 0.1 % of the direct one's
    (issue #53's bound; both solve each Newton direction to the relative residual 1e-6)."""
    necks = {}
    for solver in ("direct", "matrix_free"):
        sim = Simulation(case_from_dict(pair(3, 4.0, solver, dt_s=5e-2)))
        start = sim.necks.necks_m()[0]
        sim.advance_to(4 * sim.dt)
        necks[solver] = sim.necks.necks_m()[0]
    assert necks["direct"] > 1.02 * start, (start, necks)
    assert necks["matrix_free"] == pytest.approx(necks["direct"], rel=1e-3)


@pytest.mark.slow  # ~60 s: a molten bed of 8 spheres held 0.1 s, on either solver
def test_a_beds_density_matches_the_direct_solvers(tmp_path):
    """machine_layer3d's bed cut to 8 spheres, unsettled, molten at 200 C without the beam and
    held 0.1 s in 20 ms steps: it densifies, and its relative density on the matrix-free step is
    within 0.002 of the direct one's (issue #53's bound for the layer's final density)."""
    from taichi_sls.config import load_case
    from taichi_sls.jobs.case_run import run_case

    density = {}
    for solver in ("direct", "matrix_free"):
        sets = ["bed.count=8", "bed.z_range_um=[0.0, 60.0]", "contact.settle=false"]
        sets += ["thermal.initial_C=200", "lasers.0.power_W=0", "time.adaptive=false"]
        sets += ["time.dt_s=2e-2", "time.end_s=0.1", "output.png=false", "output.gif=false"]
        sets.append(f"time.linear_solver={solver}")
        summary = run_case(load_case("machine_layer3d", sets), tmp_path / solver, progress=False)
        assert summary["linear_solves"]["solver"] == solver
        density[solver] = summary["bed"]["relative_density"]
    assert density["direct"]["final"] > density["direct"]["initial"] + 0.02, density
    assert abs(density["matrix_free"]["final"] - density["direct"]["final"]) <= 0.002


def test_refused_with_the_cells_dilatation():
    """The operator holds each point's own tangent, not the cell's volumetric one."""
    case = pair(2, 4.0, "matrix_free")
    case["solver"] = {"dilatation": "cell"}
    with pytest.raises(CaseError, match='linear_solver = "matrix_free"'):
        case_from_dict(case)


def test_refused_with_the_velocity_penalty():
    """The penalty is added to assembled rows, which the matrix-free step does not gather."""
    case = pair(2, 4.0, "matrix_free")
    case["time"]["implicit_velocity_penalty"] = 1e-6
    with pytest.raises(CaseError, match="time.implicit_velocity_penalty"):
        case_from_dict(case)


@pytest.mark.slow  # ~17 s
def test_a_hybrid_run_with_heat_takes_it(tmp_path):
    """The hybrid pair with backward-Euler heat: the mechanics' solves are matrix-free, the
    heat's (assembled anyway) take the direct solver; the run records the mechanics' solver."""
    from taichi_sls.config import load_case
    from taichi_sls.jobs.case_run import run_case

    sets = ["grid.spacing_um=4", "time.stop=end", "time.end_s=4e-5", "output.png=false"]
    sets += ["output.gif=false", "time.linear_solver=matrix_free"]
    summary = run_case(load_case("power25W_resolved", sets), tmp_path, progress=False)
    assert summary["status"] == "complete"
    assert summary["linear_solves"]["solver"] == "matrix_free"
    assert summary["linear_solves"]["cg_iterations"] > 0


def test_a_krylov_solve_that_does_not_converge_stops_the_run_with_its_state(tmp_path, monkeypatch):
    """CG held to one iteration cannot reach its tolerance: the run stops with a message that
    says so and names the keys to change, its state written beside the frames already out
    (failed_state.npz), never a step taken on an unconverged solve."""
    from taichi_sls.jobs.case_run import run_case
    from taichi_sls.solver import multigrid

    monkeypatch.setattr(multigrid, "CG_MAX_ITERATIONS", 1)
    data = pair(2, 4.0, "matrix_free", dt_s=1e-3)
    data["time"]["end_s"] = 3e-3
    data["output"] = {"frames": 3, "png": False, "gif": False}
    summary = run_case(case_from_dict(data), tmp_path, progress=False)
    assert summary["status"] == "failed"
    assert "conjugate gradients with the multigrid" in summary["error"]
    assert 'time.linear_solver = "direct"' in summary["error"]
    assert "implicit_velocity_penalty" not in summary["error"]  # refused with matrix_free
    assert (tmp_path / "failed_state.npz").is_file()
    assert (tmp_path / "summary.json").is_file()


def test_the_coarsest_matrix_is_the_coarsest_operator():
    """The coarsest level's matrix, assembled entry by entry from its quadrature points, is the
    operator the cycle applies there (its tangent through the points and its lumped mass over
    dt), on a random vector over its unknowns to round-off; symmetric, as its Cholesky needs."""
    sim = Simulation(case_from_dict(pair(2, 2.0, "matrix_free", dt_s=1e-3)))
    sim.advance_to(sim.dt)
    multigrid = sim.implicit.linear.multigrid
    k = len(multigrid.levels) - 1
    rows, M = multigrid.coarsest_matrix()
    x = np.zeros(multigrid.levels[k].free.size)
    x[rows] = np.random.default_rng(1).standard_normal(len(rows))
    applied = multigrid.apply(k, x.reshape(-1, 2)).reshape(-1)[rows]
    assert k >= 1 and len(rows) > 100
    assert np.linalg.norm(M @ x[rows] - applied) <= 1e-12 * np.linalg.norm(applied)
    assert np.abs(M - M.T).max() <= 1e-12 * np.abs(M).max()


def test_auto_rows_take_the_blocks_with_the_matrix_free_step():
    """time.implicit_rows = "auto" stores a small 3D scene's rows dense for the direct step and
    by blocks for the matrix-free one (its fixed part's rows alone, which dense over the box
    outweigh the rest of its memory); "dense" keeps them dense; 2D stays dense."""
    from taichi_sls.solver.step_config import sparse_rows

    grid = (37, 22, 22)
    for solver, rows, expected in (
        ("direct", "auto", False),
        ("matrix_free", "auto", True),
        ("matrix_free", "dense", False),
    ):
        case = pair(3, 4.0, solver)
        case["time"]["implicit_rows"] = rows
        assert sparse_rows(case_from_dict(case), grid) is expected, (solver, rows)
    assert sparse_rows(case_from_dict(pair(2, 4.0, "matrix_free")), (37, 22)) is False
