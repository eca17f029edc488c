"""ParaView point data: one ``vtu/points_NNNN.vtu`` per frame and the ``points.pvd`` collection.

A point carries (:func:`point_data`; units in the names, SI but lengths in um as in the case
file): ``T_C``, ``liquid_fraction``, ``body_id`` (the ``[[bodies]]`` index, from 0),
``velocity_m_s`` and ``displacement_um`` (3-component vectors, z = 0: ParaView's Glyph and Warp By
Vector need three), the material's Cauchy stress ``stress_xx_Pa``, ``stress_yy_Pa``,
``stress_zz_Pa`` (plane strain: not zero), ``stress_xy_Pa``, its invariants ``von_mises_Pa`` and
``pressure_Pa`` (-trace/3, positive in compression), ``equivalent_plastic_strain`` and ``J``
(det F)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
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
    """(N, 2) in-plane vectors as (N, 3), z = 0."""
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
    vectors (N, 2), stress (N, 3, 3), the rest (N,)."""
    sig = np.asarray(stress_Pa, dtype=float).reshape(-1, 3, 3)
    von_mises, pressure = stress_invariants(sig)
    return {
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


class VtuWriter:
    def __init__(self, out_dir: Path) -> None:
        self.out_dir = Path(out_dir)
        self._pvd: dict[int, tuple[float, str]] = {}

    def write(
        self, index: int, t_s: float, x: np.ndarray, fields: Mapping[str, np.ndarray]
    ) -> None:
        """Frame ``index`` at time ``t_s``: points ``x`` (N, 2) with ``fields`` (N,) or (N, k)
        each; the collection file is rewritten to list it."""
        import meshio  # only needed for vtu=True

        for name, v in fields.items():
            if len(v) != len(x):  # a short array would shift every later tuple in ParaView
                raise ValueError(f"frame {index}: {name} has {len(v)} tuples for {len(x)} points")
        rel = f"vtu/points_{index:04d}.vtu"
        pts = np.column_stack([x, np.zeros(len(x))])
        cells = [("vertex", np.arange(len(x)).reshape(-1, 1))] if len(x) else []
        mesh = meshio.Mesh(pts, cells, point_data=dict(fields))
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
