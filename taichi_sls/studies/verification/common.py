"""Shared pieces of the verification runners: the result record and sampling helpers."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ...config import Case, Material


@dataclass
class Result:
    """One verification run: error measures (dimensionless unless the name says otherwise)."""

    case: str
    h_um: float
    dt_s: float
    errors: dict[str, float]
    wall_s: float
    steps: int
    transfer: str
    precision: str
    info: dict[str, float] = field(default_factory=dict)
    method: str = ""  # the capillary force, where surface tension is on


def material(case: Case) -> Material:
    return case.materials[case.bodies[0].material]


def result(case: Case, sim, errors: dict[str, float], t0: float, **info: float) -> Result:
    return Result(
        case=case.case.name,
        h_um=case.grid.spacing_um,
        dt_s=sim.dt,
        errors=errors,
        wall_s=time.perf_counter() - t0,
        steps=sim.steps,
        transfer=transfer_label(case),
        precision=case.solver.precision,
        info=dict(info),
        method=case.surface_tension.method if case.physics.surface_tension else "",
    )


def transfer_label(case: Case) -> str:
    s = case.solver
    return f"pic_flip {s.flip_ratio:g}" if s.transfer == "pic_flip" else s.transfer


def samples(sim, n_out: int, end_s: float, read: Callable[[], float]) -> tuple:
    """Advance to ``end_s`` in ``n_out`` equal chunks of whole steps (of the first step, with
    an adaptive one); read after each."""
    per = max(1, int(round(end_s / n_out / sim.dt)))
    ts, vals = [sim.t], [read()]
    for _ in range(n_out):
        sim.advance_to(sim.t + per * sim.dt)
        ts.append(sim.t)
        vals.append(read())
    return np.array(ts), np.array(vals)


def run_to(sim, duration_s: float) -> None:
    """Advance by ``duration_s`` in whole steps (of the first step, with an adaptive one)."""
    sim.advance_to(sim.t + int(round(duration_s / sim.dt)) * sim.dt)
