"""ParaView point data: one ``vtu/points_NNNN.vtu`` per frame and the ``points.pvd`` collection.

A point carries (:func:`point_data`; units in the names, SI but lengths in um as in the case
file): ``T_C``, ``liquid_fraction``, ``body_id`` (the ``[[bodies]]`` index, from 0),
``velocity_m_s`` and ``displacement_um`` (3-component vectors, z = 0: ParaView's Glyph and Warp By
Vector need three), the material's Cauchy stress ``stress_xx_Pa``, ``stress_yy_Pa``,
``stress_zz_Pa`` (plane strain: not zero), ``stress_xy_Pa``, its invariants ``von_mises_Pa`` and
``pressure_Pa`` (-trace/3, positive in compression), ``equivalent_plastic_strain`` and ``J``
(det F).

In 3D the points have their three coordinates, the vectors their z, and the stress adds
``stress_xz_Pa`` and ``stress_yz_Pa``; the material's c = 1/2 surface (io/surface3d.py) adds
``vtu/surface_NNNN.vtu`` (triangles, with ``T_C`` and ``liquid_fraction`` at the vertices)
and its ``surface.pvd``. A resumed run's collections keep the frames already written."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from xml.etree import ElementTree
from xml.sax.saxutils import quoteattr

import numpy as np

from .atomic import atomic_path, atomic_write_text


def stress_invariants(stress: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(von Mises stress, pressure) of (N, 3, 3) Cauchy stresses: sqrt(3/2 s:s) with s the
    deviator, and -trace/3 (positive in compression)."""
    sig = np.asarray(stress, dtype=float).reshape(-1, 3, 3)
    mean = np.trace(sig, axis1=1, axis2=2) / 3.0
    dev = sig - mean[:, None, None] * np.eye(3)
    return np.sqrt(1.5 * (dev * dev).sum(axis=(1, 2))), -mean


def _vector3(v: np.ndarray) -> np.ndarray:
    """(N, 2) in-plane vectors as (N, 3), z = 0; (N, 3) as they are."""
    v = np.asarray(v, dtype=float)
    return np.concatenate([v, np.zeros((len(v), 3 - v.shape[1]))], axis=1)


def point_data(
    *,
    body_id: np.ndarray,
    velocity_m_s: np.ndarray,
    displacement_um: np.ndarray,
    stress_Pa: np.ndarray,
    equivalent_plastic_strain: np.ndarray,
    J: np.ndarray,
) -> dict[str, np.ndarray]:
    """The VTU fields of the solver's per-point state (besides T_C and liquid_fraction):
    vectors (N, 2) or in 3D (N, 3), stress (N, 3, 3), the rest (N,)."""
    sig = np.asarray(stress_Pa, dtype=float).reshape(-1, 3, 3)
    von_mises, pressure = stress_invariants(sig)
    out = {
        "body_id": np.asarray(body_id, dtype=np.int32).ravel(),
        "velocity_m_s": _vector3(velocity_m_s),
        "displacement_um": _vector3(displacement_um),
        "stress_xx_Pa": sig[:, 0, 0],
        "stress_yy_Pa": sig[:, 1, 1],
        "stress_zz_Pa": sig[:, 2, 2],
        "stress_xy_Pa": sig[:, 0, 1],
        "von_mises_Pa": von_mises,
        "pressure_Pa": pressure,
        "equivalent_plastic_strain": np.asarray(equivalent_plastic_strain, dtype=float).ravel(),
        "J": np.asarray(J, dtype=float).ravel(),
    }
    if np.asarray(velocity_m_s).shape[1:] == (3,):  # 3D: the shear stresses out of the plane
        out.update(stress_xz_Pa=sig[:, 0, 2], stress_yz_Pa=sig[:, 1, 2])
    return out


class VtuWriter:
    """The frames' VTU files and their collections (``points.pvd``; in 3D ``surface.pvd`` of
    the c = 1/2 surface, ``vtu/surface_NNNN.vtu``: triangles with T_C and liquid_fraction)."""

    def __init__(self, out_dir: Path) -> None:
        self.out_dir = Path(out_dir)
        self._pvd: dict[str, dict[int, tuple[float, str]]] = {"points": {}, "surface": {}}

    def resume(self) -> None:
        """Keep the frames the collections of an earlier run in this folder list."""
        for name, entries in self._pvd.items():
            path = self.out_dir / f"{name}.pvd"
            if not path.is_file():
                continue
            for ds in ElementTree.parse(path).getroot().iter("DataSet"):
                rel = ds.get("file", "")
                if (self.out_dir / rel).is_file():
                    entries[int(Path(rel).stem.split("_")[-1])] = (float(ds.get("timestep")), rel)

    def write(
        self, index: int, t_s: float, x: np.ndarray, fields: Mapping[str, np.ndarray]
    ) -> None:
        """Frame ``index`` at time ``t_s``: points ``x`` (N, 2) or (N, 3) with ``fields`` (N,)
        or (N, k) each; the collection file is rewritten to list it."""
        for name, v in fields.items():
            if len(v) != len(x):  # a short array would shift every later tuple in ParaView
                raise ValueError(f"frame {index}: {name} has {len(v)} tuples for {len(x)} points")
        x = np.asarray(x, dtype=float)
        pts = _vector3(x if x.ndim == 2 else x.reshape(-1, 2))
        cells = [("vertex", np.arange(len(x)).reshape(-1, 1))] if len(x) else []
        self._write("points", index, t_s, pts, cells, fields)

    def write_surface(
        self,
        index: int,
        t_s: float,
        verts: np.ndarray,
        tris: np.ndarray,
        fields: Mapping[str, np.ndarray],
    ) -> None:
        """Frame ``index`` of the surface: triangles ``tris`` (T, 3) into ``verts`` (V, 3),
        ``fields`` (V,) at the vertices."""
        cells = [("triangle", np.asarray(tris, dtype=np.int64))] if len(tris) else []
        self._write("surface", index, t_s, np.asarray(verts, dtype=float), cells, fields)

    def _write(
        self,
        name: str,
        index: int,
        t_s: float,
        pts: np.ndarray,
        cells: list,
        fields: Mapping[str, np.ndarray],
    ) -> None:
        import meshio  # only needed for vtu=True

        rel = f"vtu/{name}_{index:04d}.vtu"
        mesh = meshio.Mesh(pts, cells, point_data=dict(fields))
        with atomic_path(self.out_dir / rel) as tmp:
            meshio.write(tmp, mesh, file_format="vtu")
        self._pvd[name][index] = (float(t_s), rel)
        entries = "".join(
            f'    <DataSet timestep="{t!r}" group="" part="0" file={quoteattr(f)}/>\n'
            for _, (t, f) in sorted(self._pvd[name].items())
        )
        atomic_write_text(
            self.out_dir / f"{name}.pvd",
            '<?xml version="1.0"?>\n'
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            f"  <Collection>\n{entries}  </Collection>\n</VTKFile>\n",
        )
