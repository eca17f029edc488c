"""An experiment, not part of the package: hopper_pa12 with a second-difference penalty on the
grid velocity added to the implicit step's matrix (and so to its residual),

    eps * eta * sum over unknowns and axes of (v[i - e] - 2 v[i] + v[i + e])^2,

zero on any linear velocity field, to test whether the light nodes' near-null modes are what
blows up the R0/h = 20 run at time.newton_tolerance = 1e-8 (docs/implicit.md, "Open").

    python docs/experiments/light_node_penalty.py R0_OVER_H NEWTON_TOLERANCE EPS
"""

import sys
import time

import numpy as np
import scipy.sparse as sp

from taichi_sls.solver import implicit, implicit_system
from taichi_sls.studies import verification

MELT_VISCOSITY_PA_S = 3558.0  # cases/verification/hopper_pa12.toml


def second_differences(dof_node: np.ndarray) -> sp.csr_matrix:
    """The sum of w w^T, w = (1, -2, 1), over (i - e, i, i + e) triples of unknowns of one
    component."""
    dim = dof_node.shape[1] - 1
    index = {tuple(r): k for k, r in enumerate(dof_node.tolist())}
    rows, cols, vals = [], [], []
    for k, node in enumerate(dof_node.tolist()):
        for axis in range(dim):
            below, above = list(node), list(node)
            below[axis] -= 1
            above[axis] += 1
            kb, ka = index.get(tuple(below)), index.get(tuple(above))
            if kb is None or ka is None:
                continue
            triple = ((kb, 1.0), (k, -2.0), (ka, 1.0))
            for i, wi in triple:
                for j, wj in triple:
                    rows.append(i)
                    cols.append(j)
                    vals.append(wi * wj)
    n = len(dof_node)
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))


def main() -> None:
    r0_over_h, tolerance, eps = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
    prepare = implicit.ImplicitStepper.prepare
    matrix = implicit_system.GridSystem.matrix

    def penalised_prepare(self):
        system = prepare(self)
        system.penalty = eps * MELT_VISCOSITY_PA_S * second_differences(system.dof_node)
        return system

    def penalised_matrix(self, values):
        penalty = getattr(self, "penalty", None)
        plain = matrix(self, values)
        return plain if penalty is None else (plain + penalty).tocsr()

    implicit.ImplicitStepper.prepare = penalised_prepare
    implicit_system.GridSystem.matrix = penalised_matrix
    start = time.time()
    case = verification.load("hopper_pa12", r0_over_h, {"time": {"newton_tolerance": tolerance}})
    try:
        result = verification.run(case)
        errors = {k: f"{100 * v:+.2f} %" for k, v in result.errors.items()}
        wall = f"{time.time() - start:.0f} s"
        print(r0_over_h, tolerance, eps, result.steps, "steps", errors, wall)
    except Exception as e:  # noqa: BLE001 - the experiment reports how the run ended
        print(r0_over_h, tolerance, eps, "failed:", str(e)[:200])


if __name__ == "__main__":
    main()
