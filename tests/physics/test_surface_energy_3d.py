"""The surface-energy force in 3D (``domain.dim = 3``, issue #39): the c = 1/2 surface of the
node colour by marching tetrahedra (physics/tetra.py) and f_i = -gamma sum_q w_q A_q
(I - n n^T) grad N_i(x_q) on its triangles. Checked: the triangles of a plane are exact; the
force has no resultant and no torque; its virtual work under a dilation is -2 gamma A; its pull
on a hemisphere is the Laplace pressure 2 gamma / R; a sphere at rest carries it; the l = 2
mode of a sphere oscillates with Rayleigh's period; the semi-implicit stiffness is the surface
Laplacian. Each scene compiles its own kernels: the default suite runs the plane and one sphere
at R/h = 10 (two floors), the rest is slow."""

import math

import numpy as np
import pytest
from helpers import advance_steps

from taichi_sls.backend import ti
from taichi_sls.physics.tetra import tet_corner, tet_triangles
from taichi_sls.solver.grid_views import surface_only
from taichi_sls.solver.scene import build_scene
from taichi_sls.solver.simulation import Simulation, init_taichi
from taichi_sls.studies import verification as ver
from taichi_sls.studies.verification.capillarity import hemisphere_pressure, mode_amplitude_3d

FAST = {"solver": {"optimize": False}}


def test_marching_tetrahedra_cut_a_plane_exactly():
    """A field linear in x is linear on each tetrahedron, so its zero set is the plane itself:
    the six tetrahedra's triangles cover the plane's section of the unit cube, z = 0.3 + 0.2 x
    + 0.1 y over the unit square, area sqrt(1 + 0.2^2 + 0.1^2), to round-off, each corner on
    the plane; and a corner on one side of the plane alone gives one triangle per tetrahedron
    about it (the section of x + y + z = 0.5: the triangle of area sqrt(3)/8)."""
    init_taichi(optimize=False)
    out = ti.field(float, shape=3)

    @ti.kernel
    def cut(a: float, b: float, c: float, d: float):
        out[0] = 0.0
        out[1] = 0.0
        out[2] = 0.0
        for t in range(6):
            f = ti.Vector([0.0, 0.0, 0.0, 0.0])
            p = ti.Matrix([[0.0] * 3 for _ in range(4)])
            for k in range(4):
                o = tet_corner(t, k)
                for e in range(3):
                    p[k, e] = ti.cast(o[e], float)
                f[k] = a * p[k, 0] + b * p[k, 1] + c * p[k, 2] - d
            count, tri = tet_triangles(f, p)
            for q in range(count):
                x = [
                    ti.Vector([tri[3 * q + r, 0], tri[3 * q + r, 1], tri[3 * q + r, 2]])
                    for r in range(3)
                ]
                out[0] += 0.5 * (x[1] - x[0]).cross(x[2] - x[0]).norm()
                out[2] += 1.0
                for r in ti.static(range(3)):
                    out[1] = ti.max(out[1], ti.abs(a * x[r][0] + b * x[r][1] + c * x[r][2] - d))

    cut(-0.2, -0.1, 1.0, 0.3)
    assert out[0] == pytest.approx(math.sqrt(1.05), rel=1e-14) and out[1] < 1e-15
    cut(1.0, 1.0, 1.0, 0.5)
    assert out[0] == pytest.approx(math.sqrt(3) / 8, rel=1e-14) and out[1] < 1e-15
    assert out[2] == 6.0  # every tetrahedron holds corner (0, 0, 0)


def _sphere(R_over_h: float, st: dict) -> tuple:
    """The laplace3d sphere at R/h with gamma on at once; its node force is the surface force."""
    vc = ver.load("laplace3d", R_over_h, {**FAST, "surface_tension": {"ramp_s": 0.0, **st}})
    sim = Simulation(vc.case)
    surface_only(sim.state)  # stress-free, no gravity: the node force is the surface force
    f = sim.state.nodes.force.to_numpy()
    X = (np.indices(f.shape[:3]).transpose(1, 2, 3, 0) - sim.state.cfg.off) * sim.state.cfg.h
    return vc.case, sim, f, X


def test_3d_force_has_no_resultant_or_torque_and_does_the_area_work():
    """Without the mass floor, sum f_i = 0 and sum x_i x f_i = 0 to round-off at each quadrature
    point (the weights reproduce constants and linear fields, and I - n n^T is symmetric), and
    the virtual work of the dilation v = x - x_c is -2 gamma A, A the surface's area, near
    4 pi R^2 (measured 0.986 of it at R/h = 10: the c = 1/2 surface of the smoothed colour lies
    inside the seeded sphere by about its smoothing's variance over R; 3 % as the 2D test)."""
    case, sim, f, X = _sphere(10, {"surface_energy_mass_floor": 0.0})
    gamma = case.materials["fluid"].surface_tension_N_m
    R = case.bodies[0].radius_um * 1e-6
    scale = np.abs(f).sum()
    assert scale > gamma * R
    assert np.abs(f.sum(axis=(0, 1, 2))).max() < 1e-12 * scale
    torque = np.cross(X, f).sum(axis=(0, 1, 2))
    assert np.abs(torque).max() < 1e-12 * scale * np.abs(X).max()
    xc = sim.state.points.x.to_numpy().mean(axis=0)
    work = ((X - xc) * f).sum()
    assert work / (-2 * gamma * 4 * math.pi * R * R) == pytest.approx(1.0, abs=0.03)


def test_laplace_pressure_on_a_hemisphere_R_h_10():
    """With the default floor (spread: the resultant kept), the pull on each of the three
    hemispheres is the Laplace pressure 2 gamma / R over pi R^2 within 2 % at R/h = 10
    (measured -0.80 / -0.73 / -0.78 %; the issue's bound)."""
    case, sim, f, _ = _sphere(10, {})
    assert np.abs(f.sum(axis=(0, 1, 2))).max() < 1e-12 * np.abs(f).sum()
    gamma = case.materials["fluid"].surface_tension_N_m
    p = hemisphere_pressure(sim) / (2 * gamma / (case.bodies[0].radius_um * 1e-6))
    print("hemisphere pressure / (2 gamma / R), R/h = 10:", p)
    assert np.abs(p - 1.0).max() < 0.02


@pytest.mark.slow
def test_laplace_pressure_on_a_hemisphere_R_h_20():
    """The same at R/h = 20 within 1 % (measured -0.044 / -0.005 / -0.022 %; about 20 s)."""
    case, sim, f, _ = _sphere(20, {})
    gamma = case.materials["fluid"].surface_tension_N_m
    p = hemisphere_pressure(sim) / (2 * gamma / (case.bodies[0].radius_um * 1e-6))
    print("hemisphere pressure / (2 gamma / R), R/h = 20:", p)
    assert np.abs(p - 1.0).max() < 0.01


def test_perturbed_sphere_is_seeded_with_its_mode():
    """r = R (1 + eps P_2(cos theta)) about x: the measured amplitude is eps (1 + 4 eps / 7)
    to second order (the cube of 1 + eps P_2 against P_2, over the sphere), and no l = 3 mode
    beyond the seeding's staircase. Measured 0.05154 (0.2 % off it) and eps_3 = -4.5e-4 at
    R/h = 10 (bound 1e-3, as the 2D disc's -1e-3)."""
    sc = build_scene(ver.load("inviscid3d", 10).case)
    eps = 0.05
    assert mode_amplitude_3d(sc.x, sc.vol, 2) == pytest.approx(eps * (1 + 4 * eps / 7), rel=0.01)
    assert abs(mode_amplitude_3d(sc.x, sc.vol, 3)) < 0.02 * eps


@pytest.mark.slow
def test_3d_capillary_stiffness_is_the_surface_laplacian():
    """The semi-implicit stiffness on the triangles (physics/stiffness.py, triangle_tangent):
    symmetric, each row summing to zero (a uniform velocity does not stretch the surface), and
    under the dilation v = x - x_c, v^T K v = 2 A scale (tr(I - n n^T) = 2), A the area whose
    virtual work the force does: -sum f . v / gamma, to round-off. The stiffness is stored as
    scalar rows (one value per node pair, the same on each velocity component), as the implicit
    step assembles it. Slow: its kernel's 27 x 27 node pairs take long to compile."""
    from taichi_sls.physics.stiffness import REACH, WIDTH, capillary_tangent

    case, sim, f, X = _sphere(4, {"surface_energy_mass_floor": 0.0})
    st = sim.state
    gamma = case.materials["fluid"].surface_tension_N_m
    K = ti.field(float, f.shape[:3] + (WIDTH,) * 3)  # scalar rows: the block is K_ij I

    @ti.kernel
    def assemble(scale: float):
        capillary_tangent(st.cfg, st.box, st.nodes, K, scale)

    assemble(1.0)
    k = K.to_numpy()  # K[i, d] = K_{i, i + d - REACH}, the same on each component
    xc = st.points.x.to_numpy().mean(axis=0)
    V = X - xc
    pad = ((REACH, REACH),) * 3
    Vp = np.pad(V, pad + ((0, 0),))
    kp = np.pad(k, pad + ((0, 0),) * 3)
    n = V.shape[:3]
    Kv, asym, scale = np.zeros_like(V), 0.0, np.abs(k).max()
    for o in np.ndindex(WIDTH, WIDTH, WIDTH):
        at = tuple(slice(o[a], o[a] + n[a]) for a in range(3))  # the nodes i + d, padded
        Kv += k[:, :, :, o[0], o[1], o[2], None] * Vp[at]
        back = kp[at + tuple(WIDTH - 1 - np.array(o))]  # K_{i + d, i}
        asym = max(asym, np.abs(k[:, :, :, o[0], o[1], o[2]] - back).max())
    quad = float((V * Kv).sum())
    rows = k.sum(axis=(3, 4, 5))
    assert np.abs(rows).max() < 1e-12 * scale
    assert asym < 1e-12 * scale
    work = (V * f).sum()
    assert quad == pytest.approx(-work / gamma, rel=1e-10)
    assert quad > 0.0


@pytest.mark.slow
def test_l2_period_of_a_sphere_R_h_10():
    """The l = 2 mode of a nearly inviscid sphere (cases/verification/inviscid3d.toml, eps0 =
    0.05, eta_N = 1e-4 Pa s) oscillates with Rayleigh's period 2 pi / omega, omega^2 =
    8 gamma / (rho R^3) (33.3 us), within 2 % at R/h = 10 (the issue's bound; measured +1.72 %,
    beside the 2D disc's +1.23 % at the same R/h; 27 minutes on two loaded cores)."""
    r = ver.run(ver.load("inviscid3d", 10))
    print("l = 2 period, R/h = 10:", r.errors, r.info)
    assert abs(r.errors["period"]) < 0.02


def test_a_perturbed_sphere_starts_to_round_off_and_keeps_its_momentum():
    """The force in the explicit step: the l = 2 sphere of inviscid3d at R/h = 4 (seeded
    eps = 0.0539 on the coarse staircase) for 40 steps (1.2 us of its 33 us period): the mode's
    amplitude falls (measured to 0.0506) while the momentum stays at round-off (the force has
    no resultant; the spread floor keeps it): measured 2.7e-15 of the mass times the largest
    speed, bound 1e-12. The mass cut-off is off here: with the default (solver.small_mass) the
    nodes below it, at the edge where the surface force acts, drop theirs (measured 1.1e-8)."""
    sets = {"solver": {"optimize": False, "small_mass": 0.0}}
    sim = Simulation(ver.load("inviscid3d", 4, sets).case)
    st = sim.state
    eps0 = mode_amplitude_3d(st.points.x.to_numpy(), st.points.volume0.to_numpy(), 2)
    advance_steps(sim, 40)
    x, v = st.points.x.to_numpy(), st.points.v.to_numpy()
    m = st.points.mass.to_numpy()
    eps = mode_amplitude_3d(x, st.points.volume0.to_numpy() * st.points.J.to_numpy(), 2)
    print(f"eps {eps0:.5f} -> {eps:.5f}")
    assert eps < eps0 - 1e-3
    P = (m[:, None] * v).sum(axis=0)
    assert np.abs(P).max() < 1e-12 * m.sum() * np.abs(v).max()
