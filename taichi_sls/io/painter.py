"""What a run's frame painter offers the output writer (io/writer.py), and the one place that
picks the painter for a case: the 2D frames (io/frames.py: the material rasterised from the
points, coloured by temperature and by deformation) or the 3D ones (io/frames3d.py: sections
and the lit surface of a colour grid). The writer names the files and writes the VTU; it asks
nothing of a painter but what is below, so it never branches on the dimension."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np

from .frames import Frame2DPainter
from .frames3d import Frame3DPainter, view_3d
from .surface3d import Surface

if TYPE_CHECKING:
    from ..config import Case

# the fields a frame is painted from, one value per point
FRAME_FIELDS = ("T_C", "deform", "liquid_fraction")


class FramePainter(Protocol):
    """Paints a run's frames, one figure reused across them."""

    dim: int  # coordinates per point: 2 or 3

    def paint(
        self, t_s: float, x: np.ndarray, fields: Mapping[str, np.ndarray], png: Path | None
    ) -> Surface | None:
        """The frame at ``t_s`` seconds of the points ``x`` (N, dim; um) and their
        FRAME_FIELDS, written to ``png`` if given; returns the material's surface that the VTU
        carries beside the points (3D), or None."""
        ...

    def close(self) -> None:
        """Release the figure (a later frame builds it again)."""
        ...


def frame_domain_um(case: Case) -> tuple[float, float, float, float]:
    """The frames' x and y range (um): the domain and the ghost layer, but not above the top."""
    g = case.grid
    ghost = g.ghost_cells * g.spacing_um
    return (-ghost, case.domain.width_um + ghost, -ghost, case.domain.height_um)


def frame_painter(case: Case, bed: bool = False) -> FramePainter:
    """The painter of ``case``'s frames, by its dimension; ``bed``: a powder layer's colours."""
    domain_um = frame_domain_um(case)
    melt_C = min(m.melt_C for m in case.materials.values())
    dpi = case.output.dpi
    if case.domain.dim == 3:
        return Frame3DPainter(domain_um, view_3d(case), melt_C, bed, dpi=dpi)
    return Frame2DPainter(domain_um, melt_C, case.output.deformation, dpi=dpi, bed=bed)
