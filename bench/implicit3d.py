"""The implicit step in 3D, its cost against the unknowns: ``taichi-sls bench implicit3d
[--quick] [--steps N] [--dt S] [--solvers ...] [--spacings ...] [--out renders]``.

Two molten PA12 spheres, R = 20 um, touching at a point in a 120 x 60 x 60 um box (surface
tension on, no gravity), implicit steps at the "auto" step (``--dt``: a fixed one; 1e-2 is a
layer's hold, where the viscous stiffness outweighs the inertia 1e8 times), at h = 4, 3 and
2.5 um (``--quick``: 4 only), each with the direct solver (``direct``: its default library,
MKL PARDISO where installed; ``direct-cholmod``: CHOLMOD), AMG-CG (pyamg's smoothed
aggregation with the rigid-body modes) and the matrix-free step (CG with the grid multigrid,
solver/multigrid.py), the direct and matrix-free ones also with their rows (the matrix-free
step's: the fixed part's alone) stored by blocks (``time.implicit_rows = "blocks"``: the
solver's name with "-blocks") beside dense ones. The process material
(``pa12_process``) with ``--dt``, the paper's PA12 without. After one step (which compiles),
``--steps`` steps are timed: the wall time per step and per Newton linear solve, Newton
iterations, CG iterations per solve (0: the factorization alone), the unknowns, and the
implicit grid fields' memory (the rows in the blocks they were written in, the rest over the
grid) per grid node, per active node (one with unknowns) and per point, and the host's arrays
of the last step per point (the fixed part's gathered rows and CSR matrix, the assembled
tangent or the multigrid's levels).
Writes ``implicit3d.csv`` and ``implicit3d.json`` and prints the table (docs/record/implicit.md, "In
3D")."""

import argparse
import json
import time
from pathlib import Path

import numpy as np

from taichi_sls.config import case_from_dict
from taichi_sls.io.atomic import atomic_write_text, write_rows
from taichi_sls.solver import linear_solve
from taichi_sls.solver.fields import allocated_row_nodes
from taichi_sls.solver.multigrid import MatrixFreeSolver
from taichi_sls.solver.simulation import Simulation

SPACINGS_UM = (4.0, 3.0, 2.5)
COLUMNS = [
    "h_um",
    "solver",
    "direct_solver",
    "rows",
    "points",
    "unknowns",
    "steps",
    "dt_s",
    "wall_per_step_s",
    "wall_per_solve_s",
    "newton_iterations_per_step",
    "cg_iterations_per_solve",
    "bytes_per_node",
    "bytes_per_active_node",
    "bytes_per_point",
    "host_bytes_per_point",
]
SOLVERS = (
    "direct",
    "direct-cholmod",
    "direct-blocks",
    "amg",
    "matrix_free",
    "matrix_free-blocks",
)
LIBRARIES = ("cholmod", "pardiso")  # a direct solver's suffix naming its library


def pair_case(
    h_um: float,
    solver: str,
    rows: str = "dense",
    dt_s: float | None = None,
    library: str = "auto",
) -> dict:
    """The sphere pair at spacing h_um with time.linear_solver = solver, time.implicit_rows
    = rows and time.direct_solver = library; ``dt_s``: a fixed step, with the process
    material."""
    spheres = [
        {"center_um": [x, 30.0, 30.0], "radius_um": 20.0, "temperature_C": 200.0}
        for x in (40.0, 80.0)
    ]
    return {
        "grid": {"spacing_um": h_um},
        "domain": {"dim": 3, "width_um": 120.0, "height_um": 60.0, "depth_um": 60.0},
        "bodies": spheres,
        "physics": {"thermal": False, "gravity_m_s2": [0.0, 0.0, 0.0]},
        "time": _time(solver, rows, library) | ({} if dt_s is None else {"dt_s": dt_s}),
        "output": {"frames": 1},
        **({"materials": {"PA12": {"preset": "pa12_process"}}} if dt_s else {}),
    }


def _time(solver: str, rows: str, library: str) -> dict:
    return {
        "integrator": "implicit",
        "linear_solver": solver,
        "implicit_rows": rows,
        "direct_solver": library,
        "end_s": 1.0,
    }


def _grid_bytes(sim: Simulation) -> int:
    """The implicit step's grid fields in bytes: the rows where they hold storage (in 3D the
    blocks written, solver/fields.py ``row_field``), and the force and numbering over the
    grid."""
    imp, dim = sim.state.implicit, sim.state.cfg.dim
    total = 0
    for f in (imp.fixed, imp.tangent):
        total += 8 * allocated_row_nodes(f, dim) * int(np.prod(f.shape[dim:]))
    return total + _grid_nodes(sim) * dim * (8 + 4 + 4)  # internal force, free, dof


def _grid_nodes(sim: Simulation) -> int:
    return int(np.prod(sim.state.implicit.free.shape))


def measure(
    h_um: float,
    solver: str,
    steps: int,
    rows: str = "dense",
    dt_s: float | None = None,
    library: str = "auto",
) -> dict:
    sim = Simulation(case_from_dict(pair_case(h_um, solver, rows, dt_s, library)))
    sim.advance_to(sim.dt)  # one step: compiles the step's kernels
    spent = {"s": 0.0, "n": 0}
    kinds = (linear_solve.LinearSolver, MatrixFreeSolver)
    solves = [k.solve for k in kinds]
    host = {"bytes": 0}

    def timed(solve):
        def run(self, A, b, *args, **kwargs):
            t0 = time.perf_counter()
            try:
                return solve(self, A, b, *args, **kwargs)
            finally:
                spent["s"] += time.perf_counter() - t0
                spent["n"] += 1
                host["bytes"] = max(host["bytes"], _host_bytes(sim, A))

        return run

    for kind, solve in zip(kinds, solves, strict=True):
        kind.solve = timed(solve)
    try:
        newton0 = sim.implicit.newton_total
        cg0 = sim.implicit.linear.stats.cg_iterations
        t0 = time.perf_counter()
        sim.advance_to(sim.t + steps * sim.dt)
        wall = time.perf_counter() - t0
    finally:
        for kind, solve in zip(kinds, solves, strict=True):
            kind.solve = solve
    dim = sim.state.cfg.dim
    grid = _grid_bytes(sim)
    nodes = _grid_nodes(sim)
    unknowns = sim.implicit.last.unknowns
    active = int((sim.state.implicit.free.to_numpy().reshape(-1, dim).max(axis=1) > 0).sum())
    return {
        "h_um": h_um,
        "rows": rows,
        "solver": sim.implicit.last.solver,
        "direct_solver": sim.implicit.linear.backend
        if sim.implicit.last.solver == "direct"
        else "",
        "points": sim.scene.n_points,
        "unknowns": unknowns,
        "steps": steps,
        "dt_s": float(sim.state.scalars.dt[None]),
        "wall_per_step_s": round(wall / steps, 3),
        "wall_per_solve_s": round(spent["s"] / max(spent["n"], 1), 4),
        "newton_iterations_per_step": round((sim.implicit.newton_total - newton0) / steps, 2),
        "cg_iterations_per_solve": round(
            (sim.implicit.linear.stats.cg_iterations - cg0) / max(spent["n"], 1), 1
        ),
        "bytes_per_node": round(grid / nodes),
        "bytes_per_active_node": round(grid / max(active, 1)),
        "bytes_per_point": round(grid / sim.scene.n_points),
        "host_bytes_per_point": round(host["bytes"] / sim.scene.n_points),
    }


def _host_bytes(sim: Simulation, A) -> int:
    """The host's arrays of the step being solved: the Newton matrix (assembled) or the
    multigrid's levels (matrix-free)."""
    linear = sim.implicit.linear
    if isinstance(linear, MatrixFreeSolver):
        return linear.multigrid.nbytes  # the fixed part stays in the grid's rows
    return A.data.nbytes + A.indices.nbytes + A.indptr.nbytes


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("implicit3d", help="the 3D implicit step's cost against its unknowns")
    ap.add_argument("--out", default="renders", help="folder for implicit3d.csv and .json")
    ap.add_argument("--quick", action="store_true", help="h = 4 um only")
    ap.add_argument("--steps", type=int, default=3, help="timed steps per row")
    ap.add_argument("--dt", type=float, default=None, help="a fixed step (s); default auto")
    ap.add_argument("--solvers", nargs="+", choices=SOLVERS, default=list(SOLVERS))
    ap.add_argument("--spacings", nargs="+", type=float, default=None, help="h (um)")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    spacings = args.spacings or (SPACINGS_UM[:1] if args.quick else SPACINGS_UM)
    for h in spacings:
        for name in args.solvers:
            solver, _, suffix = name.partition("-")
            library = suffix if suffix in LIBRARIES else "auto"
            storage = "dense" if suffix in ("", *LIBRARIES) else suffix
            rows.append(measure(h, solver, args.steps, storage, args.dt, library))
            r = rows[-1]
            print(
                f"h {r['h_um']:5.2f} um {r['solver']:6s} {r['direct_solver']:7s} {r['rows']:6s} "
                f"{r['unknowns']:7d} unknowns "
                f"{r['wall_per_step_s']:7.2f} s/step {r['wall_per_solve_s']:7.3f} s/solve "
                f"{r['newton_iterations_per_step']:5.2f} Newton/step "
                f"{r['cg_iterations_per_solve']:5.1f} CG/solve  "
                f"{r['bytes_per_node']} B/node {r['bytes_per_active_node']} B/active node "
                f"{r['bytes_per_point']} B/point {r['host_bytes_per_point']} B/point on the host",
                flush=True,
            )
            # after every row: a long run stopped later keeps the rows measured
            write_rows(out / "implicit3d.csv", rows, COLUMNS)
            atomic_write_text(out / "implicit3d.json", json.dumps(rows, indent=1))
    return 0
