"""A layer file (``layer.npz``): the material points of a finished bed run as they ended, which a
later case reads as the previous layer to deposit on (``bed.previous_layer``, docs/record/beds.md).

Arrays (lengths in um): ``x_um`` (N, dim) positions, dim 2 or 3 (the run's ``domain.dim``);
``volume_um2`` (N,) current volumes in 2D (the seeded volume times J, per unit depth), or
``volume_um3`` in 3D; ``body`` (N,) the body each point belonged to in that run; ``material``
(N,) an index into ``material_names``; ``T_C`` (N,) temperatures; ``info`` a one-line JSON text
(case name, time reached, status). Optional, the points' mechanical state as the run left it
(``volume0_um2`` or ``volume0_um3``, the seeded volumes, and ``state_<member>`` for each of
CARRIED_STATE, and of OPTIONAL_STATE where the run wrote it): a soft solid under surface tension
sits in equilibrium with its stress (a pore or a neck compressed by 10-20 % at the paper's 1e5
Pa modulus), so a layer restarted stress-free would be squeezed again by the unbalanced surface
force and ring (measured: 1-2 m/s within a microsecond; tests/jobs/test_bed_refrozen.py).
Written by the run (jobs/case_run.py, io/layer_output.py); read here, checked, once per file.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from .errors import CaseError

LAYER_ARRAYS = ("x_um", "body", "material", "material_names", "T_C", "info")  # and a volume


def volume_key(dim: int, seeded: bool = False) -> str:
    """The file's name of the points' volumes: per unit depth (um^2) in 2D, um^3 in 3D."""
    return f"volume{'0' if seeded else ''}_um{dim}"


# the point members that hold a point's deformation and stress (solver/fields.py)
CARRIED_STATE = (
    "F",
    "J",
    "strain",
    "plastic_strain",
    "equivalent_plastic_strain",
    "iso_strain",
    "stress",
    "elastic_stretch",
    "stress_phase",
)
# carried when present: the melt's solid fraction, so that a layer that ended molten (an
# amorphous melt on a bed inside the sintering window) restarts molten at the bed temperature;
# a file without it restarts each point at the phase of that temperature
OPTIONAL_STATE = ("solid_fraction",)


@dataclass(frozen=True)
class Layer:
    """The points of a layer file (um), each with its body, material name and temperature;
    volumes in um^dim (per unit depth in 2D)."""

    x_um: np.ndarray
    volume: np.ndarray
    body: np.ndarray
    material: np.ndarray
    material_names: tuple[str, ...]
    T_C: np.ndarray
    info: dict
    volume0: np.ndarray | None = None  # the seeded volumes, where the state is carried
    state: dict[str, np.ndarray] | None = None  # CARRIED_STATE member -> (N, ...) values

    @property
    def dim(self) -> int:
        """2 or 3: the dimension of the run that wrote the file."""
        return int(self.x_um.shape[1])

    @property
    def bodies(self) -> np.ndarray:
        """The body indices present, sorted."""
        return np.unique(self.body)

    def of_body(self, b: int) -> tuple[np.ndarray, np.ndarray]:
        """(positions (n, dim), volumes (n,)) of one body's points (um, um^dim)."""
        sel = self.body == b
        return self.x_um[sel], self.volume[sel]

    def state_of_body(self, b: int) -> tuple[np.ndarray, dict[str, np.ndarray]] | None:
        """(seeded volumes (um^dim), carried members) of one body's points; None: not carried."""
        if self.state is None or self.volume0 is None:
            return None
        sel = self.body == b
        return self.volume0[sel], {k: v[sel] for k, v in self.state.items()}

    def spacing_um(self) -> np.ndarray:
        """Each point's side: the dim-th root of its volume (um)."""
        return self.volume ** (1.0 / self.dim)

    def balls_um(self) -> np.ndarray:
        """Rows (x, y[, z], r): each point as the disc (sphere) inscribed in its square (cube),
        what a new bed's particles land on."""
        return np.column_stack([self.x_um, 0.5 * self.spacing_um()])

    def bed_report(self, path: str) -> dict:
        """What a bed deposited on this layer adds to its generator's report; the generator's
        packing fractions would count the layer as void, so they read NaN."""
        return {
            "envelope": math.nan,
            "bulk": math.nan,
            "previous_layer": Path(path).name,
            "previous_layer_bodies": len(self.bodies),
            "previous_layer_points": len(self.volume),
        }


def layer_arrays(
    x_um: np.ndarray,
    volume: np.ndarray,
    body: np.ndarray,
    material: np.ndarray,
    material_names: list[str],
    T_C: np.ndarray,
    info: dict,
    volume0: np.ndarray | None = None,
    state: dict[str, np.ndarray] | None = None,
) -> dict[str, np.ndarray]:
    """The arrays of a layer file, ready for ``np.savez_compressed`` (no pickled objects);
    x_um (N, dim), volumes in um^dim."""
    x = np.asarray(x_um, dtype=np.float64)
    dim = x.shape[1]
    carried = {}
    if state is not None and volume0 is not None:
        # single precision: strains and stresses to 1e-7 relative, half the file (a bed's state
        # is some 40 numbers a point)
        carried = {f"state_{k}": np.asarray(state[k], dtype=np.float32) for k in CARRIED_STATE}
        carried |= {f"state_{k}": np.asarray(state[k]) for k in OPTIONAL_STATE if k in state}
        carried[volume_key(dim, seeded=True)] = np.asarray(volume0, dtype=np.float64)
    return {
        **carried,
        "x_um": x,
        volume_key(dim): np.asarray(volume, dtype=np.float64),
        "body": np.asarray(body, dtype=np.int32),
        "material": np.asarray(material, dtype=np.int32),
        "material_names": np.array(material_names, dtype=str),
        "T_C": np.asarray(T_C, dtype=np.float64),
        "info": np.array(json.dumps(info)),
    }


def read_layer(path: str, key: str = "bed.previous_layer") -> Layer:
    """The layer file at ``path``, checked; ``key`` names the case key in errors. Read once
    per file version (every body of the layer asks for it)."""
    try:
        stat = Path(path).stat()
    except OSError:
        raise CaseError(f"{key} = {path!r}: no such file") from None
    return _read_layer(str(path), key, stat.st_mtime_ns, stat.st_size)


@lru_cache(maxsize=8)
def _read_layer(path: str, key: str, _mtime_ns: int, _size: int) -> Layer:
    where = f"{key} = {path!r}"
    try:
        with np.load(Path(path), allow_pickle=False) as f:
            missing = [k for k in LAYER_ARRAYS if k not in f.files]
            if missing:
                raise CaseError(
                    f"{where}: not a layer file (lacks {', '.join(missing)}); expected the "
                    "layer.npz that a bed run writes to its output folder"
                )
            a = {k: f[k] for k in LAYER_ARRAYS}
            dim = a["x_um"].shape[1] if a["x_um"].ndim == 2 else 0
            if dim not in (2, 3) or volume_key(dim) not in f.files:
                raise CaseError(
                    f"{where}: positions of shape {a['x_um'].shape} without their volumes; "
                    "expected x_um (N, 2) with volume_um2 or (N, 3) with volume_um3"
                )
            a["volume"] = f[volume_key(dim)]
            carried = all(f"state_{k}" in f.files for k in CARRIED_STATE)
            if carried and volume_key(dim, seeded=True) in f.files:
                a["volume0"] = f[volume_key(dim, seeded=True)]
                kept = [*CARRIED_STATE, *(k for k in OPTIONAL_STATE if f"state_{k}" in f.files)]
                a["state"] = {k: f[f"state_{k}"].astype(np.float64) for k in kept}
    except (OSError, ValueError) as e:
        if isinstance(e, CaseError):
            raise
        raise CaseError(
            f"{where}: not readable as a layer file ({type(e).__name__}); expected the "
            "layer.npz that a bed run writes to its output folder"
        ) from None
    n = len(a["volume"])
    shapes_ok = a["x_um"].shape == (n, dim) and all(
        a[k].shape == (n,) for k in ("body", "material", "T_C")
    )
    if not shapes_ok or n == 0:
        raise CaseError(f"{where}: arrays of unequal length or no points; the file is damaged")
    names = tuple(str(s) for s in a["material_names"])
    finite = np.isfinite(a["x_um"]).all() and np.isfinite(a["T_C"]).all()
    if not finite or not (a["volume"] > 0).all() or not math.isfinite(a["volume"].sum()):
        raise CaseError(f"{where}: non-finite positions, temperatures or volumes <= 0")
    if a["material"].min() < 0 or a["material"].max() >= len(names):
        raise CaseError(f"{where}: a material index beyond material_names {list(names)}")
    state = a.get("state")
    if state is not None and (
        len(a["volume0"]) != n
        or not (a["volume0"] > 0).all()
        or any(len(v) != n or not np.isfinite(v).all() for v in state.values())
    ):
        raise CaseError(f"{where}: its carried state is damaged (lengths, finite, volumes > 0)")
    return Layer(
        x_um=a["x_um"],
        volume=a["volume"],
        body=a["body"].astype(np.int64),
        material=a["material"].astype(np.int64),
        material_names=names,
        T_C=a["T_C"],
        info=json.loads(str(a["info"])),
        volume0=a.get("volume0"),
        state=state,
    )
