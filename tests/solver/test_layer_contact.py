"""The fillet between a disc and a previous layer (solver/layer_contact.py): the closing of the
union by a disc of radius rho, checked against the analytic fillet of two touching discs
(solver/contacts.py), where the layer is the second disc's points (numpy only)."""

import functools
from types import SimpleNamespace

import numpy as np
import pytest

from taichi_sls.config import Disc
from taichi_sls.solver.contacts import fillet, in_bridge
from taichi_sls.solver.layer_contact import LayerPoints, layer_bridges

R, RHO = 20.0, 2.0
A, B = np.array([20.0, 20.0]), np.array([60.0, 20.0])
Q = 0.05  # the sample spacing the bridges are compared on (um)


@functools.lru_cache
def _bridge(spacing: float):
    """(closing bridge, analytic bridge, sample positions) with disc A as a layer of points
    ``spacing`` apart (each standing for its square) and disc B a disc resting on it."""
    g = np.arange(-R, R, spacing) + spacing / 2
    X, Y = np.meshgrid(g, g, indexing="ij")
    inside = X**2 + Y**2 < R**2
    pts = np.stack([X[inside] + A[0], Y[inside] + A[1]], axis=1)
    layer = LayerPoints(pts, np.full(len(pts), spacing / 2), np.zeros(len(pts), dtype=np.int64))
    case = SimpleNamespace(
        contact=SimpleNamespace(fillet_radius_um=RHO),
        bodies=[SimpleNamespace(shape="points"), Disc(center_um=list(B), radius_um=R)],
    )
    u, v = np.arange(34.0, 46.0, Q) + Q / 2, np.arange(5.0, 35.0, Q) + Q / 2
    px, py = (a.ravel() for a in np.meshgrid(u, v, indexing="ij"))
    in_b = np.hypot(px - B[0], py - B[1]) < R
    owner = np.where(in_b, 1, -1)
    P = np.stack([px, py], axis=-1)
    in_layer = layer.covers(P)
    owner[in_layer] = -2
    layer_bridges(case, layer, P, owner, spacing)
    got = (owner >= 0) & ~in_b & ~in_layer
    outside = (np.hypot(px - A[0], py - A[1]) >= R) & ~in_b
    exact = in_bridge(fillet(A, R, B, R, RHO), A, B, px, py) & outside
    return got, exact, px, py


def _neck(mask, px, py) -> float:
    col = mask & (np.abs(px - 40.0) < Q / 2 + 1e-9)
    return float(py[col].max() - py[col].min() + Q)


@pytest.mark.parametrize("spacing", [1.0, 0.5, 0.25])
def test_the_closing_gives_the_fillet_of_two_discs(spacing):
    """The neck of the bridge to a layer of points is the fillet's, 2 (sqrt(rho^2 + 2 R rho) -
    rho) = 14.33 um, to within 1.6 point spacings plus two samples: the layer's outline is the
    union of its points' squares, off the circle by up to spacing / sqrt(2), and the fillet
    circle's height moves about 1.1 times an outline shift (R / t for t = 9.2 um), on each side
    (2 x 1.1 / sqrt(2) = 1.56)."""
    got, exact, px, py = _bridge(spacing)
    assert _neck(exact, px, py) == pytest.approx(14.33, abs=2 * Q)
    assert _neck(got, px, py) == pytest.approx(_neck(exact, px, py), abs=1.6 * spacing + 2 * Q)


def test_the_bridge_converges_to_the_fillet():
    """The area between the closing's bridge and the fillet's shrinks with the layer's point
    spacing (from 1 um to 0.25 um: to less than half), to a fifth of the 14 um^2 bridge."""
    diff = []
    for spacing in (1.0, 0.25):
        got, exact, _, _ = _bridge(spacing)
        diff.append((got ^ exact).sum() * Q * Q)
    assert diff[1] < diff[0] / 2
    assert diff[1] < 0.2 * exact.sum() * Q * Q
