"""Contacts: the fillet geometry of the initial neck and which bodies touch
(taichi_sls/solver/contacts.py); the neck read across the line of centres is in
test_neck_section.py."""

import math

import numpy as np
import pytest

from taichi_sls.solver.contacts import fillet, in_bridge, touching


def test_fillet_between_touching_discs_has_the_closed_form_neck():
    """Touching discs of radius R joined by fillets of radius rho: neck half-width
    a = sqrt(rho^2 + 2 R rho) - rho (tangency: (R + rho)^2 = R^2 + (a + rho)^2), so the paper's
    8 um neck between 20 um discs is a 0.5 um fillet."""
    for rho in (0.5, 1.0, 2.0, 4.0):
        f = fillet([20.0, 20.0], 20.0, [60.0, 20.0], 20.0, rho)
        a = math.sqrt(rho * rho + 40.0 * rho) - rho
        assert f.neck_width == pytest.approx(2 * a, rel=1e-12)
        assert f.neck_point == pytest.approx([40.0, 20.0])
    assert fillet([20.0, 20.0], 20.0, [60.0, 20.0], 20.0, 0.5).neck_width == pytest.approx(8.0)


def test_fillet_is_tangent_to_both_discs_at_any_angle():
    """Unequal radii at an angle to the axes: each fillet circle touches each disc (centre
    distances r + rho) and the neck is the gap between the fillet circles."""
    ca, cb, ra, rb, rho = np.array([10.0, 5.0]), np.array([35.0, 22.0]), 12.0, 18.0, 2.5
    cb = ca + (cb - ca) / np.linalg.norm(cb - ca) * (ra + rb)  # touching
    f = fillet(ca, ra, cb, rb, rho)
    for c in (f.centre_plus, f.centre_minus):
        assert np.linalg.norm(c - ca) == pytest.approx(ra + rho)
        assert np.linalg.norm(c - cb) == pytest.approx(rb + rho)
    gap = np.linalg.norm(f.centre_plus - f.centre_minus) - 2 * rho
    assert f.neck_width == pytest.approx(gap)


def test_fillet_refuses_discs_too_far_apart():
    assert fillet([0.0, 0.0], 10.0, [25.0, 0.0], 10.0, 2.0) is None  # gap 5 >= 2 rho
    assert fillet([0.0, 0.0], 10.0, [23.0, 0.0], 10.0, 2.0) is not None  # gap 3 < 2 rho


def test_bridge_fills_the_neck_and_nothing_beyond_it():
    """The bridge holds the notch between two touching discs near the contact, not points far
    from it, and not the inside of a fillet circle."""
    f = fillet([20.0, 20.0], 20.0, [60.0, 20.0], 20.0, 2.0)
    half = f.neck_width / 2
    px = np.array([40.0, 40.0, 40.0, 40.0, 20.0, 40.0])
    py = np.array([20.0, 20.0 + 0.9 * half, 20.0 - 0.9 * half, 20.0 + 1.1 * half, 45.0, 30.0])
    assert in_bridge(f, [20.0, 20.0], [60.0, 20.0], px, py).tolist() == [
        True,
        True,
        True,
        False,
        False,
        False,
    ]


def test_touching_pairs_from_points():
    """Bodies 0 and 1 touch (points one spacing apart), 2 is alone."""
    x = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [10.0, 0.0]])
    body = np.array([0, 0, 1, 2])
    assert touching(x, body, 1.0) == [(0, 1)]
