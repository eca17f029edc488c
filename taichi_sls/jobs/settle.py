"""``contact.settle``: the run starts from the bodies' own adhesive equilibrium.

A powder held at its bed temperature has had its particles touching for seconds before the laser
reaches them: a soft solid with a surface energy has zipped its contacts open elastically until
the adhesion balances the stored energy (jobs/unheated.py), and nothing rings any more. Seeded
discs (with or without a fillet) are not at that equilibrium, so a laser switched on at once
melts a contact that still swings, and the neck it leaves carries that swing
(docs/record/convergence.md, "The laser meets the settled pair"). Here the scene first steps with
every laser absorbing nothing until the stop rule of a case no laser heats holds (jobs/schedule.py,
``settled``: the kinetic energy quiet and the first contact's neck held over the frames before),
checked on the output's log-spaced frame times; then the clock restarts at t = 0 from that state
(``Simulation.restart_clock``) and the lasers act on their own times.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from ..config import Case
from ..solver import struct_copy
from ..solver.guard import SimulationError
from ..solver.params import laser_arrays
from ..solver.simulation import Simulation
from .observers.stop_rule import StopRule
from .run_loop import Frame, Observer, Pacer, StopRequests, run_frames
from .schedule import frame_times
from .unheated import unheated_case


def settle_rule_case(case: Case) -> Case:
    """The case whose stop rule the settling runs under: every laser absorbing nothing, to
    solidification (so ``settled`` reads it as a case no laser heats) within ``time.max_s``."""
    unheated = unheated_case(case)
    return unheated.model_copy(update={"time": case.time.model_copy(update={"stop": "solidified"})})


def lasers_absorb(sim: Simulation, absorb: bool) -> None:
    """Every beam's power on (as the case says) or off, in place: the step is not recompiled."""
    if not sim.state.cfg.n_lasers:
        return
    beams = laser_arrays(sim.case)
    if not absorb:
        beams["amplitude_W_m3"] = np.zeros_like(beams["amplitude_W_m3"])
    struct_copy.from_numpy(sim.state.lasers, beams)


class SettleLog(Observer):
    """Prints each frame of the settling (with ``progress``)."""

    def __init__(self, progress: bool) -> None:
        self.progress = progress

    def frame(self, frame: Frame) -> None:
        m = frame.monitors
        if self.progress and frame.index > 0:
            print(
                f"settling: t = {frame.sim.t * 1e3:.4g} ms, neck {m['contact_line_um']:.4g} um, "
                f"kinetic energy {m['kinetic_ratio']:.2g} of the surface energy",
                file=sys.stderr,
            )


def settle(
    sim: Simulation, case: Case, progress: bool = True, stops: StopRequests | None = None
) -> dict[str, float]:
    """Step ``sim`` unheated until its bodies have settled, then restart its clock at t = 0.
    Returns the record of the summary's ``settle``: the time it took (s), the steps, the first
    contact's neck (um) and the kinetic ratio at the end, the wall time (s). Raises
    SimulationError if the bodies have not settled by ``time.max_s``. A run of the loop with
    the settle rule's observers; ``stops``: the run's stop requests."""
    rule = settle_rule_case(case)
    wall0 = time.perf_counter()
    lasers_absorb(sim, False)
    if case.contact.settle_steps == "implicit" and sim.handover is not None:
        sim.handover.hand_over(sim.t)  # adaptive implicit steps from the start
    stop = StopRule(rule)
    times = [(0, sim.t), *enumerate(frame_times(rule, sim.dt), 1)]
    pacer = Pacer(sim, stops or StopRequests())
    done = run_frames(pacer, times, [stop, SettleLog(progress)])
    last = stop.last
    if not done:
        raise SimulationError(
            f"contact.settle: the bodies had not settled by time.max_s = {case.time.max_s:g} s "
            f"({_unsettled_cause(last, case)})"
        )
    record = {
        "time_s": sim.t,
        "steps": sim.steps,
        "neck_um": last["contact_line_um"],
        "kinetic_ratio": last["kinetic_ratio"],
        "wall_s": time.perf_counter() - wall0,
    }
    print(
        f"{case.case.name}: settled unheated in {record['time_s'] * 1e3:.3g} ms "
        f"({record['steps']} steps, {record['wall_s']:.1f} s), neck {record['neck_um']:.4g} um: "
        "t = 0 from here",
        file=sys.stderr,
    )
    lasers_absorb(sim, True)
    sim.restart_clock()
    return record


def _unsettled_cause(last: dict[str, float], case: Case) -> str:
    """Why the settle rule did not hold at the last frame, and what to change: a scene at or
    above its crystallisation temperature (a bed at its melting onset) is never solid, however
    still it is; otherwise its kinetic energy has not decayed within the time allowed."""
    solid_below = min(m.crystallization_C for m in case.materials.values())
    if last["molten_fraction"] > 0.0 or last["T_max_C"] > solid_below:
        return (
            f"not solid: peak {last['T_max_C']:.2f} C against crystallisation at "
            f"{solid_below:g} C, molten fraction {last['molten_fraction']:.2g}; a scene at or "
            "above its crystallisation temperature never reads settled: start it cooler or set "
            "contact.settle = false"
        )
    return (
        f"kinetic ratio {last['kinetic_ratio']:.2g}, time.settled_kinetic_fraction "
        f"{case.time.settled_kinetic_fraction:g}; raise time.max_s or set contact.settle = false"
    )
