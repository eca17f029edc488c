"""The surface-energy capillary force (physics/surface_energy.py) and what it is verified with:
polygon bodies, the colour interface's contact line, Hopper's coalescence."""

import math

import numpy as np
import pytest
from helpers import deep_update, neck_and_kinetic_energy

from taichi_sls.config import CaseError, case_from_dict, load_case
from taichi_sls.solver.grid_views import surface_only
from taichi_sls.solver.scene import build_scene, inside_polygon
from taichi_sls.solver.simulation import Simulation
from taichi_sls.studies import verification as ver
from taichi_sls.studies.verification.hopper import colour_section, hopper_layout

SE = {"surface_tension": {"method": "surface_energy"}}


def _disc_force(R_over_h: float, sets: dict) -> tuple:
    vc = ver.load(
        "laplace",
        R_over_h,
        deep_update(SE, deep_update(sets, {"surface_tension": {"ramp_s": 0.0}})),
    )
    sim = Simulation(vc.case)
    st = sim.state
    surface_only(st)  # stress-free, no gravity: the node force is the surface force alone
    f = st.nodes.force.to_numpy()
    nx, ny = f.shape[:2]
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    X = np.stack([(i - st.cfg.off) * st.cfg.h, (j - st.cfg.off) * st.cfg.h], axis=-1)
    return vc.case, sim, f, X


@pytest.mark.parametrize("weight", ["hat", "gimp"])
def test_force_has_no_resultant_or_torque_and_does_the_perimeter_work(weight):
    """Without the mass floor, sum f_i = 0 and sum x_i x f_i = 0 to round-off (the weights
    reproduce constants and linear fields), and the virtual work of a uniform dilation v = x - x_c
    is -gamma L: sum f_i . (x_i - x_c) = -gamma L, L the outline's length (near 2 pi R)."""
    sets = {"surface_tension": {"surface_energy_weight": weight, "surface_energy_mass_floor": 0.0}}
    case, sim, f, X = _disc_force(10, sets)
    gamma = case.materials["fluid"].surface_tension_N_m
    R = case.bodies[0].radius_um * 1e-6
    scale = np.abs(f).sum()  # the force's own magnitude: about gamma times the node count
    assert scale > gamma
    assert np.abs(f.sum(axis=(0, 1))).max() < 1e-12 * scale
    torque = (X[..., 0] * f[..., 1] - X[..., 1] * f[..., 0]).sum()
    assert abs(torque) < 1e-12 * scale * np.abs(X).max()
    xc = np.asarray(case.bodies[0].center_um) * 1e-6
    work = ((X - xc) * f).sum()
    # 3 %: the outline of the points' colour is a polygon through the staircase of the seeding
    assert work / (-gamma * 2 * math.pi * R) == pytest.approx(1.0, abs=0.03)


def test_spread_floor_keeps_the_resultant():
    """floor_mode = "spread" hands the force of light nodes to their neighbours: no resultant;
    "clip" drops it and loses momentum."""
    sets = {"surface_tension": {"surface_energy_mass_floor": 0.3}}
    case, sim, f, X = _disc_force(10, sets)
    scale = np.abs(f).sum()
    assert np.abs(f.sum(axis=(0, 1))).max() < 1e-12 * scale
    clip = deep_update(sets, {"surface_tension": {"surface_energy_floor_mode": "clip"}})
    _, _, f2, _ = _disc_force(10, clip)
    assert np.abs(f2.sum(axis=(0, 1))).max() > 1e-6 * scale


def test_section_of_a_colour_band():
    """c = 1 inside |y - 5| < 2.5 on a 1 m grid, 0 outside: the c = 1/2 line cuts each edge
    between the last inside and the first outside node half-way."""
    c = np.zeros((11, 11))
    c[:, 3:8] = 1.0
    assert colour_section(c, 1.0, 0, 4.0) == pytest.approx(5.0)  # on a node column
    assert colour_section(c, 1.0, 0, 4.5) == pytest.approx(5.0)  # through cell centres


def test_polygon_body_seeds_like_a_rectangle(tmp_path):
    base = {
        "grid": {"spacing_um": 2.0},
        "domain": {"width_um": 40.0, "height_um": 40.0},
        "physics": {"thermal": False},
    }
    rect = case_from_dict(
        {**base, "bodies": [{"shape": "rect", "min_um": [5, 5], "max_um": [25, 17]}]}
    )
    sq = [[5, 5], [25, 5], [25, 17], [5, 17]]
    poly = case_from_dict({**base, "bodies": [{"shape": "polygon", "vertices_um": sq}]})
    a, b = build_scene(rect), build_scene(poly)
    assert a.n_points == b.n_points == 10 * 6 * 4
    np.testing.assert_array_equal(np.sort(a.x, axis=0), np.sort(b.x, axis=0))
    assert poly.bodies[0].perimeter_um() == pytest.approx(64.0)
    # from a file, relative to the case file
    (tmp_path / "outline.txt").write_text("# x y (um)\n5 5\n25, 5\n25 17\n5 17\n")
    text = (
        "[grid]\nspacing_um = 2.0\n[domain]\nwidth_um = 40.0\nheight_um = 40.0\n"
        '[physics]\nthermal = false\n[[bodies]]\nshape = "polygon"\nvertices_file = "outline.txt"\n'
    )
    (tmp_path / "case.toml").write_text(text)
    assert build_scene(load_case(tmp_path / "case.toml")).n_points == a.n_points
    with pytest.raises(CaseError, match="vertices"):
        case_from_dict({**base, "bodies": [{"shape": "polygon"}]})
    with pytest.raises(CaseError, match="outside the domain"):
        case_from_dict(
            {**base, "bodies": [{"shape": "polygon", "vertices_um": [[0, 0], [50, 0], [0, 5]]}]}
        )
    with pytest.raises(CaseError, match="vertices_file = 'nope.txt': no such file"):
        case_from_dict({**base, "bodies": [{"shape": "polygon", "vertices_file": "nope.txt"}]})


def test_inside_polygon_even_odd():
    tri = np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]])
    inside = inside_polygon(tri, np.array([1.0, 3.0, -1.0]), np.array([1.0, 3.0, 1.0]))
    assert list(inside) == [True, False, False]


def test_hopper_shape_seeds_the_exact_outline():
    """Hopper's outline at tau0 = 0.3 as a polygon: the seeded area is the exact 2 pi R0^2
    within the staircase of the points, and the colour interface's neck starts above the exact
    r_n = 0.364 R0 (the cusp, kappa R0 ~ -100, is filled in over about a cell; measured 0.45 R0
    with the colour filter at R0/h = 10), less so without the filter."""
    R0 = 20e-6
    rn = []
    for filt in (False, True):
        vc = ver.load(
            "hopper_shape", 10, {"surface_tension": {"surface_energy_colour_filter": filt}}
        )
        sc = build_scene(vc.case)
        assert sc.vol.sum() / (2 * math.pi * R0**2) == pytest.approx(1.0, abs=0.01)
        sim = Simulation(vc.case)
        _, X = hopper_layout(vc.case)
        rn.append(
            0.5 * colour_section(sim.necks.colour(), sim.state.cfg.h, sim.state.cfg.off, X) / R0
        )
    assert 0.30 < rn[0] < rn[1] < 0.50


def test_colour_contact_line_of_the_paper_pair():
    """The colour interface's contact line of the paper's pair at t = 0 (no r_p): 13.58 um at
    h = 2 um with the colour filter, 9.33 um without (the filter bridges gaps about twice as
    wide; both fall as sqrt(h): touching circles meet in a point, docs/record/verification.md); the
    level set of eq. 21 gives the paper's 8.27 um beside it. All on the vertical node column
    (contact.neck_section = "column"). The section across the centres reads the colour that
    contact.neck_colour names whatever the force's filter: filtered (the default before issue
    #54), the filtered column's value; raw, the unfiltered one."""
    cls, across, across_raw = [], [], []
    for filt in ("true", "false"):
        sim = Simulation(
            load_case(
                "nolaser",
                [
                    f"surface_tension.surface_energy_colour_filter={filt}",
                    "contact.neck_section=column",
                ],
            )
        )
        m = sim.monitors()
        cls.append(m["contact_line_um"])
        assert m["contact_line_level_set_um"] == pytest.approx(8.27, abs=0.01)
        sim.case.contact.neck_colour = "filtered"
        across.append(sim.necks.necks_m("colour")[0] * 1e6)
        sim.case.contact.neck_colour = "raw"
        across_raw.append(sim.necks.necks_m("colour")[0] * 1e6)
    assert cls[0] == pytest.approx(13.58, abs=0.05)
    assert cls[1] == pytest.approx(9.33, abs=0.05)
    assert across == pytest.approx([13.58, 13.58], abs=0.05)
    assert across_raw == pytest.approx([9.33, 9.33], abs=0.05)


def test_surface_energy_is_the_default_and_csf_stays_reachable():
    vc = ver.load("laplace", 10)
    assert vc.case.surface_tension.method == "surface_energy"
    csf = Simulation(ver.load("laplace", 10, {"surface_tension": {"method": "csf"}}).case)
    assert csf.necks.neck_measure() == "level_set" and csf.curvature_every >= 1


def test_laplace_pressure_and_spurious_currents():
    """A disc of Maxwell fluid at rest (cases/verification/laplace.toml at R/h = 10, gamma ramped
    in over 20 us, APIC) carries gamma / R (2D Laplace law). Measured +0.8 %, Ca 0.014 at
    R/h = 10 (docs/record/verification.md). Tolerance: the issue's 2 %; Ca below 0.02, half the 0.06
    that the CSF left at R/h = 20 before this force, with the margin that keeps the check off
    round-off."""
    r = ver.run(ver.load("laplace", 10))
    print("Laplace, R/h = 10:", r.errors, r.info)
    assert abs(r.errors["pressure"]) < 0.02
    assert r.errors["capillary_number"] < 0.02


def test_square_rounds_off_to_a_disc():
    """A square of Maxwell fluid (cases/verification/square.toml, h = 2 um) rounds off: its n = 4
    amplitude falls to 0.086 of its start in 300 us (the CSF: 0.47), its area kept within 1 %
    (the fluid's compressibility). Tolerance: below 0.15; area within 2 %."""
    r = ver.run(ver.load("square", 2.0))
    print("square:", r.errors, r.info)
    assert r.errors["mode4_left"] < 0.15
    assert r.errors["area"] < 0.02


def test_nolaser_pair_adheres_then_holds():
    """The paper's pair at 140 C with no laser (cases/nolaser.toml, 1 ms): the soft solid (E =
    1e5 Pa) adheres at the cusp, where the force pulls with its full 2 gamma: the colour's neck
    grows 13.58 -> 14.9 um within the first 50 us, then holds. Measured: within 0.4 % from
    0.1 ms to 1 ms, kinetic energy 1e-12 J/m at the end. Tolerances: the neck within 1 % from
    0.1 ms on and the kinetic energy decaying below 1e-11 J/m."""
    sim = Simulation(load_case("nolaser"))
    lines, ke = neck_and_kinetic_energy(sim, 1e-4, 10)
    assert max(lines) / min(lines) - 1.0 < 0.01
    assert ke[-1] < ke[0] and ke[-1] < 1e-11


@pytest.mark.slow  # ~40 s; the default suite checks Hopper on cases/sinter_hold.toml
def test_hopper_from_touching_discs_R0_h_10():
    """Coalescence of two touching fluid discs at R0/h = 10 (the quick version of the R0/h = 20
    target below), mid-plane through cell centres: r_n / R0 against Hopper's
    exact solution at tau = 0.5, 1, 2, 3, measured +2.8 / -2.2 / -1.4 / -0.4 %, area -0.06 %
    (the CSF, mid-plane on a node line: -30 / -50 / -58 / -57 %). Tolerance: the issue's 5 %
    and 0.5 %."""
    r = ver.run(ver.load("hopper", 10, {"verification": {"hopper_midplane": "cell"}}))
    for k in ("neck_tau0.5", "neck_tau1", "neck_tau2", "neck_tau3"):
        assert abs(r.errors[k]) < 0.05, r.errors
    assert abs(r.errors["area"]) < 0.005


@pytest.mark.slow
def test_hopper_from_touching_discs_R0_h_20():
    """The issue's target: within 5 % at R0/h = 20, area within 0.5 % (measured -3.1 / -2.1 /
    -0.4 / -0.1 % with the mid-plane on a node line, -0.07 % area; 3.5 min, 12 min on two
    shared cores).

    The same run read by the per-contact section the process results rest on
    (``Necks.necks_m``: reach ``pair_reach``, the default colour of ``contact.neck_colour``,
    the points' kernel sum closed by a one-cell disc; issues #40 item 6 and #54 item 5):
    within 3 % (those items' bar) at all four times, past the discs' initial diameter from
    tau ~1.45 on (measured -2.58 / -1.70 / -0.65 / +1.20 %; 10 min on one shared core; the
    force's filtered colour, the default before, read -2.87 / -2.11 / -0.38 / -0.10 %, the raw
    colour -13.4 / -4.6 / -0.26 / +0.49 %: it keeps the slot the two bodies' points leave along
    the node-line mid-plane, which the closing fills; docs/record/verification.md)."""
    r = ver.run(ver.load("hopper", 20))
    print(r.errors)
    for k in ("neck_tau0.5", "neck_tau1", "neck_tau2", "neck_tau3"):
        assert abs(r.errors[k]) < 0.05, r.errors
    assert abs(r.errors["area"]) < 0.005
    for k in ("neck_centres_tau0.5", "neck_centres_tau1", "neck_centres_tau2", "neck_centres_tau3"):
        assert abs(r.errors[k]) < 0.03, r.errors
