"""Everything a run writes into its output folder: case copy, frames, VTU points, time series
and its plot, summary, GIF.

Every file is written atomically (io/atomic.py), so a run that is interrupted -- Ctrl-C,
wall-clock limit, crash -- leaves each output either old or complete, never truncated."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from .atomic import atomic_write_text
from .frames import DEFORM_LABELS
from .gif import write_gif
from .painter import FRAME_FIELDS, FramePainter
from .series import BED_PANELS, BED_PANELS_PER_ROW, MONITORED, SeriesWriter, plot_series
from .summary import write_summary
from .vtu import VtuWriter

# the drawn deformation in a VTU written without the full point data: named for what it is
VTU_DEFORM_NAMES = {
    "displacement": "displacement_magnitude_um",
    "plastic_strain": "equivalent_plastic_strain",
}


class OutputWriter:
    """Writes everything a run produces into ``out_dir``; see the module docstring. The frames'
    pictures are ``painter``'s (io/painter.frame_painter picks it for a case)."""

    def __init__(
        self,
        out_dir: Path,
        *,
        painter: FramePainter,
        png: bool = True,
        gif: bool = True,
        vtu: bool = False,
        deformation: str = "displacement",
        bed: bool = False,
    ) -> None:
        if deformation not in DEFORM_LABELS:
            raise ValueError(
                f"deformation={deformation!r}; allowed: {', '.join(sorted(DEFORM_LABELS))}"
            )
        self.out_dir = Path(out_dir)
        self.png, self.gif, self.vtu = png, gif, vtu
        self.deformation = deformation  # the drawn one, and the VTU's without full point data
        self.bed = bed  # a powder layer: its own series (BED_PANELS)
        self.frames_written = 0
        self.out_dir.mkdir(parents=True, exist_ok=True)
        (self.out_dir / "frames").mkdir(exist_ok=True)
        self._png_paths: dict[int, Path] = {}
        self.series = SeriesWriter(self.out_dir / "timeseries.csv")
        self._painter = painter
        self._vtu = VtuWriter(self.out_dir)

    # ----------------------------------------------------------------- simple files

    def write_case(self, toml_text: str, name: str = "case.toml") -> None:
        """A case file into the folder: the case as given (case.toml), or as resolved, what
        ran (resolved.toml)."""
        atomic_write_text(self.out_dir / name, toml_text)

    def summary(self, data: dict) -> None:
        write_summary(self.out_dir / "summary.json", data)

    def row(self, values: dict[str, float]) -> None:
        """Append a row to timeseries.csv (the whole file rewritten atomically); the keys name
        their units (a 3D run's energies end in ``_J``: jobs/run_loop.named_monitors)."""
        self.series.row(values)

    @property
    def next_index(self) -> int:
        """The frame index after the last one written (or found when resuming)."""
        return max(self._png_paths, default=self.frames_written - 1) + 1

    def resume(self) -> None:
        """Continue an existing output folder: keep its time series rows and frames."""
        self.series.resume()
        self.resume_frames()

    def resume_frames(self) -> None:
        """Continue an existing output folder's frames (PNG for the GIF, VTU collections)."""
        self._vtu.resume()
        for p in sorted((self.out_dir / "frames").glob("frame_*.png")):
            self._png_paths[int(p.stem.split("_")[1])] = p

    # ----------------------------------------------------------------- frames

    def frame(
        self,
        index: int,
        t_s: float,
        x_um: np.ndarray,
        T_C: np.ndarray,
        deform: np.ndarray,
        liquid_fraction: np.ndarray,
        point_data: Mapping[str, np.ndarray] | None = None,
    ) -> None:
        """Write frame ``index`` (PNG and/or VTU as configured) for time ``t_s`` seconds.

        ``deform`` is the drawn deformation (``deformation``); ``point_data`` the VTU's further
        fields (:func:`taichi_sls.io.vtu.point_data`). Without it the VTU carries ``deform``
        under the name of what it is."""
        if not (self.png or self.vtu):  # nothing to draw
            self.frames_written += 1
            return
        x = np.asarray(x_um, dtype=float).reshape(-1, self._painter.dim)
        fields = {
            name: np.asarray(v, dtype=float).ravel()
            for name, v in zip(FRAME_FIELDS, (T_C, deform, liquid_fraction), strict=True)
        }
        for name, v in fields.items():
            if v.shape != (len(x),):
                raise ValueError(f"frame {index}: {name} has {v.size} values for {len(x)} points")
        index, t_s = int(index), float(t_s)
        png = self.out_dir / "frames" / f"frame_{index:04d}.png" if self.png else None
        surf = self._painter.paint(t_s, x, fields, png)
        if png is not None:
            self._png_paths[index] = png
        if self.vtu:
            read = {k: fields[k] for k in ("T_C", "liquid_fraction")}
            self._vtu.write(index, t_s, x, {**read, **self._vtu_extra(fields, point_data)})
            if surf is not None:  # the material's surface, beside the points (3D)
                self._vtu.write_surface(index, t_s, surf.verts, surf.tris, surf.values)
        self.frames_written += 1

    def _vtu_extra(
        self, fields: dict[str, np.ndarray], point_data: Mapping[str, np.ndarray] | None
    ) -> Mapping[str, np.ndarray]:
        """The point arrays beside T and the liquid fraction: the caller's, or the deformation."""
        if point_data is not None:
            return point_data
        return {VTU_DEFORM_NAMES[self.deformation]: fields["deform"]}

    # ----------------------------------------------------------------- end of run

    def finish(self, events: dict[str, float] | None = None) -> None:
        """Write animation.gif (if enabled) and timeseries.png (``events``, label: time in s,
        marked on a bed's); release the figure."""
        self.finish_frames()
        self.plot_series(events)

    def finish_frames(self, gif: bool = True) -> None:
        """Release the figure; write animation.gif if enabled and ``gif``."""
        self._painter.close()
        if self.gif and gif:
            paths = [p for _, p in sorted(self._png_paths.items())]
            if not paths:  # e.g. a fresh writer finishing an earlier run's folder
                paths = sorted((self.out_dir / "frames").glob("frame_*.png"))
            if paths:
                write_gif(paths, self.out_dir / "animation.gif")

    def plot_series(self, events: dict[str, float] | None = None) -> None:
        """timeseries.png (``events``, label: time in s, marked on a bed's)."""
        csv_path, png_path = self.out_dir / "timeseries.csv", self.out_dir / "timeseries.png"
        if self.bed:
            plot_series(csv_path, png_path, BED_PANELS, BED_PANELS_PER_ROW, events, True)
        else:
            plot_series(csv_path, png_path, [c for c in MONITORED if c in self.series.header])
