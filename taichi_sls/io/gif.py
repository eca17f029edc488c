"""The animation: PNG frames into a looping GIF kept under a size budget."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .atomic import atomic_write_bytes

GIF_MAX_BYTES = 2_000_000
GIF_FRAME_S = 0.15
_GIF_BUDGET = int(0.9 * GIF_MAX_BYTES)  # encoder output varies a little with the frame subset
_GIF_MIN_FRAMES = 20  # below this, downscale instead of dropping more frames


def write_gif(paths: list[Path], gif_path: Path) -> None:
    """Encode PNG frames into a looping GIF under GIF_MAX_BYTES (drop frames, then downscale)."""
    import imageio.v3 as iio

    def rgb(p: Path) -> np.ndarray:
        im = np.asarray(iio.imread(p))
        return np.stack([im] * 3, axis=-1) if im.ndim == 2 else im[..., :3]

    def encode(sel: list[Path], scale: int, step: int) -> bytes:
        first = rgb(sel[0])[::scale, ::scale]
        data = np.full((len(sel), *first.shape), 255, dtype=np.uint8)  # one copy, no stacking
        for k, p in enumerate(sel):
            im = rgb(p)[::scale, ::scale]
            h, w = min(im.shape[0], first.shape[0]), min(im.shape[1], first.shape[1])
            data[k, :h, :w] = im[:h, :w]  # pad/crop should a frame differ in size
        # Dropping frames keeps the animation's pace: each kept frame shows `step` times longer.
        ms = round(1000 * GIF_FRAME_S * step)
        return iio.imwrite(
            "<bytes>", data, extension=".gif", plugin="pillow", is_batch=True, duration=ms, loop=0
        )

    n, step, scale = len(paths), 1, 1
    probe = paths[:: max(1, n // 8)][:8]  # estimate bytes per frame from a few frames
    per_frame = len(encode(probe, 1, 1)) / len(probe)
    step = max(1, math.ceil(n * per_frame / _GIF_BUDGET))
    if n / step < _GIF_MIN_FRAMES and n >= _GIF_MIN_FRAMES:
        step = max(1, n // _GIF_MIN_FRAMES)
    while True:
        data = encode(paths[::step], scale, step)
        if len(data) <= GIF_MAX_BYTES or scale >= 16:
            break
        if len(paths[::step]) > _GIF_MIN_FRAMES:
            step *= 2
        else:
            scale *= 2
    atomic_write_bytes(gif_path, data)
