"""Two touching spheres of a Maxwell liquid coalescing under surface tension, no heat
(``domain.dim = 3``): ``taichi-sls bench spherepair [--r-over-h 8] [--tau 3.8] [--octant]
[--out renders]``, then ``--plot`` on the tables (bench/sphere_pair_report.py).

The 3D counterpart of Hopper's pair (cases/verification/hopper.toml): the same zero-yield
Perzyna liquid (eta_N = eta / 2 = 0.3 Pa s, Maxwell time 1 us) and surface-energy force, as
spheres of radius R = 20 um. The neck x is half the 3D neck of solver/neck_section.py (the
area-equivalent radius of the narrowest c = 1/2 section across the centres), the half-length L
half the span of c >= 1/2 along the line of centres; both are reported over R against
tau = gamma t / (eta_N R), with the volume change (sum of V0 J over the points); one coalesced
sphere has x = L = 2^(1/3) R. ``--octant`` runs the eighth of the pair under three mirror
walls (8x fewer points, the same answer: tests/bench/test_sphere_pair.py) and reads the
measures on its points unfolded into the whole pair. No closed form is checked: 3D sphere
coalescence has none (Hopper's is 2D); the report sets the run beside Frenkel's and Pokluda et
al.'s models. Writes sphere_pair_r<R/h>[_octant].csv.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

from bench.sphere_pair_report import report_main
from taichi_sls.config import Case, case_from_dict
from taichi_sls.config.loading import add_set_argument, apply_override, bundled_case
from taichi_sls.io.atomic import write_rows
from taichi_sls.solver.contacts import point_colour
from taichi_sls.solver.neck_section import neck_section, pair_reach, trilinear
from taichi_sls.solver.simulation import Simulation

R_UM = 20.0


def hopper_fluid() -> dict[str, object]:
    """Hopper's viscous liquid as cases/verification/hopper.toml defines it (mu = 3e5 Pa,
    eta = 0.6 Pa s: eta_N = 0.3 Pa s, Maxwell time 1 us), its one material table."""
    with open(bundled_case("verification/hopper"), "rb") as f:
        return dict(tomllib.load(f)["materials"]["fluid"])


FLUID = hopper_fluid()
ETA_PAS = float(FLUID["viscosity_Pas"])  # the zero-yield Perzyna liquid is Newtonian, eta / 2
OPEN = {"mechanical": "open", "thermal": "insulated"}


def sphere_pair_case(
    r_over_h: float,
    tau_end: float,
    overrides: list[str] = (),
    octant: bool = False,
    on_nodes: bool = False,
) -> Case:
    """Two spheres of radius R_UM touching along x in a box of open walls, h = R / r_over_h,
    to tau_end (the centres off the nodes, as Hopper's pair). ``octant``: the eighth of the
    pair under three mirror walls (physics/mirror.py): the contact plane x = W (right), and
    the planes y = 0 (bottom) and z = 0 (front) through the centres, on node planes.
    ``on_nodes``: the whole pair placed as the octant's unfolding (its centres and contact
    on node planes), the run an octant must reproduce."""
    h = R_UM / r_over_h
    box = (4.6 * R_UM, 3.6 * R_UM, 3.6 * R_UM)
    if octant or on_nodes:  # the octant's box, whole multiples of h, or twice it
        side = [h * math.ceil(0.5 * s / h) * (1 if octant else 2) for s in box]
    else:
        side = [h * math.ceil(s / h) for s in box]
    gamma = 36.3e-3  # the material's default surface tension (N/m)
    end_s = tau_end * 0.5 * ETA_PAS * R_UM * 1e-6 / gamma
    sphere = {"shape": "disc", "radius_um": R_UM, "material": "fluid"}
    boundary = {w: OPEN for w in ("left", "right", "bottom", "top", "front", "back")}
    if octant:
        bodies = [sphere | {"center_um": [side[0] - R_UM, 0.0, 0.0]}]
        mirror = {"mechanical": "mirror", "thermal": "insulated"}
        boundary |= {"right": mirror, "bottom": mirror, "front": mirror}
    else:
        off = (0.0, 0.0) if on_nodes else (0.377, 0.211)
        y, z = 0.5 * side[1] + off[0], 0.5 * side[2] + off[1]
        x0 = 0.5 * side[0] - R_UM
        bodies = [sphere | {"center_um": [x0 + 2 * R_UM * k, y, z]} for k in (0, 1)]
    data = {
        "case": {"name": "sphere_pair", "description": "3D coalescence of two liquid spheres"},
        "grid": {"spacing_um": h},
        "domain": {"dim": 3, "width_um": side[0], "height_um": side[1], "depth_um": side[2]},
        "bodies": bodies,
        "materials": {"fluid": FLUID},
        "physics": {"thermal": False, "gravity_m_s2": [0.0, 0.0, 0.0]},
        "boundary": boundary,
        "time": {"end_s": end_s},
        "solver": {"transfer": "apic"},
        "surface_tension": {"method": "surface_energy", "initial_stress": "none"},
        "contact": {"neck_section": "centres"},
    }
    for text in overrides:
        apply_override(data, text)
    return case_from_dict(data)


def full_pair_points(sim: Simulation, octant: bool) -> tuple[np.ndarray, np.ndarray, int]:
    """The pair's point positions (m) and colour weights (the mass colour m / (rho V_cell), or
    the volume colour where the force uses it), and which of them are the first sphere's count;
    an octant's points unfolded over its three mirror planes into the whole pair."""
    x, weight = sim.point_arrays(("x",))["x"], sim.necks.colour_weights()
    if not octant:
        order = np.argsort(sim.scene.body, kind="stable")
        return x[order], weight[order], int(np.sum(sim.scene.body == 0))
    side = np.asarray(sim.case.domain_um()) * 1e-6
    copies = []
    for sx in (1.0, -1.0):  # the first sphere (x < W), then its image beyond the contact plane
        for sy in (1.0, -1.0):
            for sz in (1.0, -1.0):
                c = np.empty_like(x)
                c[:, 0] = x[:, 0] if sx > 0 else 2.0 * side[0] - x[:, 0]
                c[:, 1] = side[1] + sy * x[:, 1]
                c[:, 2] = side[2] + sz * x[:, 2]
                copies.append(c)
    return np.concatenate(copies), np.tile(weight, 8), 4 * len(x)


def pair_measures(sim: Simulation, octant: bool) -> tuple[float, float]:
    """(neck x, half-length L) of the pair (m): x half the 3D neck of solver/neck_section.py on the
    whole pair's colour (filtered as ``contact.neck_colour`` says), L half the span of c >= 1/2
    along the line of centres; both tend to 2^(1/3) R as the pair coalesces into one sphere."""
    cfg = sim.state.cfg
    x, weight, first = full_pair_points(sim, octant)
    extent = x.max(axis=0) + 4 * cfg.h
    shape = tuple(int(math.ceil(e / cfg.h)) + 2 * cfg.off + 4 for e in extent)
    raw = point_colour(x, weight, cfg.h, cfg.lp, cfg.off, shape)
    field = sim.necks.section_colour(raw) - 0.5
    ca = np.average(x[:first], axis=0, weights=weight[:first])
    cb = np.average(x[first:], axis=0, weights=weight[first:])
    reach = pair_reach(R_UM * 1e-6, R_UM * 1e-6, 3)
    neck, _ = neck_section(field, cfg.h, cfg.off, ca, cb, reach)
    e = (cb - ca) / np.linalg.norm(cb - ca)
    s = np.arange(0.0, 2.0 * reach, cfg.h / 32.0)  # past 2 R, the touching pair's end
    mid = 0.5 * (ca + cb)
    half = []
    for sign in (1.0, -1.0):
        f = trilinear(field, cfg.h, cfg.off, mid + sign * s[:, None] * e, -1.0)
        k = int(np.nonzero(f >= 0.0)[0].max())  # the outermost crossing, linear between samples
        half.append(s[k] + (s[k + 1] - s[k]) * f[k] / (f[k] - f[k + 1]))
    return 0.5 * neck, 0.5 * (half[0] + half[1])


def coalesce(
    case: Case, frames: int, progress: bool = True, octant: bool = False
) -> list[dict[str, float]]:
    """Run the pair to its end in ``frames`` equal parts; per frame: tau, x / R, L / R, the
    volume change and the equivalent radius of the whole over R."""
    sim = Simulation(case)
    m = case.materials["fluid"]
    rate = m.surface_tension_N_m / (0.5 * m.viscosity_Pas * R_UM * 1e-6)
    v0 = float(sim.point_arrays(("volume0",))["volume0"].sum())
    n = max(1, round(case.time.end_s / frames / sim.dt))
    copies = 8.0 if octant else 1.0
    rows = []
    started = time.perf_counter()
    for k in range(frames + 1):
        if k:
            sim.advance_to(sim.t + n * sim.dt)
        neck, length = pair_measures(sim, octant)
        now = sim.point_arrays(("volume0", "J"))
        vol = float((now["volume0"] * now["J"]).sum())
        rows.append(
            {
                "tau": sim.t * rate,
                "x_over_R": neck / (R_UM * 1e-6),
                "length_over_R": length / (R_UM * 1e-6),
                "volume_change": vol / v0 - 1.0,
                "radius_over_R": np.cbrt(3.0 * copies * vol / (4.0 * math.pi)) / (R_UM * 1e-6),
                "steps": sim.steps,
                "wall_s": round(time.perf_counter() - started, 1),
            }
        )
        if progress:
            r = rows[-1]
            print(
                f"tau {r['tau']:.3f}: x/R {r['x_over_R']:.4f}, L/R {r['length_over_R']:.4f}, "
                f"volume {r['volume_change']:+.3%}, {r['wall_s']:.0f} s",
                file=sys.stderr,
            )
    return rows


def csv_name(r_over_h: float, octant: bool) -> str:
    """sphere_pair_r<R/h>[_octant].csv: one table per resolution and domain."""
    return f"sphere_pair_r{r_over_h:g}{'_octant' if octant else ''}.csv"


def main(args: argparse.Namespace) -> int:
    if args.plot:
        return report_main(args.plot, Path(args.out))
    case = sphere_pair_case(args.r_over_h, args.tau, args.set, octant=args.octant)
    rows = coalesce(case, args.frames, octant=args.octant)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_rows(out / csv_name(args.r_over_h, args.octant), rows)
    last = rows[-1]
    print(
        f"sphere pair, R/h = {args.r_over_h:g}: x/R {last['x_over_R']:.3f} at tau "
        f"{last['tau']:.2f}, volume {last['volume_change']:+.2%}, whole "
        f"{last['radius_over_R']:.4f} R (coalesced: 2^(1/3) = {2 ** (1 / 3):.4f})"
    )
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("spherepair", help="3D coalescence of two liquid spheres (x/R vs tau)")
    ap.add_argument("--r-over-h", type=float, default=8.0, help="R / h (default 8)")
    ap.add_argument("--tau", type=float, default=3.8, help="tau = gamma t / (eta_N R) to reach")
    ap.add_argument("--frames", type=int, default=19, help="frames over the run")
    ap.add_argument("--out", default="renders", help="folder for sphere_pair_r*.csv")
    ap.add_argument(
        "--plot",
        nargs="+",
        metavar="CSV",
        help="no run: draw these tables (one per R/h) beside Frenkel and Pokluda et al. "
        "into OUT/sphere_pair.png and print how they converge",
    )
    ap.add_argument(
        "--octant",
        action="store_true",
        help="run the eighth of the pair under three mirror walls (8x fewer points)",
    )
    add_set_argument(ap, "override of the case")
    ap.set_defaults(func=main)
