"""ParaView point data: one ``vtu/points_NNNN.vtu`` per frame and the ``points.pvd`` collection."""

from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from .atomic import atomic_path, atomic_write_text


class VtuWriter:
    def __init__(self, out_dir: Path) -> None:
        self.out_dir = Path(out_dir)
        self._pvd: dict[int, tuple[float, str]] = {}

    def write(self, index: int, t_s: float, x: np.ndarray, fields: dict) -> None:
        import meshio  # only needed for vtu=True

        rel = f"vtu/points_{index:04d}.vtu"
        pts = np.column_stack([x, np.zeros(len(x))])
        cells = [("vertex", np.arange(len(x)).reshape(-1, 1))] if len(x) else []
        mesh = meshio.Mesh(pts, cells, point_data=fields)
        with atomic_path(self.out_dir / rel) as tmp:
            meshio.write(tmp, mesh, file_format="vtu")
        self._pvd[index] = (t_s, rel)
        entries = "".join(
            f'    <DataSet timestep="{t!r}" group="" part="0" file={quoteattr(f)}/>\n'
            for _, (t, f) in sorted(self._pvd.items())
        )
        atomic_write_text(
            self.out_dir / "points.pvd",
            '<?xml version="1.0"?>\n'
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            f"  <Collection>\n{entries}  </Collection>\n</VTKFile>\n",
        )
