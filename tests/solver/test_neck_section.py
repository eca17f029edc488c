"""The neck of a contact (solver/neck_section.py): in 2D the width of a section line across the
line of centres, in 3D the c = 1/2 section normal to it, read as 2 sqrt(A / pi), the narrowest
over the middle half of the centre distance; what both share, tested over dim;
the fillet contact of two spheres (the torus bridge, scene._sphere_bridges); a sphere's Laplace
pressure 2 gamma / R. Numpy fields and seeded scenes here (no Taichi kernel); the runs of
settle and stop = "solidified" in 3D are in tests/jobs/test_settle3d.py."""

import math

import numpy as np
import pytest
from helpers import make_case

from taichi_sls.solver.contacts import fillet, in_bridge
from taichi_sls.solver.neck_section import (
    equivalent_radii,
    filtered_colour,
    neck_section,
    section_area,
)
from taichi_sls.solver.scene import build_scene, laplace_pressure

R = 20e-6
OFF = 3  # array index of the node at 0


def _nodes(h: float, side: float) -> np.ndarray:
    """Node positions (m), (n, n, n, 3), array index i at (i - OFF) h."""
    ax = (np.arange(int(round(side / h)) + 1 + 2 * OFF) - OFF) * h
    return np.stack(np.meshgrid(ax, ax, ax, indexing="ij"), axis=-1)


def _pair(h: float, d: float) -> tuple[np.ndarray, np.ndarray]:
    """Two centres d apart along x, off the nodes (no section falls on a node plane)."""
    ca = np.array([0.4 * R, 2 * R, 2 * R]) + np.array([0.37, 0.21, 0.13]) * h
    return ca, ca + np.array([d, 0.0, 0.0])


def test_marching_triangles_cut_a_half_plane_exactly():
    """A field linear on the lattice is linear on every triangle: the area where it is >= 0 is
    exact to round-off (a line cutting the unit square at x + 0.5 y = 0.6, lattice h = 0.1)."""
    t = np.linspace(0.0, 1.0, 11)
    x, y = np.meshgrid(t, t, indexing="ij")
    area = section_area(0.6 - x - 0.5 * y, 0.1)
    exact = 0.6 * 1.0 - 0.5 * 0.5  # x <= 0.6 - y / 2 over y in [0, 1]
    assert area == pytest.approx(exact, rel=1e-12)
    # a hole inside the material counts (the span between the outermost crossings, as 2D)
    ring = np.where(np.hypot(x - 0.5, y - 0.5) < 0.15, -1.0, 0.4 - np.hypot(x - 0.5, y - 0.5))
    assert section_area(ring, 0.1) > section_area(0.4 - np.hypot(x - 0.5, y - 0.5), 0.1) - 1e-12


@pytest.mark.parametrize("R_over_h, tol", [(5, 0.01), (10, 0.003), (20, 0.001)])
def test_the_waist_of_a_hyperboloid_reads_its_circle(R_over_h, tol):
    """A smooth neck of exact circular section: r = sqrt(a^2 + s^2 / 2) about the line of
    centres, a = 0.6 R, narrowest at the mid-plane. Read to second order in h (trilinear
    colour, lattice of h/4): measured -0.60 / -0.15 / -0.04 % at R/h = 5 / 10 / 20, so the
    tolerances 1 / 0.3 / 0.1 %."""
    h = R / R_over_h
    a, (ca, cb) = 0.6 * R, _pair(h, 1.6 * R)
    P = _nodes(h, 4 * R)
    s = P[..., 0] - 0.5 * (ca[0] + cb[0])
    field = np.sqrt(a * a + 0.5 * s * s) - np.hypot(P[..., 1] - ca[1], P[..., 2] - ca[2])
    width, at = neck_section(field, h, OFF, ca, cb, (2 * R**3) ** (1 / 3))
    assert width == pytest.approx(2 * a, rel=tol)
    assert abs(at[0] - 0.5 * (ca[0] + cb[0])) <= h  # the narrowest plane is the waist's


@pytest.mark.parametrize("R_over_h, tol", [(5, 0.02), (10, 0.005)])
def test_a_fillet_torus_reads_its_neck(R_over_h, tol):
    """Touching spheres joined by the torus of tube radius rho = R/4 (the 3D fillet): the neck
    2 (t - rho) of the 2D fillet, t the torus centre's distance from the axis. The field is
    the distance outside the torus tube within the bridge, the spheres' own elsewhere; measured
    +1.2 / +0.24 % at R/h = 5 / 10 (tolerances 2 / 0.5 %)."""
    h, rho = R / R_over_h, 0.25 * R
    ca, cb = _pair(h, 2 * R)
    f = fillet((0.0, 0.0), R, (2 * R, 0.0), R, rho)
    P = _nodes(h, 4 * R)
    s = P[..., 0] - ca[0]
    r = np.hypot(P[..., 1] - ca[1], P[..., 2] - ca[2])
    spheres = np.maximum(R - np.hypot(s, r), R - np.hypot(s - 2 * R, r))
    tube = np.hypot(s - R, r - f.centre_plus[1]) - rho
    half = R - R * R / (R + rho)  # the tangent points' distance from the mid-plane
    bridge = np.where((np.abs(s - R) <= half) & (r < f.centre_plus[1]), tube, -1.0)
    width, _ = neck_section(np.maximum(spheres, bridge), h, OFF, ca, cb, (2 * R**3) ** (1 / 3))
    assert width == pytest.approx(f.neck_width, rel=tol)


def test_a_coalesced_sphere_reads_its_diameter():
    """The end state of a coalescence, one sphere of radius 2^(1/3) R about the pair's middle:
    convex, no waist, so the widest section (its equator) is the neck: 2^(4/3) R within 1 %
    at R/h = 5 (the equator's circle, second order: measured -0.2 %)."""
    h = R / 5
    ca, cb = _pair(h, 1.6 * R)
    P = _nodes(h, 4 * R)
    big = 2 ** (1 / 3) * R
    field = big - np.linalg.norm(P - 0.5 * (ca + cb), axis=-1)
    width, _ = neck_section(field, h, OFF, ca, cb, (2 * R**3) ** (1 / 3))
    assert width == pytest.approx(2 * big, rel=0.01)


@pytest.mark.parametrize("dim", [2, 3])
def test_no_material_reads_zero_and_a_blown_up_state_nan(dim):
    """No material on the sections: a neck of 0 (torn). NaN centres (the state the guard
    reports) or centres flung far apart: a NaN neck and place, not an exception, so that the
    failed run's last frame is still written."""
    h = R / 5
    ca, cb = _pair(h, 2 * R)
    ca, cb = ca[:dim], cb[:dim]
    empty = -np.ones(_nodes(h, 4 * R).shape[:dim])
    assert neck_section(empty, h, OFF, ca, cb, R)[0] == 0.0
    width, where = neck_section(empty, h, OFF, ca, ca + np.nan, R)
    assert math.isnan(width) and np.isnan(where).all() and len(where) == dim
    far = cb.copy()
    far[0] = 1e30
    assert math.isnan(neck_section(empty, h, OFF, ca, far, R)[0])


@pytest.mark.parametrize("dim", [2, 3])
def test_the_filter_is_the_force_filter(dim):
    """[1 2 1] / 4 along each axis on the interior nodes: a node's unit spike spreads to
    1/2^dim at itself and weights that sum to 1, 0 on the arrays' edge."""
    c = np.zeros((7,) * dim)
    c[(3,) * dim] = 1.0
    f = filtered_colour(c)
    assert f[(3,) * dim] == pytest.approx(0.5**dim)
    assert f[(2,) + (3,) * (dim - 1)] == pytest.approx(0.5 ** (dim + 1))
    assert f.sum() == pytest.approx(1.0) and f[0].sum() == 0.0


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
    width, where = neck_section(field, h, off, ca, cb, 9.0)
    assert width == pytest.approx(w, abs=1e-9)
    holed = np.where(np.abs(t) < 0.4, -0.2, field)
    assert neck_section(holed, h, off, ca, cb, 9.0)[0] == pytest.approx(w, abs=1e-9)


def test_neck_width_is_the_narrowest_section_and_zero_when_torn():
    """An hourglass: the width grows away from the mid-plane; the narrowest section is read.
    With no material on the mid-plane the neck is 0."""
    h, off = 0.5, 2
    i = np.arange(100)
    X, Y = np.meshgrid((i - off) * h, (i - off) * h, indexing="ij")
    field = (3.0 + 0.2 * np.abs(X - 20.0)) - np.abs(Y - 20.0)
    width, where = neck_section(field, h, off, np.array([12.0, 20.0]), np.array([28.0, 20.0]), 15.0)
    assert width == pytest.approx(6.0, abs=1e-9)
    assert where == pytest.approx([20.0, 20.0], abs=h / 8)
    torn = np.where(np.abs(X - 20.0) < 1.0, -1.0, field)
    assert neck_section(torn, h, off, np.array([12.0, 20.0]), np.array([28.0, 20.0]), 15.0)[0] == 0


SPHERES = {
    "grid": {"spacing_um": 1.0},
    "domain": {"dim": 3, "width_um": 40.0, "height_um": 24.0, "depth_um": 24.0},
    "bodies": [
        {"shape": "disc", "center_um": [12.0, 12.0, 12.0], "radius_um": 8.0},
        {"shape": "disc", "center_um": [28.0, 12.0, 12.0], "radius_um": 8.0},
    ],
}


def test_touching_spheres_are_joined_by_the_torus_bridge():
    """contact.initial = "fillet" in 3D: the points added to two touching spheres (R = 8 um,
    rho = 2 um) fill the 2D fillet's bridge turned about the line of centres: every one lies in
    it, each given to its nearer sphere, and their volume is its volume of revolution
    2 pi int r dA within 5 % (the staircase of a point spacing on a thin ring; measured +1.3 %
    at 0.5 um spacing)."""
    point = build_scene(make_case(SPHERES))
    bridged = build_scene(make_case({**SPHERES, "contact": {"initial": "fillet"}}))
    f = fillet((0.0, 0.0), 8.0, (16.0, 0.0), 8.0, 2.0)
    x = bridged.x * 1e6 - [12.0, 12.0, 12.0]
    s, r = x[:, 0], np.hypot(x[:, 1], x[:, 2])
    added = (np.hypot(s, r) >= 8.0) & (np.hypot(s - 16.0, r) >= 8.0)
    assert added.sum() == len(bridged.x) - len(point.x) > 0
    assert in_bridge(f, (0.0, 0.0), (16.0, 0.0), s[added], r[added]).all()
    assert np.array_equal(bridged.body[added], (s[added] > 8.0).astype(bridged.body.dtype))
    g = np.linspace(0.0, 16.0, 3201)
    S, Rr = np.meshgrid(g, g[:1601], indexing="ij")
    inside = in_bridge(f, (0.0, 0.0), (16.0, 0.0), S, Rr)
    inside &= (np.hypot(S, Rr) > 8.0) & (np.hypot(S - 16.0, Rr) > 8.0)
    exact = 2 * math.pi * float((Rr * inside).sum()) * (g[1] - g[0]) ** 2
    assert bridged.vol[added].sum() * 1e18 == pytest.approx(exact, rel=0.05)
    # each body's equivalent radius is the sphere's: (3 V / 4 pi)^(1/3), to its staircase
    radii = equivalent_radii(point.body, point.vol, 3)
    assert radii == pytest.approx(8e-6, rel=0.01)


def test_a_sphere_carries_twice_the_cylinder_laplace_pressure():
    """Young-Laplace: a sphere's two principal curvatures, 2 gamma / R; a disc (a cylinder in
    plane strain) gamma / R."""
    st = {"initial_stress": "laplace"}
    three = make_case({**SPHERES, "surface_tension": st})
    two = make_case(
        {
            "domain": {"width_um": 40.0, "height_um": 24.0},
            "bodies": [{"shape": "disc", "center_um": [12.0, 12.0], "radius_um": 8.0}],
            "surface_tension": st,
        }
    )
    gamma = three.materials[three.bodies[0].material].surface_tension_N_m
    assert laplace_pressure(three, three.bodies[0]) == pytest.approx(2 * gamma / 8e-6, rel=1e-15)
    assert laplace_pressure(two, two.bodies[0]) == gamma / 8e-6
