"""The 3x3 symmetric eigen-decomposition of the finite-strain update in 3D
(physics/small_matrix.py, symmetric_eigen): the Hencky strain log(b) / 2 of an elastic stretch
b ~ I read to round-off, and the implicit step's Newton converging on it. Taichi's ti.sym_eig
(Cardano's closed form) lost the small strain b - I to cancellation (log b off by 25-100 % at
|b - I| = 1e-5..1e-2), so the stress jumped with round-off changes of the velocity and the 3D
pair's Newton stalled at 5e-2 of its force scale (cases/pair3d_25W.toml,
docs/record/paper_reading.md)."""

import numpy as np
import pytest
from helpers import make_case

from taichi_sls.backend import ti
from taichi_sls.physics.small_matrix import symmetric_eigen
from taichi_sls.solver.simulation import Simulation, init_taichi

N = 500


@ti.kernel
def _decompose(b: ti.types.ndarray(), ev: ti.types.ndarray(), q: ti.types.ndarray()):
    for n in range(b.shape[0]):
        a = ti.Matrix.zero(float, 3, 3)
        for i, j in ti.static(ti.ndrange(3, 3)):
            a[i, j] = b[n, i, j]
        e, v = symmetric_eigen(a)
        for i in ti.static(range(3)):
            ev[n, i] = e[i]
            for j in ti.static(range(3)):
                q[n, i, j] = v[i, j]


def _hencky(ev: np.ndarray, q: np.ndarray) -> np.ndarray:
    return np.einsum("nij,nj,nkj->nik", q, 0.5 * np.log(ev), q)


@pytest.mark.parametrize("size", [1e-2, 1e-4, 1e-6, 0.0])
def test_the_hencky_strain_of_a_near_identity_stretch_is_read_to_round_off(size):
    """b = I + E, E random symmetric of size 1e-2..1e-6, with repeated eigenvalues among them
    (b = I, and uniaxial stretches): log(b) / 2 from symmetric_eigen within 1e-13 of numpy's
    (LAPACK) absolutely, i.e. to round-off of b's unit entries, whatever the eigenvalues' gaps;
    the eigenvectors orthonormal to 1e-14."""
    init_taichi(optimize=False)
    rng = np.random.default_rng(3)
    e = rng.normal(size=(N, 3, 3)) * size
    b = np.eye(3) + 0.5 * (e + e.transpose(0, 2, 1))
    axis = rng.normal(size=(N // 5, 3))
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    b[: N // 5] = np.eye(3) + size * np.einsum("ni,nj->nij", axis, axis)  # two equal ones
    ev, q = np.empty((N, 3)), np.empty((N, 3, 3))
    _decompose(b, ev, q)
    w, v = np.linalg.eigh(b)
    assert np.abs(_hencky(ev, q) - _hencky(w, v)).max() < 1e-13
    assert np.abs(np.einsum("nki,nkj->nij", q, q) - np.eye(3)).max() < 1e-14


def test_a_3d_finite_strain_implicit_step_of_a_fillet_pair_converges():
    """The first implicit step of a solid fillet pair at 140 C (R = 8 um, h = 2 um, surface
    tension pulling its fillet open) at 50 explicit steps, finite strain: Newton reaches its
    tolerance 1e-6 in at most 8 iterations (quadratic from the second on: the pair3d_25W case
    took 4; with ti.sym_eig it stalled at 5e-2 and no step converged)."""
    data = {
        "grid": {"spacing_um": 2.0},
        "domain": {"dim": 3, "width_um": 40.0, "height_um": 24.0, "depth_um": 24.0},
        "bodies": [
            {"shape": "disc", "center_um": [12.0, 12.0, 12.0], "radius_um": 8.0},
            {"shape": "disc", "center_um": [28.0, 12.0, 12.0], "radius_um": 8.0},
        ],
        "contact": {"initial": "fillet", "fillet_radius_um": 2.0},
        "solver": {"strain": "finite"},
        "time": {"dt_s": "auto", "integrator": "implicit"},
    }
    sim = Simulation(make_case(data))
    sim.implicit.step()
    assert sim.implicit.last.unknowns > 0
    assert sim.implicit.last.iterations <= 8, sim.implicit.last
