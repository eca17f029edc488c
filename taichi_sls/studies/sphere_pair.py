"""Two touching spheres of a Maxwell liquid coalescing under surface tension, no heat
(``domain.dim = 3``): ``taichi-sls bench spherepair [--r-over-h 8] [--tau 3.8] [--out renders]``.

The 3D counterpart of Hopper's pair (cases/verification/hopper.toml): the same zero-yield
Perzyna liquid (eta_N = eta / 2 = 0.3 Pa s, Maxwell time 1 us) and surface-energy force, as
spheres of radius R = 20 um. The neck x is half the 3D neck of solver/section3d.py (the
area-equivalent radius of the narrowest c = 1/2 section across the centres); it is reported as
x / R against tau = gamma t / (eta_N R), with the volume change (sum of V0 J over the points)
and, at the end, the equivalent radius of the whole against the coalesced sphere's 2^(1/3) R.
No closed form is checked: 3D sphere coalescence has none (Hopper's is 2D); the figures are the
run's (earlier at R/h = 8 to tau 3.8: x/R 0.876 at 1, 1.085 at 2, 1.177 at 3, 1.212 at 3.8,
volume -0.16 %). Writes sphere_pair.csv. An explicit run: about 2e5 steps at R/h = 8 (a GPU's
work; R/h = 4 is a quick look).
"""

from __future__ import annotations

import argparse
import math
import sys
import tomllib
from pathlib import Path

import numpy as np

from ..config import Case, case_from_dict
from ..config.loading import add_set_argument, apply_override, bundled_case
from ..io.atomic import write_rows
from ..solver.simulation import Simulation

R_UM = 20.0


def hopper_fluid() -> dict[str, object]:
    """Hopper's viscous liquid as cases/verification/hopper.toml defines it (mu = 3e5 Pa,
    eta = 0.6 Pa s: eta_N = 0.3 Pa s, Maxwell time 1 us), its one material table."""
    with open(bundled_case("verification/hopper"), "rb") as f:
        return dict(tomllib.load(f)["materials"]["fluid"])


FLUID = hopper_fluid()
ETA_PAS = float(FLUID["viscosity_Pas"])  # the zero-yield Perzyna liquid is Newtonian, eta / 2
OPEN = {"mechanical": "open", "thermal": "insulated"}


def sphere_pair_case(r_over_h: float, tau_end: float, overrides: list[str] = ()) -> Case:
    """Two spheres of radius R_UM touching along x in a box of open walls, h = R / r_over_h,
    to tau_end (the centres off the nodes, as Hopper's pair)."""
    h = R_UM / r_over_h
    side = [4.6 * R_UM, 3.6 * R_UM, 3.6 * R_UM]
    side = [h * math.ceil(s / h) for s in side]
    y, z = 0.5 * side[1] + 0.377, 0.5 * side[2] + 0.211
    x0 = 0.5 * side[0] - R_UM
    gamma = 36.3e-3  # the material's default surface tension (N/m)
    end_s = tau_end * 0.5 * ETA_PAS * R_UM * 1e-6 / gamma
    data = {
        "case": {"name": "sphere_pair", "description": "3D coalescence of two liquid spheres"},
        "grid": {"spacing_um": h},
        "domain": {"dim": 3, "width_um": side[0], "height_um": side[1], "depth_um": side[2]},
        "bodies": [
            {"shape": "disc", "center_um": [x0, y, z], "radius_um": R_UM, "material": "fluid"},
            {
                "shape": "disc",
                "center_um": [x0 + 2 * R_UM, y, z],
                "radius_um": R_UM,
                "material": "fluid",
            },
        ],
        "materials": {"fluid": FLUID},
        "physics": {"thermal": False, "gravity_m_s2": [0.0, 0.0, 0.0]},
        "boundary": {w: OPEN for w in ("left", "right", "bottom", "top", "front", "back")},
        "time": {"end_s": end_s},
        "solver": {"transfer": "apic"},
        "surface_tension": {"method": "surface_energy", "initial_stress": "none"},
        "contact": {"neck_section": "centres"},
    }
    for text in overrides:
        apply_override(data, text)
    return case_from_dict(data)


def coalesce(case: Case, frames: int, progress: bool = True) -> list[dict[str, float]]:
    """Run the pair to its end in ``frames`` equal parts; per frame: tau, x / R, the volume
    change and the equivalent radius of the whole over R."""
    sim = Simulation(case)
    m = case.materials["fluid"]
    rate = m.surface_tension_N_m / (0.5 * m.viscosity_Pas * R_UM * 1e-6)
    v0 = float(sim.point_arrays(("volume0",))["volume0"].sum())
    n = max(1, round(case.time.end_s / frames / sim.dt))
    rows = []
    for k in range(frames + 1):
        if k:
            sim.advance(n)
        neck = sim.necks_m()[0]
        now = sim.point_arrays(("volume0", "J"))
        vol = float((now["volume0"] * now["J"]).sum())
        rows.append(
            {
                "tau": sim.t * rate,
                "x_over_R": 0.5 * neck / (R_UM * 1e-6),
                "volume_change": vol / v0 - 1.0,
                "radius_over_R": np.cbrt(3.0 * vol / (4.0 * math.pi)) / (R_UM * 1e-6),
            }
        )
        if progress:
            r = rows[-1]
            print(
                f"tau {r['tau']:.3f}: x/R {r['x_over_R']:.4f}, volume {r['volume_change']:+.3%}",
                file=sys.stderr,
            )
    return rows


def main(args: argparse.Namespace) -> int:
    case = sphere_pair_case(args.r_over_h, args.tau, args.set)
    rows = coalesce(case, args.frames)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_rows(out / "sphere_pair.csv", rows)
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
    ap.add_argument("--out", default="renders", help="folder for sphere_pair.csv")
    add_set_argument(ap, "override of the case")
    ap.set_defaults(func=main)
