"""The points' own kernel colour on a raster (contact.neck_colour = "kernel"; solver/
kernel_colour.py): on a straight outline its c = 1/2 crossing is the outline wherever the
outline lies in the cell, where the raw node colour, bilinear between nodes, moves with it."""

import numpy as np
import pytest

from taichi_sls.solver.contacts import point_colour
from taichi_sls.solver.kernel_colour import kernel_colour, kernel_neck, section_box
from taichi_sls.solver.neck_section import bilinear

H = 1.0
LP = 0.25 * H  # 2x2 points per cell


def _half_plane(edge: float, width: float = 12.0) -> tuple[np.ndarray, np.ndarray]:
    """Points at spacing h / 2 filling edge - width < x < edge, 0 < y < width, each with its
    whole square's volume (their squares tile the block: its outline is exactly x = edge)."""
    s = 0.5 * H
    xs = edge - s * (np.arange(int(width / s)) + 0.5)
    ys = s * (np.arange(int(width / s)) + 0.5)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    x = np.stack([X.ravel(), Y.ravel()], axis=1)
    return x, np.full(len(x), s * s)


def _crossing(x: np.ndarray, c: np.ndarray) -> float:
    """Where c falls through 1/2 along x (linear between samples)."""
    k = int(np.nonzero((c[:-1] >= 0.5) & (c[1:] < 0.5))[0][-1])
    return float(x[k] + (c[k] - 0.5) / (c[k] - c[k + 1]) * (x[k + 1] - x[k]))


@pytest.mark.parametrize("edge", [10.0, 10.1, 10.25, 10.4, 10.5, 10.7])
def test_a_straight_outline_crosses_one_half_on_itself(edge):
    """The kernel colour of a block whose point squares tile it is the hat's integral over the
    block: 1/2 on its edge exactly, wherever the edge lies in the cell. Read linearly between
    the raster's nodes (h / 4 apart), which moves the crossing by up to 3.3e-3 h (measured):
    tolerance 5e-3 h, a fourteenth of the raw colour's 0.07 h (the next test)."""
    x, vol = _half_plane(edge)
    lo, hi = np.array([edge - 4.0, 4.0]), np.array([edge + 4.0, 8.0])
    r = kernel_colour(x, vol, H, LP, lo, hi)
    row = int(round((6.0 - r.origin[1]) / r.spacing))
    xs = r.origin[0] + r.spacing * np.arange(r.values.shape[0])
    assert np.abs(r.values[:, row][xs < edge - 2.0] - 1.0).max() < 1e-12  # partition of unity
    assert _crossing(xs, r.values[:, row]) == pytest.approx(edge, abs=5e-3 * H)


def test_the_raw_node_colour_moves_its_crossing_with_the_outline_in_the_cell():
    """What the kernel colour removes: the raw colour (the same sum, at the nodes) bilinear
    between nodes crosses 1/2 up to ~0.07 h off a straight edge, by the edge's place in the
    cell (measured 0.07 h at a fifth of a cell): a first-order error in h."""
    off, shape = 4, (40, 24)
    worst = 0.0
    for edge in (10.0, 10.1, 10.2, 10.3, 10.4, 10.5):
        x, vol = _half_plane(edge)
        raw = point_colour(x, vol / H**2, H, LP, off, shape)
        xs = np.arange(edge - 3.0, edge + 3.0, 0.01)
        c = bilinear(raw, H, off, xs, np.full_like(xs, 6.0))
        worst = max(worst, abs(_crossing(xs, c) - edge))
    assert worst > 0.05 * H


def test_the_section_box_holds_every_section():
    """The box of a contact turned by 30 deg holds the ends of its extreme sections."""
    ca, cb, reach = np.array([0.0, 0.0]), np.array([2.0 * np.cos(0.5), 2.0 * np.sin(0.5)]), 1.5
    lo, hi = section_box(ca, cb, reach, 0.25, 0.0)
    e = (cb - ca) / 2.0
    n = np.array([-e[1], e[0]])
    for s in (0.5, 1.5):
        for t in (-reach, reach):
            p = ca + s * e + t * n
            assert np.all(p >= lo - 1e-12) and np.all(p <= hi + 1e-12)


def test_a_blown_up_state_reads_nan():
    x, vol = _half_plane(10.0)
    nan = np.array([np.nan, 0.0])
    assert np.isnan(kernel_neck(x, vol, H, LP, nan, np.array([1.0, 0.0]), 5.0))
