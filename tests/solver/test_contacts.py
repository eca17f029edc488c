"""Contacts: the fillet geometry of the initial neck, which bodies touch, and the neck read
across the line of centres (taichi_sls/solver/contacts.py)."""

import math

import numpy as np
import pytest

from taichi_sls.solver.contacts import fillet, in_bridge, neck_width, touching


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


@pytest.mark.parametrize("angle_deg", [0.0, 30.0, 45.0])
def test_neck_width_reads_a_band_exactly_at_any_angle_and_ignores_a_hole(angle_deg):
    """A band of material of width w across the line of centres, rotated: the field is linear
    near its edges, so bilinear interpolation puts the crossings exactly; an empty strip along
    the line of centres (the stagnation strip) does not shorten the neck."""
    h, off, w = 1.0, 2, 7.3
    th = math.radians(angle_deg)
    e = np.array([math.cos(th), math.sin(th)])
    n = np.array([-e[1], e[0]])
    ca = np.array([20.0, 20.0]) - 10.0 * e
    cb = np.array([20.0, 20.0]) + 10.0 * e
    i = np.arange(45)
    X, Y = np.meshgrid((i - off) * h, (i - off) * h, indexing="ij")
    t = (X - 20.0) * n[0] + (Y - 20.0) * n[1]
    field = w / 2 - np.abs(t)
    width, where = neck_width(field, h, off, ca, cb, 9.0)
    assert width == pytest.approx(w, abs=1e-9)
    holed = np.where(np.abs(t) < 0.4, -0.2, field)
    assert neck_width(holed, h, off, ca, cb, 9.0)[0] == pytest.approx(w, abs=1e-9)


def test_neck_width_is_the_narrowest_section_and_zero_when_torn():
    """An hourglass: the width grows away from the mid-plane; the narrowest section is read.
    With no material on the mid-plane the neck is 0."""
    h, off = 0.5, 2
    i = np.arange(100)
    X, Y = np.meshgrid((i - off) * h, (i - off) * h, indexing="ij")
    field = (3.0 + 0.2 * np.abs(X - 20.0)) - np.abs(Y - 20.0)
    width, where = neck_width(field, h, off, np.array([12.0, 20.0]), np.array([28.0, 20.0]), 15.0)
    assert width == pytest.approx(6.0, abs=1e-9)
    assert where == pytest.approx([20.0, 20.0], abs=h / 8)
    torn = np.where(np.abs(X - 20.0) < 1.0, -1.0, field)
    assert neck_width(torn, h, off, np.array([12.0, 20.0]), np.array([28.0, 20.0]), 15.0)[0] == 0


def test_neck_width_of_a_blown_up_state_is_nan():
    """NaN centres (the state the guard reports) give a NaN neck, not an exception, so that the
    failed run's last frame is still written."""
    field = np.zeros((10, 10))
    width, where = neck_width(field, 1.0, 2, np.array([np.nan, 1.0]), np.array([5.0, 1.0]), 3.0)
    assert math.isnan(width) and np.isnan(where).all()
    far = neck_width(field, 1.0, 2, np.array([0.0, 1.0]), np.array([1e30, 1.0]), 3.0)[0]
    assert math.isnan(far)
