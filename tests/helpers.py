"""Shared test helpers: small cases built from dicts, compiled without Taichi's advanced
optimisation (about 10x faster to compile; the tests measure accuracy, not speed)."""

import functools
import os
import subprocess
import sys
from pathlib import Path

from taichi_sls.config import case_from_dict, deep_update

PAPER_SCENE = {
    "domain": {"width_um": 80.0, "height_um": 48.0},
    "bodies": [
        {"shape": "disc", "center_um": [20.0, 20.0], "radius_um": 20.0},
        {"shape": "disc", "center_um": [60.0, 20.0], "radius_um": 20.0},
    ],
}

__all__ = [
    "PAPER_SCENE",
    "advance_steps",
    "deep_update",
    "guard_message",
    "make_case",
    "neck_and_kinetic_energy",
]


def make_case(data: dict):
    """A validated Case from raw data, with fast compilation unless the data says otherwise."""
    data = deep_update({"solver": {"optimize": False}}, data)
    return case_from_dict(data)


def material_field(m):
    """A one-element Taichi struct field of material ``m`` (after ti.init), as kernels see it."""
    import numpy as np

    from taichi_sls.physics.materials import material_struct
    from taichi_sls.solver.params import material_values

    f = material_struct().field(shape=1)
    f.from_numpy({k: np.array([v]) for k, v in material_values(m, 0.0).items()})
    return f


def advance_steps(sim, n: int) -> None:
    """n steps of a fixed-step simulation, as ``Simulation.advance_to`` takes them (the whole
    steps nearest to the time; an adaptive one lands on t + n dt)."""
    sim.advance_to(sim.t + n * sim.dt)


def neck_and_kinetic_energy(sim, every_s: float, frames: int) -> tuple[list, list]:
    """The contact line (um) and kinetic energy (J/m) after each of ``frames`` advances of
    ``every_s``, printed for the test log."""
    n = round(every_s / sim.dt)
    lines, ke = [], []
    for _ in range(frames):
        advance_steps(sim, n)
        m = sim.monitors()
        lines.append(m["contact_line_um"])
        ke.append(m["kinetic_energy_J_per_m"])
    print("contact line (um):", [round(c, 3) for c in lines], "KE:", [f"{k:.1e}" for k in ke])
    return lines, ke


def guard_message(sim, frames: int = 1, steps: int = 0) -> str | None:
    """The guard's message at the first of ``frames`` checks (each after ``steps`` steps) that
    stops the run, or None if none does."""
    from taichi_sls.solver.guard import SimulationError

    for _ in range(frames):
        advance_steps(sim, steps)
        try:
            sim.monitors()
        except SimulationError as e:
            return str(e)
    return None


_SHARED: dict = {}


def shared(key: str, build):
    """``build()`` once while the Taichi program it ran in lives: a Simulation whose kernels
    several tests use compiles them once (every ``ti.init``, so every new Simulation, sends each
    kernel through Taichi's front end again). A test between them that starts Taichi afresh
    frees the fields, and the next call builds anew. Callers restore what a test changes."""
    from taichi.lang import impl

    hit = _SHARED.get(key)
    if hit is None or hit[0] is not impl.get_runtime():
        value = build()
        hit = _SHARED[key] = (impl.get_runtime(), value)
    return hit[1]


@functools.cache
def explicit_coarse_peak_C() -> float:
    """The peak temperature (C) of the coarse 25 W pair's explicit run to 0.1 ms (its pulse ends
    at 20 us), which implicit runs of the case are held to: run once per test process. It
    starts Taichi afresh: call it after the test's own simulation is read."""
    from taichi_sls.config import load_case
    from taichi_sls.solver.simulation import Simulation

    ref = Simulation(load_case("power25W_coarse", ["time.end_s=1e-4"]))
    ref.advance_to(1e-4)
    return ref.monitors()["T_peak_C"]


def run_command(module: list[str], case_path, out) -> subprocess.CompletedProcess:
    """``python -m <module> <case> --out <out>`` as a user starts it, this checkout on the path;
    its stdout and stderr as text."""
    root = Path(__file__).resolve().parents[1]
    return subprocess.run(
        [sys.executable, "-m", *module, str(case_path), "--out", str(out)],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(root)},
        timeout=120,
    )


def grid_rows(nodes_per_axis: int):
    """An SPD matrix with the implicit step's 3D pattern: 3 components a node, each node
    coupled to the 5 x 5 x 5 nodes around it (random entries, diagonally dominant)."""
    import numpy as np
    import scipy.sparse as sp

    band = sp.diags([1.0] * 5, [-2, -1, 0, 1, 2], shape=(nodes_per_axis,) * 2)
    node = sp.kron(sp.kron(band, band), band)
    A = sp.kron(node, np.ones((3, 3))).tocsr()
    A.data = np.random.default_rng(0).random(A.nnz)
    A = (A + A.T + 500.0 * sp.eye(A.shape[0])).tocsr()  # diagonally dominant: SPD
    A.sort_indices()
    return A
