"""Warnings a run's frames raise: inertia that matters under ``solver.mass_scale``."""

from __future__ import annotations

from typing import Any

from ...config import Case
from ..run_loop import Frame, Observer

KINETIC_WARNING = 1e-2  # kinetic energy over surface energy above which inertia matters


class InertiaWarning(Observer):
    """Adds to ``warnings`` each frame whose kinetic energy (with the inertia scale) passes
    ``KINETIC_WARNING`` of the surface energy when the mass is scaled."""

    key = "warnings"

    def __init__(self, case: Case, warnings: list[str]) -> None:
        self.scale, self.warnings = case.solver.mass_scale, warnings

    def frame(self, frame: Frame) -> None:
        ratio = frame.monitors.get("kinetic_ratio", 0.0)
        if ratio > KINETIC_WARNING and self.scale > 1.0:
            self.warnings.append(
                f"t = {frame.sim.t:.3g} s: kinetic energy {ratio:.2g} of the surface energy "
                f"with solver.mass_scale = {self.scale:g}: inertia matters, the scale is too large"
            )

    def state(self) -> dict[str, Any]:
        return {"warnings": list(self.warnings)}

    def restore(self, state: dict[str, Any]) -> None:
        self.warnings.extend(state.get("warnings", []))
