"""Checkpoints: the full state every ``every`` frames (``checkpoint.npz``), with what each
observer keeps (the initial frame, the neck history, the contacts, the time series), so that a
resumed run ends as the uninterrupted one would, in the same folder or another."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

from ...solver.simulation import Simulation
from ..run_loop import Frame, Observer

CHECKPOINT = "checkpoint.npz"


class Checkpoints(Observer):
    """Writes ``path`` every ``every`` frames with the state of ``observers`` (the list it
    ends)."""

    def __init__(self, path: Path, every: int, observers: Sequence[Observer]) -> None:
        self.path, self.every, self.observers = path, every, observers

    def frame(self, frame: Frame) -> None:
        if self.every and frame.index > 0 and frame.index % self.every == 0:
            save(frame.sim, self.path, frame.index, self.observers)


def save(sim: Simulation, path: Path, index: int, observers: Sequence[Observer]) -> None:
    """The simulation's state at frame ``index``, with every observer's."""
    run = {o.key: o.state() for o in observers if o.key}
    sim.save_checkpoint(path, {"frame": index, "run": json.dumps(run)})


def resume(sim: Simulation, path: Path, observers: Sequence[Observer]) -> int:
    """Restore a checkpoint into ``sim`` and ``observers``; returns its frame index."""
    extra = sim.load_checkpoint(path)
    run = json.loads(extra.get("run", "{}"))
    for o in observers:
        if o.key:
            o.restore(run.get(o.key, {}))
    return int(extra["frame"])
