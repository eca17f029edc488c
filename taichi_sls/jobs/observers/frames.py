"""The frames: a PNG and (``output.vtu``) ParaView point data per frame, the GIF at the end."""

from __future__ import annotations

from typing import Any

from ...io.vtu import point_data
from ...io.writer import OutputWriter
from ..run_loop import Frame, Observer, RunEnd


def vtu_point_data(snap: dict[str, Any]) -> dict[str, Any]:
    """The VTU fields of a full :meth:`Simulation.snapshot`."""
    return point_data(
        body_id=snap["body_id"],
        velocity_m_s=snap["velocity_m_s"],
        displacement_um=snap["displacement_vector_um"],
        stress_Pa=snap["stress_Pa"],
        equivalent_plastic_strain=snap["plastic_strain"],
        J=snap["J"],
    )


class Frames(Observer):
    """Draws each frame; the GIF at the end (not after an interrupt: the frames stay)."""

    key = "frames"
    records_failed_frame = True

    def __init__(self, writer: OutputWriter) -> None:
        self.writer = writer

    def frame(self, frame: Frame) -> None:
        w = self.writer
        snap = frame.sim.snapshot(full=w.vtu)
        deform = snap["displacement_um" if w.deformation == "displacement" else "plastic_strain"]
        extra = vtu_point_data(snap) if w.vtu else None
        w.frame(
            frame.index,
            frame.sim.t,
            snap["x_um"],
            snap["T_C"],
            deform,
            snap["liquid_fraction"],
            extra,
        )

    def finish(self, end: RunEnd) -> None:
        self.writer.finish_frames(gif=not end.interrupted)

    def restore(self, state: dict[str, Any]) -> None:
        self.writer.resume_frames()  # the frames the folder holds, for the GIF
