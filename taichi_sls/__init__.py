"""taichi_sls: particle-scale MPM simulation of selective laser sintering of polymer powder
(Maeshima, Kim, Zohdi 2020, read as docs/model.md fixes it).

The Python API (README, "Python API")::

    import taichi_sls as sls
    case = sls.load_case("power25W", ["lasers.0.power_W=15"])  # a file or a bundled case
    summary = sls.run_case(case, "out/p15")   # every output, as the command line writes it
    sim = sls.Simulation(case)                # or step it yourself
    sim.advance_to(5e-5); print(sim.monitors()["contact_line_um"])

Names are imported on first use, so ``import taichi_sls`` loads neither Taichi nor Dask.
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.2.0"

_API = {
    "Case": "taichi_sls.config",
    "CaseError": "taichi_sls.config",
    "load_case": "taichi_sls.config",
    "case_from_dict": "taichi_sls.config",
    "bundled_cases": "taichi_sls.config",
    "Simulation": "taichi_sls.solver.simulation",
    "SimulationError": "taichi_sls.solver.guard",
    "run_case": "taichi_sls.jobs.case_run",
    "read_series": "taichi_sls.io.series",
}
__all__ = sorted(_API)


def __getattr__(name: str) -> Any:
    if name in _API:
        return getattr(importlib.import_module(_API[name]), name)
    raise AttributeError(f"module 'taichi_sls' has no attribute {name!r}")
