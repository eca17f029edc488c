"""The implicit integrator (solver/implicit.py): its tangent, its capillary stiffness, its linear
solves, its verification rows at steps far beyond the explicit limits, and its input checks."""

import numpy as np
import pytest
import scipy.sparse as sp
from helpers import advance_steps, deep_update, explicit_coarse_peak_C, shared

from taichi_sls.config import CaseError, load_case
from taichi_sls.solver import checkpoint
from taichi_sls.solver.implicit import ImplicitStepper, NewtonError
from taichi_sls.solver.linear_solve import (
    DirectFactor,
    LinearSolveError,
    LinearSolver,
    preconditioned_cg,
)
from taichi_sls.solver.simulation import Simulation
from taichi_sls.solver.time_step import resolve_dt, resolve_heat_substeps, time_step_limits
from taichi_sls.studies import verification as ver

IMPLICIT = {"time": {"integrator": "implicit"}}


# one configuration for the tangent checks, so that their kernels compile once: the zero-yield
# Maxwell disc with a solvent viscosity, one step taken (stressed, moving, gamma ramping in)
DISC = {
    "time": {"integrator": "implicit", "dt_s": 2e-6},
    "materials": {"fluid": {"solvent_viscosity_Pa_s": 0.05}},
}


def _step_disc():
    sim = Simulation(ver.load("laplace", 10, DISC).case)
    st = sim.state

    def saved():
        return checkpoint.capture(st), st.scalars.to_numpy(), st.box.to_numpy(), sim.steps

    at_rest = saved()
    advance_steps(sim, 1)
    return sim, {0: at_rest, 1: saved()}


def _stepped_disc(steps: int = 1) -> Simulation:
    """The Laplace disc of Maxwell fluid at R/h = 10 (cases/verification/laplace.toml) after
    ``steps`` steps: built once for the tests here (its implicit kernels compiled once), and
    put back to its state at rest or after its first step for each (what a test's steps and
    settings changed), then stepped on to ``steps``."""
    sim, states = shared("stepped_disc", _step_disc)
    st = sim.state
    start = min(steps, 1)
    saved, scalars, box, done = states[start]
    checkpoint.restore(st, saved)
    st.scalars.from_numpy(scalars)
    st.box.from_numpy(box)
    sim.steps = done
    sim.implicit.penalty = sim.case.time.implicit_velocity_penalty
    if steps > start:
        advance_steps(sim, steps - start)
    return sim


@pytest.mark.parametrize("steps", [2, 0], ids=["prestressed", "at_rest"])
def test_tangent_is_the_derivative_of_the_internal_force(steps):
    """Small-strain incremental update, prestressed and moving after two steps (gamma ramps in
    from zero: after one step the disc is still at rest) or at rest: the internal force is
    affine in the grid velocity (the zero-yield return's secant ratio tau / (tau + dt) does not
    depend on the strain increment; the solvent stress is linear), so the assembled tangent
    times a velocity change is the internal force's change to round-off. At rest the trial
    deviator is zero and the return map reads it as elastic: the tangent there must still be
    the flow's (the implicit step keeps its first iterate's tangent; with mu there, 11 % off
    here, Newton converged linearly and hopper_pa12's first step stopped just inside its
    tolerance). Tolerance 1e-9 relative: a wrong index, sign or factor shows at order one."""
    sim = _stepped_disc(steps)
    stepper = sim.implicit
    system = stepper.prepare()
    rng = np.random.default_rng(1)
    v0 = system.v0
    assert (np.abs(v0).max() > 0.0) == (steps > 0)
    dv = rng.normal(size=system.n) * 1e-3  # m/s, the disc's flow (v0 after two steps)
    f0, tangent = stepper.internal(system, v0)
    f1, _ = stepper.internal(system, v0 + dv)
    K = system.matrix(tangent)
    assert abs(K - K.T).max() == 0.0  # the points write the upper triangle; a reader mirrors it
    change = -(f1 - f0)
    assert np.linalg.norm(change) > 0.0
    assert np.linalg.norm(K @ dv - change) <= 1e-9 * np.linalg.norm(change)


def test_capillary_stiffness_is_symmetric_semidefinite_and_blind_to_translation():
    """The surface Laplacian gamma dt sum_q w_q L_q (t . grad N_i)(t . grad N_j): symmetric,
    v^T K v >= 0, and zero on a uniform velocity (grad of a constant along t), so the implicit
    capillary term holds back no rigid motion. The fixed matrix less its inertia m_i / dt."""
    sim = _stepped_disc()
    system = sim.implicit.prepare()
    A = system.matrix(system.fixed)
    mass = sim.state.nodes.mass.to_numpy()
    i, j, c = system.dof_node.T
    K = A - sp.diags(mass[i, j] / sim.dt)
    assert abs(K).max() > 0
    assert abs(K - K.T).max() <= 1e-12 * abs(K).max()
    rng = np.random.default_rng(2)
    for _ in range(5):
        v = rng.normal(size=system.n)
        assert v @ (K @ v) >= -1e-12 * abs(K).max() * (v @ v)
    # rows whose every neighbour is an unknown: the row sum per component vanishes
    uniform = (c == 0).astype(float)
    full = np.diff(system.indptr) == system.slots.shape[1]
    assert full.sum() > 0.5 * system.n
    row = K @ uniform
    assert np.abs(row[full]).max() <= 1e-10 * abs(K).max()


def test_second_differences_hold_linear_fields_free_and_stiffen_a_checkerboard():
    """time.implicit_velocity_penalty's matrix on the disc's unknowns: the same entries as a
    loop over the (i - e, i, i + e) triples written out here; zero on a linear velocity field
    (the second difference of integers is exact); on a checkerboard of one component each
    triple adds (1 + 2 + 1)^2 = 16."""
    sim = _stepped_disc()
    system = sim.implicit.prepare()
    P = system.matrix(system.second_differences())
    index = {tuple(r): k for k, r in enumerate(system.dof_node.tolist())}
    reference = np.zeros((system.n, system.n))
    triples = {0: 0, 1: 0}
    for (i, j, c), k in index.items():
        for di, dj in ((1, 0), (0, 1)):
            below, above = index.get((i - di, j - dj, c)), index.get((i + di, j + dj, c))
            if below is not None and above is not None:
                w = np.zeros(system.n)
                w[[below, k, above]] = (1.0, -2.0, 1.0)
                reference += np.outer(w, w)
                triples[c] += 1
    assert triples[0] > 100
    assert np.array_equal(P.toarray(), reference)
    i, j, c = system.dof_node.T.astype(float)
    linear = np.where(c == 0, 3.0 * i - 5.0 * j + 7.0, -2.0 * i + 11.0 * j - 1.0)
    assert np.abs(P @ linear).max() == 0.0
    checkerboard = np.where(c == 0, (-1.0) ** (i + j), 0.0)
    assert checkerboard @ (P @ checkerboard) == 16.0 * triples[0]


def test_the_velocity_penalty_enters_the_step_and_vanishes_with_its_size():
    """The same step of the disc at time.implicit_velocity_penalty = 0, 1e-6 and 5e-7: the
    penalty reaches the converged velocity, its change is linear in the penalty (halving it
    halves the change, within 1 %: the step converges to the unpenalised one), and at 1e-6
    the nodes of at least half the heaviest node's mass move by at most 1e-3 of the flow's
    largest velocity (measured 1.5e-4; the light nodes, which it is for, by more)."""
    sim = _stepped_disc()
    stepper, st = sim.implicit, sim.state
    saved, scalars = checkpoint.capture(st), st.scalars.to_numpy()
    velocities = []
    for penalty in (0.0, 1e-6, 5e-7):
        checkpoint.restore(st, saved)
        st.scalars.from_numpy(scalars)
        stepper.penalty = penalty
        system = stepper.prepare()
        velocities.append(stepper.newton(system))
    plain, full, half = velocities
    change, half_change = np.linalg.norm(full - plain), np.linalg.norm(half - plain)
    assert change > 0.0
    assert abs(change / half_change - 2.0) <= 0.02
    mass = st.nodes.mass.to_numpy()
    i, j, _ = system.dof_node.T
    heavy = mass[i, j] >= 0.5 * mass.max()
    assert heavy.sum() > 100
    assert np.abs(full - plain)[heavy].max() <= 1e-3 * np.abs(plain).max()


@pytest.mark.parametrize("how", ["direct", "amg"])
def test_linear_solver_reuses_its_preconditioner(how):
    """A 2D grid operator (mass plus Laplacian, SPD) solved to the relative residual asked; a
    drifted matrix of the same pattern is solved with the kept factorization or hierarchy as
    CG's preconditioner (direct: no new factorization while CG converges within its limit)."""
    n = 60
    lap = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    A = (sp.kronsum(lap, lap) + 0.01 * sp.eye(n * n)).tocsr()
    b = np.random.default_rng(3).normal(size=n * n)
    solver = LinearSolver(how, rtol=1e-8)
    x = solver.solve(A, b)
    assert np.linalg.norm(A @ x - b) <= 1e-7 * np.linalg.norm(b)
    A2 = A.copy()
    A2.data *= 1.0 + 0.02 * np.cos(np.arange(A2.nnz))  # same pattern, drifted values
    A2 = ((A2 + A2.T) * 0.5).tocsr()
    x2 = solver.solve(A2, b)
    assert np.linalg.norm(A2 @ x2 - b) <= 1e-7 * np.linalg.norm(b)
    assert solver.stats.factorizations == 1
    assert solver.stats.cg_iterations > 0


def test_kept_factor_preconditions_a_system_over_other_unknowns():
    """time.refactorize = "when_slow": a factorization kept from one set of unknowns
    preconditions CG on a drifted matrix whose unknowns are partly other (some left, some
    entered: a node's mass crossing the cut), reaching the residual asked with no new
    factorization; with no keys, or asked to refresh, it factorizes afresh."""
    n = 40
    lap = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    full = (sp.kronsum(lap, lap) + 0.01 * sp.eye(n * n)).tocsr()
    keys = np.arange(n * n, dtype=np.int64)
    old = keys[keys % 397 != 5]  # 4 unknowns absent before ...
    new = keys[keys % 389 != 3]  # ... 4 others absent after
    A_old = full[old][:, old].tocsr()
    A_new = full[new][:, new].tocsr()
    A_new.data *= 1.0 + 0.02 * np.cos(np.arange(A_new.nnz))
    A_new = ((A_new + A_new.T) * 0.5).tocsr()
    b = np.random.default_rng(11).normal(size=len(new))
    solver = LinearSolver("direct", rtol=1e-8)
    solver.solve(A_old, np.ones(len(old)), refresh=True, keys=old)
    x = solver.solve(A_new, b, keys=new)
    assert np.linalg.norm(A_new @ x - b) <= 1e-8 * np.linalg.norm(b)
    assert solver.stats.factorizations == 1
    assert 0 < solver.stats.cg_iterations <= solver.refresh_after
    # unknowns that only left: the Woodbury correction makes the kept factorization the exact
    # inverse of what remains, one CG iteration
    exact = LinearSolver("direct", rtol=1e-8)
    exact.solve(full, np.ones(n * n), refresh=True, keys=keys)
    remaining = keys[keys % 97 != 5]  # 17 left
    A_left = full[remaining][:, remaining].tocsr()
    x = exact.solve(A_left, b[: len(remaining)], keys=remaining)
    assert np.linalg.norm(A_left @ x - b[: len(remaining)]) <= 1e-8 * np.linalg.norm(b)
    assert exact.stats.factorizations == 1 and exact.stats.cg_iterations == 1
    fresh = LinearSolver("direct", rtol=1e-8)
    fresh.solve(A_old, np.ones(len(old)), refresh=True, keys=old)
    fresh.solve(A_new, b)  # no keys: another pattern is factorized
    assert fresh.stats.factorizations == 2 and fresh.stats.cg_iterations == 0


def test_linear_solver_solves_a_refreshed_matrix_directly():
    """A fresh factorization solves its own matrix exactly, and the same matrix again without
    CG or a new factorization (the implicit step's kept tangent); ``preconditioned_cg`` with no
    preconditioner reaches the residual asked."""
    n = 30
    lap = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    A = (sp.kronsum(lap, lap) + 0.01 * sp.eye(n * n)).tocsr()
    rng = np.random.default_rng(5)
    b, b2 = rng.normal(size=n * n), rng.normal(size=n * n)
    solver = LinearSolver("direct", rtol=1e-8)
    for rhs in (b, b2):
        x = solver.solve(A, rhs, refresh=rhs is b)
        assert np.linalg.norm(A @ x - rhs) <= 1e-12 * np.linalg.norm(rhs)
    assert solver.stats.factorizations == 1 and solver.stats.cg_iterations == 0
    A2 = A.copy()
    A2.data *= 1.0 + 0.02 * np.cos(np.arange(A2.nnz))
    A2 = ((A2 + A2.T) * 0.5).tocsr()
    x = solver.solve(A2, b, refresh=True)
    assert solver.stats.factorizations == 2 and solver.stats.cg_iterations == 0
    assert np.linalg.norm(A2 @ x - b) <= 1e-12 * np.linalg.norm(b)
    x, iterations, converged = preconditioned_cg(A, b, lambda r: r, 1e-8, 500)
    assert converged and 0 < iterations < 500
    assert np.linalg.norm(A @ x - b) <= 1e-8 * np.linalg.norm(b)


def test_direct_factor_solves_definite_and_indefinite_matrices_on_one_pattern():
    """The direct factorization solves an SPD matrix (Cholesky) and, refreshed on the same
    pattern, a symmetric indefinite one (the LDL^T fallback) and then an SPD one again, each to
    round-off."""
    n = 20
    lap = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    A = (sp.kronsum(lap, lap) + 0.01 * sp.eye(n * n)).tocsr()
    shifted = (A - 1.5 * sp.eye(n * n)).tocsr()  # eigenvalues on both sides of zero
    assert shifted.nnz == A.nnz
    b = np.random.default_rng(7).normal(size=n * n)
    factor = DirectFactor(A)
    for matrix, definite in ((A, True), (shifted, False), (2.0 * A, True)):
        factor.update(matrix)
        assert factor.cholesky == definite
        x = factor.solve(b)
        assert np.linalg.norm(matrix @ x - b) <= 1e-10 * np.linalg.norm(b)


def test_a_singular_newton_matrix_refuses_the_step(monkeypatch):
    """A matrix that neither Cholesky nor LDL^T factorizes (singular: a zero pivot) raises
    LinearSolveError, and the implicit step turns it into a NewtonError naming the step, so
    that an adaptive run redoes the step smaller and a fixed-step run stops through its guard
    path (failed_state.npz) rather than with qdldl's RuntimeError, as it did."""
    singular = sp.csr_matrix(np.array([[1.0, 1.0], [1.0, 1.0]]))
    definite = sp.csr_matrix(np.array([[2.0, 1.0], [1.0, 2.0]]))
    solver = LinearSolver("direct", 1e-6)
    solver.solve(definite, np.ones(2))
    with pytest.raises(LinearSolveError, match="neither Cholesky nor LDL"):
        solver.solve(singular, np.ones(2), refresh=True)
    # nothing of the failed factorization is kept: the next matrix is solved exactly
    assert np.allclose(definite @ solver.solve(definite, np.ones(2)), np.ones(2), rtol=1e-12)
    sim = _stepped_disc()
    internal = ImplicitStepper.internal

    def singular_tangent(self, system, v, tangent=True):
        f_int, stiffness = internal(self, system, v, tangent)
        if tangent:  # the step's matrix, fixed part plus tangent, of ones: rank one
            stiffness = 1.0 - system.fixed
        return f_int, stiffness

    monkeypatch.setattr(ImplicitStepper, "internal", singular_tangent)
    with pytest.raises(NewtonError, match=r"implicit step 1 .*linear solve failed"):
        advance_steps(sim, 1)


@pytest.mark.slow
def test_implicit_viscous_decay_beside_the_explicit():
    """The n = 2 mode of a Maxwell-fluid disc at R/h = 10 (cases/verification/viscous_decay.toml)
    at dt = 1 us, 151x the explicit step and 2x its capillary limit, against the explicit run of
    the same case side by side: the fitted rate within 2 % of the explicit one (backward Euler's
    first-order lag, dt times the rate 0.6 %, plus the fit) and within the explicit test's 20 % of
    Stokes' n gamma / (2 eta_N R) (the coarse grid's bias)."""
    explicit = ver.run(ver.load("viscous_decay", 10))
    implicit = ver.run(
        ver.load("viscous_decay", 10, deep_update(IMPLICIT, {"time": {"dt_s": 1e-6}}))
    )
    print("viscous decay explicit / implicit:", explicit.info, implicit.info)
    assert implicit.steps * 100 < explicit.steps
    ratio = implicit.info["rate_1_s"] / explicit.info["rate_1_s"]
    assert abs(ratio - 1.0) < 0.02
    assert abs(implicit.errors["decay_rate"]) < 0.2


@pytest.mark.slow
def test_implicit_laplace_pressure_at_a_large_step():
    """A disc of Maxwell fluid at rest carries gamma / R (cases/verification/laplace.toml, R/h =
    10) at dt = 5 us, 10x the capillary limit: the explicit test's 2 % on the pressure and its
    capillary-number bound 0.02 on the spurious currents."""
    vc = ver.load("laplace", 10, deep_update(IMPLICIT, {"time": {"dt_s": 5e-6}}))
    assert 5e-6 > 10 * time_step_limits(vc.case)["surface_tension"]
    r = ver.run(vc)
    print("implicit Laplace, R/h = 10:", r.errors, r.info)
    assert abs(r.errors["pressure"]) < 0.02
    assert r.errors["capillary_number"] < 0.02


@pytest.mark.parametrize(
    "sets, key",
    [
        (["solver.update=musl"], "solver.update"),
        (["surface_tension.method=csf"], "surface_tension.method"),
        (["time.linear_solver=lu"], "linear_solver"),
        (["time.newton_tolerance=0"], "newton_tolerance"),
    ],
)
def test_implicit_input_errors_name_the_key(sets, key):
    with pytest.raises(CaseError, match=key):
        load_case("power25W_coarse", ["time.integrator=implicit", *sets])


def test_implicit_step_takes_heat_substeps():
    """A step beyond the heat's limit takes the fewest substeps of at most heat_step_fraction of
    the thermal limit; "auto" is implicit_step_factor times the explicit "auto" step."""
    case = load_case("power25W_coarse", ["time.integrator=implicit", "time.dt_s=1e-4"])
    dt, limits = resolve_dt(case)
    assert dt == 1e-4 and limits == {}
    heat_step = case.time.heat_step_fraction * time_step_limits(case)["thermal"]
    n = resolve_heat_substeps(case, dt)
    assert dt / n <= heat_step < dt / (n - 1)
    auto = load_case("power25W_coarse", ["time.integrator=implicit"])
    explicit, _ = resolve_dt(load_case("power25W_coarse"))
    assert resolve_dt(auto)[0] == pytest.approx(auto.time.implicit_step_factor * explicit)


# slow (~15 s): backward-Euler heat's balance to round-off stays in default
# (tests/physics/test_process.py, test_top_loss_backward_euler_heat_balances_to_round_off)
@pytest.mark.slow
def test_implicit_heat_keeps_the_energy_balance():
    """The 25 W pair (coarse grid) over the laser pulse and after, implicit steps of 5 us (95x
    the explicit step; 10 us moves the collapsing point contact over half a cell in the first
    step, which the guard refuses) with their heat substeps: the enthalpy rise equals the laser
    energy to round-off (the guard's bound, 1e-6 in f64, checked at every monitor; measured
    ~1e-15) and the peak temperature follows the explicit run's within 1 % (the same heat
    update, on points that moved differently)."""
    sets = ["time.integrator=implicit", "time.dt_s=5e-6", "time.end_s=1e-4"]
    sim = Simulation(load_case("power25W_coarse", sets))
    assert sim.heat_substeps > 1
    for _ in range(20):
        advance_steps(sim, 1)
        mon = sim.monitors()
        assert abs(sim.energy_error(mon)) < 1e-12
    assert mon["laser_energy_J_per_m"] > 0
    assert mon["T_peak_C"] == pytest.approx(explicit_coarse_peak_C(), rel=0.01)


@pytest.mark.slow
def test_implicit_hopper_from_his_outline_at_ten_times_the_capillary_limit():
    """Hopper's coalescence from his outline at tau0 = 0.3 (cases/verification/hopper_shape.toml,
    R0/h = 20) at 10x the explicit capillary limit (510x the explicit step): r_n / R0 within the
    3 % of the issue at tau = 0.5, 1, 2, 3 (measured +2.7 / +0.2 / +0.0 / -0.2 %, the explicit run
    +3.15 / +0.26 / +0.08 / -0.14 %), area within 0.5 %."""
    limit = time_step_limits(ver.load("hopper_shape", 20).case)["surface_tension"]
    r = ver.run(ver.load("hopper_shape", 20, deep_update(IMPLICIT, {"time": {"dt_s": 10 * limit}})))
    print("implicit Hopper, 10x:", r.errors)
    for tau in (0.5, 1, 2, 3):
        assert abs(r.errors[f"neck_tau{tau:g}"]) < 0.03
    assert abs(r.errors["area"]) < 0.005


@pytest.mark.slow
def test_the_velocity_penalty_steadies_a_second_of_sintering_at_a_tight_tolerance():
    """hopper_pa12 at R0/h = 20 and time.newton_tolerance = 1e-8: without the penalty light
    nodes at the neck's edges run away (Newton fails near 0.7 s, or the area drifts 9 %;
    docs/record/implicit.md); with time.implicit_velocity_penalty = 1e-6 the run completes, r_n / R0
    within the issue's 3 % of Hopper at tau = 0.5 and 1 and the area within 0.5 %, as at the
    default tolerance without it."""
    sets = {"time": {"newton_tolerance": 1e-8, "implicit_velocity_penalty": 1e-6}}
    r = ver.run(ver.load("hopper_pa12", 20, sets))
    print("penalised, tolerance 1e-8:", r.errors)
    for tau in (0.5, 1):
        assert abs(r.errors[f"neck_tau{tau:g}"]) < 0.03
    assert abs(r.errors["area"]) < 0.005


@pytest.mark.slow
def test_a_second_of_sintering_against_hopper():
    """cases/verification/hopper_pa12.toml at R0/h = 10: the paper's pair as a zero-yield melt of
    Table 3's viscosity at 180 C coalesces for a second (tau = 1) in 10 ms steps; r_n / R0
    within the issue's 3 % of Hopper at tau = 0.5 and 1 (measured -2.25 / -2.23 %), area within
    0.5 %; every step one Newton iteration (the flow is linear and its tangent exact from
    rest)."""
    r = ver.run(ver.load("hopper_pa12", 10))
    print("a second of sintering:", r.errors, r.info)
    assert r.steps <= 120
    for tau in (0.5, 1):
        assert abs(r.errors[f"neck_tau{tau:g}"]) < 0.03
    assert abs(r.errors["area"]) < 0.005
