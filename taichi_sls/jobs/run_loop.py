"""The loop every run is: advance to the next frame time, hand the frame to each observer.

The main job, the settling before it and the unheated baseline are this loop with different
observers (jobs/observers/). Steps are taken by ``Simulation.advance_to`` alone. Fixed steps go
in chunks of bounded wall time (``CHUNK_WALL_S``), so that Ctrl-C or SIGTERM, held while a
chunk runs (a Taichi kernel cannot be stopped inside), ends the run at the next chunk with its
steps counted. Adaptive steps land on the frame time itself (a nearer target would change
them), so a signal stops them where it finds them and the steps of that frame go uncounted.
"""

from __future__ import annotations

import contextlib
import math
import signal
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..solver.simulation import Simulation

CHUNK_WALL_S = 0.25  # the wall time one chunk of fixed steps aims at
FIRST_CHUNK = 1  # steps of the first chunk, before the pace is known
CHUNK_GROWTH = 4  # a chunk at most this many times the last one


def per_metre_to_joules(column: str) -> str:
    """A 2D energy key (``..._J_per_m``, per metre of depth) named for 3D (``..._J``)."""
    return column.removesuffix("_J_per_m") + "_J" if column.endswith("_J_per_m") else column


def named_monitors(sim: Simulation, guard: bool = True) -> dict[str, float]:
    """``sim.monitors()`` with keys that name their units in the run's dimension: in 3D the
    energies are in J, not J per metre of depth."""
    mon = sim.monitors(guard=guard)
    if sim.case.domain.dim == 2:
        return mon
    return {per_metre_to_joules(k): v for k, v in mon.items()}


@dataclass
class Frame:
    """One output frame: its index, the simulation at its time and its monitors (observers
    earlier in the list may add columns: a bed's). ``failed``: the state the guard refused,
    read once for the record."""

    index: int
    sim: Simulation
    monitors: dict[str, float]
    failed: bool = False


@dataclass
class RunEnd:
    """How a run ended, handed to each observer's ``finish``: the status (complete, max_time,
    failed, interrupted), the summary the observers add to, the warnings list, and the stop
    requests (a signal during the finish makes the rest of it skip its drawing)."""

    status: str
    sim: Simulation
    summary: dict[str, Any]
    warnings: list[str]
    stops: StopRequests = field(repr=False)

    @property
    def interrupted(self) -> bool:
        """Stopped by a signal (now, or earlier): draw nothing expensive, keep what is written."""
        return self.status == "interrupted" or self.stops.pending


class Observer:
    """What a run hands its frames to. ``key`` names its part of a checkpoint; an observer
    with ``records_failed_frame`` also sees the last, refused state of a failed run."""

    key = ""
    records_failed_frame = False

    def start(self, sim: Simulation) -> None:
        """Before the first step of the loop (after settling or resuming)."""

    def frame(self, frame: Frame) -> None:
        """An output frame."""

    def finish(self, end: RunEnd) -> None:
        """The run has ended: close files, add to ``end.summary``."""

    def state(self) -> dict[str, Any]:
        """What a checkpoint keeps of this observer (JSON numbers, lists, dicts)."""
        return {}

    def restore(self, state: dict[str, Any]) -> None:
        """Continue from :meth:`state` of a checkpoint."""


class StopRequests:
    """Ctrl-C and SIGTERM during a run: while a chunk of steps runs (``held``) the request
    waits for its end, elsewhere it stops the run at once (KeyboardInterrupt). Installed only
    in the main thread (signals reach no other)."""

    def __init__(self) -> None:
        self.pending = False
        self._holding = False
        self._previous: dict[int, Any] = {}

    def __enter__(self) -> StopRequests:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self._previous[sig] = signal.signal(sig, self._request)
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)

    def _request(self, signum: int, frame: Any) -> None:
        self.pending = True
        if not self._holding:
            raise KeyboardInterrupt

    def hold(self) -> None:
        """From now on a request only marks the run interrupted (its outputs being closed)."""
        self._holding = True

    @contextlib.contextmanager
    def held(self) -> Iterator[None]:
        """A request waits for the end of the block, then stops the run."""
        self._holding = True
        try:
            yield
        finally:
            self._holding = False
        if self.pending:
            raise KeyboardInterrupt


class Pacer:
    """Advances a simulation to each frame time in chunks of bounded wall time, and keeps the
    wall time spent stepping and the pace."""

    def __init__(self, sim: Simulation, stops: StopRequests, ticks: Sequence[Any] = ()) -> None:
        self.sim, self.stops, self.ticks = sim, stops, ticks
        self.steps0 = sim.steps
        self.step_wall = 0.0
        self.observer_wall: dict[str, float] = {}  # each observer's frames, by class name
        self.index = 0  # the frame being stepped to (a failed run's last frame takes it)
        self.chunk = FIRST_CHUNK

    @property
    def steps_per_s(self) -> float:
        done = self.sim.steps - self.steps0
        return done / self.step_wall if self.step_wall > 0 else math.nan

    def advance_to(self, t: float) -> None:
        sim = self.sim
        if sim.adaptive is not None:  # steps that land on t; a stop request ends one early
            with self.stops.held():
                self._timed(t, stop=lambda: self.stops.pending)
            return
        while (left := round((t - sim.t) / sim.dt)) > 0:
            n = min(left, self.chunk)
            with self.stops.held():
                wall = self._timed(sim.t + n * sim.dt)
            grown = round(n * CHUNK_WALL_S / max(wall, 1e-9))
            self.chunk = max(1, min(CHUNK_GROWTH * n, grown))

    def _timed(self, t: float, stop: Callable[[], bool] | None = None) -> float:
        w0 = time.perf_counter()
        self.sim.advance_to(t, stop)
        wall = time.perf_counter() - w0
        self.step_wall += wall
        for tick in self.ticks:
            tick(self.sim, self.steps_per_s)
        return wall


def run_frames(
    pacer: Pacer, times: Iterable[tuple[int, float]], observers: Sequence[Observer]
) -> bool:
    """Advance to each (index, time) and hand its frame to every observer; True when one of
    them asks to stop (``stop``: a run to solidification that has settled)."""
    for index, t in times:
        pacer.index = index
        pacer.advance_to(t)
        frame = Frame(index, pacer.sim, named_monitors(pacer.sim))
        for o in observers:
            w0 = time.perf_counter()
            o.frame(frame)
            name = type(o).__name__
            spent = time.perf_counter() - w0
            pacer.observer_wall[name] = pacer.observer_wall.get(name, 0.0) + spent
        if any(getattr(o, "stop", False) for o in observers):
            return True
    return False
