"""The accuracy study: ``taichi-sls bench accuracy [--quick] [--out DIR]``.

Runs every verification case (:mod:`taichi_sls.studies.verification`) at three or more resolutions,
the transfers (APIC, FLIP, PIC/FLIP 0.9) where they differ and f32 against f64, and writes
``accuracy.csv`` (case, kind, resolution, h_um, dt_s, measure, error, wall_s, steps, transfer,
precision) and the plots ``accuracy_convergence.png`` (error against h, observed order),
``accuracy_cost.png`` (error against wall time), ``accuracy_precision.png`` and
``accuracy_transfer.png``. ``--paper`` instead runs the paper's 25 W case at h = 4, 2, 1 um to
1 ms (contact line, peak temperature, wall time) into ``paper_refinement.csv``.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from taichi_sls.config import bundled_case, deep_update
from taichi_sls.studies import verification as ver
from taichi_sls.studies.verification.common import transfer_label

COLUMNS = (
    "case",
    "kind",
    "resolution",
    "h_um",
    "dt_s",
    "measure",
    "error",
    "wall_s",
    "steps",
    "transfer",
    "precision",
    "method",
)
TRANSFERS = {
    "apic": {"transfer": "apic"},
    "flip": {"transfer": "flip"},
    "pic_flip 0.9": {"transfer": "pic_flip", "flip_ratio": 0.9},
}


@dataclass
class Study:
    """One verification case in the study: its resolutions (full, quick), the measure plotted,
    and the variants (transfers, f32) run at the resolutions listed for them."""

    name: str
    resolutions: tuple[float, ...]
    quick: tuple[float, ...]
    measure: str
    sets: dict = field(default_factory=dict)
    transfers_at: tuple[float, ...] = ()
    f32_at: tuple[float, ...] = ()
    csf_at: tuple[float, ...] = ()  # capillary cases: the paper's CSF beside the default force
    case: str = ""  # the verification case file (default: the name)
    on_request: bool = False  # run only when --only names it (the 3D cases: tens of minutes)

    @property
    def file(self) -> str:
        return self.case or self.name


# Resolutions: the coarse end that keeps the full study under ~25 minutes on two cores.
STUDIES = (
    Study(
        "bar",
        (8, 16, 32, 64),
        (8, 16, 32),
        "com_velocity",
        transfers_at=(8, 16, 32),
        f32_at=(8, 16, 32),
    ),
    Study("bar_large", (8, 16, 32), (16,), "com_velocity"),
    Study("steffen", (8, 16, 32), (8, 16), "displacement_rms", transfers_at=(32,)),
    Study("perzyna", (200, 400, 800), (200, 400), "rate_vs_closed_form"),
    Study("finite_strain", (500, 1000, 2000), (500,), "maxwell_shear"),
    Study("erf", (4.0, 2.0, 1.0), (4.0, 2.0), "temperature_rms", f32_at=(2.0,)),
    Study("gaussian", (4.0, 2.0, 1.0), (4.0, 2.0), "temperature_rms", f32_at=(2.0,)),
    Study("stefan", (25, 50, 100), (25,), "melt_front"),
    Study("spot3d", (8.0, 4.0, 2.0), (8.0, 4.0), "centre"),  # 3D: 25 min at h = 2 um
    Study("energy", (4.0, 2.0), (4.0,), "energy_balance", f32_at=(4.0,)),
    Study("curvature", (10, 20, 40), (10, 20), "curvature_mean"),
    Study("laplace", (10, 20, 40), (10,), "pressure", csf_at=(10, 20, 40)),
    Study("square", (4.0, 2.0, 1.0), (4.0,), "mode4_left", csf_at=(4.0, 2.0, 1.0)),
    Study(
        "viscous_decay",
        (10, 20, 40),
        (10,),
        "decay_rate",
        transfers_at=(20,),
        csf_at=(10, 20, 40),
    ),
    Study(
        "inviscid",
        (10, 20, 40),
        (10,),
        "period",
        transfers_at=(20,),
        f32_at=(20,),
        csf_at=(10, 20, 40),
    ),
    Study("hopper", (10, 20, 40), (10,), "neck_tau1", csf_at=(10,)),
    Study(
        "hopper_cell",
        (10, 20),
        (),
        "neck_tau1",
        sets={"verification": {"hopper_midplane": "cell"}},
        case="hopper",
    ),
    Study(  # the 2D counterpart of hopper3d_45deg
        "hopper_45deg",
        (10, 20),
        (10,),
        "neck_tau1",
        sets={"verification": {"hopper_angle_deg": 45.0}},
        case="hopper",
    ),
    Study("hopper_shape", (10, 20), (), "neck_tau1"),
    Study(  # from Hopper's outline at tau0 = 0.5, beside the same pair turned by 45 deg
        "hopper_shape_tau0.5",
        (10, 20),
        (),
        "neck_tau1",
        sets={"verification": {"hopper_tau0": 0.5}},
        case="hopper_shape",
    ),
    Study(
        "hopper_shape_45deg",
        (10, 20),
        (),
        "neck_tau1",
        sets={"verification": {"hopper_tau0": 0.5, "hopper_angle_deg": 45.0}},
        case="hopper_shape",
    ),
    Study("hopper_pa12", (10, 20), (10,), "neck_tau1"),  # the implicit integrator's
    Study("laplace3d", (10,), (10,), "pressure", on_request=True),
    Study("inviscid3d", (10,), (10,), "period", on_request=True),
    Study("viscous_decay3d", (10,), (10,), "decay_rate", on_request=True),
    Study("hopper3d", (10,), (10,), "neck_tau1", on_request=True),  # 2 cells of periodic depth
    Study(
        "hopper3d_45deg",
        (10,),
        (10,),
        "neck_tau1",
        sets={"verification": {"hopper_angle_deg": 45.0}},
        case="hopper3d",
        on_request=True,
    ),
    Study(  # the 3D pair at the resolution, to tau = 2 (about an hour on one core)
        "hopper3d_r20",
        (20,),
        (20,),
        "neck_tau1",
        sets={"verification": {"hopper_taus": [0.5, 1.0, 2.0]}},
        case="hopper3d",
        on_request=True,
    ),
    Study(  # the same pair turned by 45 deg in the plane
        "hopper3d_45deg_r20",
        (20,),
        (20,),
        "neck_tau1",
        sets={"verification": {"hopper_taus": [0.5, 1.0, 2.0], "hopper_angle_deg": 45.0}},
        case="hopper3d",
        on_request=True,
    ),
    Study(  # from Hopper's outline at tau0 = 0.5 (a prism), as the 2D turned row starts
        "hopper3d_shape_r20",
        (20,),
        (20,),
        "neck_tau1",
        sets={"verification": {"hopper_taus": [0.5, 1.0, 2.0], "hopper_tau0": 0.5}},
        case="hopper3d",
        on_request=True,
    ),
    Study(  # the same outline turned by 45 deg in the plane
        "hopper3d_shape_45deg_r20",
        (20,),
        (20,),
        "neck_tau1",
        sets={
            "verification": {
                "hopper_taus": [0.5, 1.0, 2.0],
                "hopper_tau0": 0.5,
                "hopper_angle_deg": 45.0,
            }
        },
        case="hopper3d",
        on_request=True,
    ),
)


def _row(s: Study, kind: str, res: float, r: ver.Result, measure: str, error: float) -> dict:
    return {
        "case": s.name,
        "kind": kind,
        "resolution": res,
        "h_um": r.h_um,
        "dt_s": r.dt_s,
        "measure": measure,
        "error": error,
        "wall_s": round(r.wall_s, 3),
        "steps": r.steps,
        "transfer": r.transfer,
        "precision": r.precision,
        "method": r.method,
    }


def run_study(quick: bool, out: Path, only: list[str] | None = None) -> list[dict]:
    """Run the study, appending rows to OUT/accuracy.csv as they finish; returns the rows."""
    out.mkdir(parents=True, exist_ok=True)
    rows: list[dict] = []
    path = out / "accuracy.csv"
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS)
        w.writeheader()
        for s in STUDIES:
            if (only or s.on_request) and s.name not in (only or ()):
                continue
            kind = ver.load(s.file).spec.kind
            res_list = s.quick if quick else s.resolutions
            jobs: list[tuple[float, dict]] = [(r, {}) for r in res_list]
            if not quick:
                own = transfer_label(ver.load(s.file).case)
                for r in s.transfers_at:
                    jobs += [(r, {"solver": t}) for k, t in TRANSFERS.items() if k != own]
                jobs += [(r, {"solver": {"precision": "f32"}}) for r in s.f32_at]
                jobs += [(r, {"surface_tension": {"method": "csf"}}) for r in s.csf_at]
            for res, extra in jobs:
                sets = deep_update(s.sets, extra)
                try:
                    r = ver.run(ver.load(s.file, res, sets))
                except Exception as e:  # a failing case is a row, never the end of the study
                    print(f"{s.name} at {res}: {type(e).__name__}: {e}", file=sys.stderr)
                    continue
                for measure, err in r.errors.items():
                    row = _row(s, kind, res, r, measure, err)
                    rows.append(row)
                    w.writerow(row)
                fh.flush()
                print(
                    f"{s.name:14s} {res:>6g} {r.transfer:13s} {r.precision} "
                    + " ".join(f"{k} {v:+.3e}" for k, v in r.errors.items())
                    + f"  ({r.wall_s:.1f} s, {r.steps} steps)",
                    file=sys.stderr,
                    flush=True,
                )
    return rows


# ------------------------------------------------------------------------------ paper case


PAPER_COLUMNS = ("h_um", "dt_s", "steps", "contact_line_um", "T_peak_C", "wall_s", "status")


def run_paper(spacings: list[float], out: Path, end_s: float = 1e-3) -> list[dict]:
    """cases/power25W.toml at each spacing, dt = 2.5e-8 s per um of h (the paper's 5e-8 s at
    h = 2 um, scaled with the elastic limit), to ``end_s``: contact line and peak temperature."""
    from taichi_sls.config import load_case
    from taichi_sls.solver.guard import SimulationError
    from taichi_sls.solver.simulation import Simulation

    out.mkdir(parents=True, exist_ok=True)
    path = out / "paper_refinement.csv"
    rows = []
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=PAPER_COLUMNS)
        w.writeheader()
        for h in spacings:
            case = load_case(
                bundled_case("power25W"),
                [f"grid.spacing_um={h}", f"time.dt_s={2.5e-8 * h}", f"time.end_s={end_s}"],
            )
            t0 = time.perf_counter()
            sim = Simulation(case)
            status = "complete"
            try:
                n = int(round(end_s / sim.dt))
                for k in range(10):  # monitors (and the guard) ten times over the run
                    sim.advance_to(sim.t + (n * (k + 1) // 10 - n * k // 10) * sim.dt)
                    mon = sim.monitors()
            except SimulationError as e:
                status = f"failed: {e}"
                mon = {"contact_line_um": math.nan, "T_peak_C": math.nan}
            row = {
                "h_um": h,
                "dt_s": sim.dt,
                "steps": sim.steps,
                "contact_line_um": round(mon["contact_line_um"], 3),
                "T_peak_C": round(mon["T_peak_C"], 2),
                "wall_s": round(time.perf_counter() - t0, 1),
                "status": status,
            }
            rows.append(row)
            w.writerow(row)
            fh.flush()
            print(row, file=sys.stderr, flush=True)
    return rows


# ------------------------------------------------------------------------------ command line


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``accuracy`` with the bench dispatcher."""
    p = sub.add_parser("accuracy", help="verification cases against analytic solutions")
    p.add_argument("--quick", action="store_true", help="two resolutions, no variants (~2 min)")
    p.add_argument("--out", default="renders", help="folder for the CSV and plots")
    p.add_argument("--only", nargs="*", metavar="CASE", help="only these verification cases")
    p.add_argument(
        "--paper",
        nargs="*",
        type=float,
        metavar="H_UM",
        help="instead: the 25 W paper case to 1 ms at these spacings (default 4 2 1)",
    )
    p.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    if args.paper is not None:
        run_paper(args.paper or [4.0, 2.0, 1.0], out)
        return 0
    from bench.accuracy_plots import plot, summary_table

    t0 = time.perf_counter()
    rows = run_study(args.quick, out, args.only)
    for p in plot(rows, out, STUDIES, TRANSFERS):
        print(f"wrote {p}", file=sys.stderr)
    print(summary_table(rows, STUDIES))
    print(f"accuracy study: {len(rows)} rows in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    return 0
