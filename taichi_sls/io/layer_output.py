"""The layer file of a finished bed run (``layer.npz``, format: config/layer_file.py), written
atomically so that a later case never reads a torn one."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from ..config.layer_file import layer_arrays
from .atomic import atomic_write_bytes


def write_layer(path: str | Path, **arrays) -> None:
    """Write the points of a run as a layer file (keywords: those of ``layer_arrays``)."""
    buf = io.BytesIO()
    np.savez_compressed(buf, **layer_arrays(**arrays))
    atomic_write_bytes(path, buf.getvalue())
