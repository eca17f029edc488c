"""The verdict's baseline: the neck the same pair reaches without the laser.

A soft solid with a surface energy adheres: two touching discs of the paper's solid (E = 1e5 Pa,
a yield strain of order one) zip their contact elastically until the adhesion balances the
stored energy (the 2D JKR contact of cylinders), also when no laser ever heats them. Growth by
melting is growth beyond that, so the fusion rule measures the refrozen neck against the neck of
the same case run unheated for ``fusion.baseline_s`` (``fusion.baseline = "unheated"``).
"""

from __future__ import annotations

import math

from ..config import Case
from ..solver.guard import SimulationError
from ..solver.simulation import Simulation
from .observers.record import Record
from .run_loop import Pacer, StopRequests, run_frames


def unheated_case(case: Case) -> Case:
    """The case with every laser absorbing nothing, run for ``fusion.baseline_s``. The lasers
    stay (absorptivity 0) so that the step compiles exactly as the heated run's: a zero power
    would compile the laser out."""
    lasers = [las.model_copy(update={"absorptivity": 0.0}) for las in case.lasers]
    return case.model_copy(
        update={
            "lasers": lasers,
            "time": case.time.model_copy(update={"stop": "end", "end_s": case.fusion.baseline_s}),
        }
    )


def needs_baseline(case: Case) -> bool:
    """The unheated run is made where a verdict will be given against it: a run to
    solidification in which a laser heats, with the capillary force acting on moving bodies."""
    ph = case.physics
    return (
        case.fusion.baseline == "unheated"
        and case.time.stop == "solidified"
        and any(las.power_W > 0 and las.absorptivity > 0 for las in case.lasers)
        and ph.mechanics
        and ph.surface_tension
        and len(case.bodies) == 2  # more bodies: per contact against the initial necks
    )


def unheated_neck_um(case: Case) -> float:
    """The first contact's neck (um) at the end of the unheated run; NaN if it fails. A run of
    the loop with one frame, at ``fusion.baseline_s`` (fixed steps: the whole steps that reach
    it)."""
    sim = Simulation(unheated_case(case))
    end = case.fusion.baseline_s
    if sim.adaptive is None:
        end = math.ceil(end / sim.dt - 1e-9) * sim.dt
    record = Record()
    try:
        run_frames(Pacer(sim, StopRequests()), [(1, end)], [record])
    except SimulationError:  # the guard stopped it: the baseline is unknown
        return math.nan
    return record.last["contact_line_um"]
