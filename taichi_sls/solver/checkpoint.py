"""Checkpoints: the full state of a run in one ``.npz``, written atomically, and read back so
that a resumed run continues bitwise as if uninterrupted (CPU)."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..config import CaseError
from . import struct_copy
from .fields import State

POINT_MEMBERS = (
    "x",
    "x0",
    "v",
    "C",
    "F",
    "strain",
    "plastic_strain",
    "equivalent_plastic_strain",
    "iso_strain",
    "iso_strain_step",
    "stress",
    "elastic_stretch",
    "stress_phase",
    "viscous_stress",
    "J",
    "enthalpy",
    "T",
    "solid_fraction",
    "time_molten",
)
# added after checkpoints were first written: an older one resumes with their initial values
LATER_MEMBERS = ("elastic_stretch", "stress_phase", "viscous_stress")
SCALARS = ("t", "dt", "laser_energy", "heat_out", "T_peak")
# the curvature is kept between rebuilds (surface_tension.curvature_every): part of the state
NODE_MEMBERS = ("kappa", "flags")


def save(
    st: State,
    path: Path,
    steps: int,
    case_name: str,
    extra: dict | None = None,
    order: np.ndarray | None = None,
) -> None:
    """The points, scalars and kept node fields, atomically; ``extra`` numbers alongside;
    ``order`` each point's index at the start (the blocks layout sorts them as they flow) and
    the blocks' ranges of the sorted points."""
    data = capture(st)
    if order is not None:
        data["order"] = np.asarray(order, dtype=np.int64)
    data["steps"] = np.array(steps)
    data["case_name"] = np.array(case_name)
    for k, v in (extra or {}).items():
        data[f"x_{k}"] = np.array(v)
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp.npz")
    np.savez(tmp, **data)
    os.replace(tmp, path)


def load(st: State, path: Path, case_name: str) -> tuple[int, dict]:
    """Restore a state written by :func:`save`; returns (steps, extra)."""
    try:
        z = np.load(path)
    except (OSError, ValueError) as e:
        raise CaseError(f"--resume {path}: not a readable checkpoint ({e})") from None
    n = z["p_x"].shape[0]
    if n != st.n_points or str(z["case_name"]) != case_name:
        raise CaseError(
            f"--resume {path}: checkpoint of case {str(z['case_name'])!r} with {n} points "
            f"does not match case {case_name!r} with {st.n_points} points"
        )
    restore(st, z)
    return int(z["steps"]), {k[2:]: z[k].item() for k in z.files if k.startswith("x_")}


def capture(st: State, points: bool = True) -> dict[str, np.ndarray]:
    """The state a step changes, as host arrays (the points unless ``points`` is false, the
    scalars, the kept node fields, the blocks' ranges): what a checkpoint holds, and with the
    points kept on the device, what the adaptive step restores to redo a step it refused."""
    data = {}
    if points:
        data.update(
            {f"p_{k}": v for k, v in struct_copy.to_numpy(st.points, POINT_MEMBERS).items()}
        )
    if st.blocks is not None:
        data["b_start"] = st.blocks.start.to_numpy()
        data["b_count"] = st.blocks.count.to_numpy()
    data.update({f"s_{k}": np.array(getattr(st.scalars, k)[None]) for k in SCALARS})
    data.update({f"g_{k}": v for k, v in struct_copy.to_numpy(st.nodes, NODE_MEMBERS).items()})
    data["steps"] = np.array(st.scalars.step[None])
    return data


def restore(st: State, data: Mapping[str, np.ndarray]) -> None:
    """Put back a state from :func:`capture` (or a checkpoint file's arrays); the points only
    if it holds them."""
    if "p_x" in data:
        kept = [k for k in POINT_MEMBERS if f"p_{k}" in data or k not in LATER_MEMBERS]
        struct_copy.from_numpy(st.points, {k: data[f"p_{k}"] for k in kept})
    for k in SCALARS:
        getattr(st.scalars, k)[None] = float(data[f"s_{k}"])
    struct_copy.from_numpy(st.nodes, {k: data[f"g_{k}"] for k in NODE_MEMBERS})
    if st.blocks is not None:
        if "b_start" in data:
            st.blocks.start.from_numpy(data["b_start"])
            st.blocks.count.from_numpy(data["b_count"])
        st.blocks.clear_sums()  # a refused step's heat (its Newton raised before its end)
    st.scalars.step[None] = int(data["steps"])


def point_order(path: Path, n_points: int) -> np.ndarray | None:
    """The points' order a checkpoint was saved in (None for one written before it was kept,
    or unreadable: :func:`load` says why)."""
    try:
        with np.load(path) as z:
            order = z["order"] if "order" in z.files else None
    except (OSError, ValueError):
        return None
    if order is None or order.shape != (n_points,):
        return None
    return order
