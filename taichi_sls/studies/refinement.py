"""The paper's cases under grid and time-step refinement: ``taichi-sls bench refinement``.

    taichi-sls bench refinement [--out out/refinement] [--cases power5W ...] [--spacings 4 2 1 0.5]
        [--dt-factors 1 0.5 0.25] [--at 2] [--refrozen] [--set key=value ...]

Runs each bundled case (default power5W, power15W, power25W, nolaser) at each grid spacing h
(default 4, 2, 1, 0.5 um) to 1 ms with dt = 2.5e-8 s per um of h (the paper's 5e-8 s at
h = 2 um, scaled with the elastic limit, as ``bench accuracy --paper``), and at the spacing
``--at`` (2 um) also with dt times each ``--dt-factors`` (1/2, 1/4). ``--refrozen`` runs
h = 4, 2, 1 um until the pair has refrozen (``time.stop = "solidified"``) into
out/refinement_refrozen. ``--set`` overrides every run's case (after the study's own keys);
where it sets ``time.dt_s=auto`` a dt factor scales ``time.safety`` instead, and the accuracy
controls of an adaptive (or hybrid) implicit step with it.

Each run writes its usual outputs to OUT/<case>/h<h>um_dt<factor>/; a run already finished there
(complete, or stopped by the guard, with the same resolved case.toml) is read, not run again, so
an interrupted study resumes. Writes OUT/refinement.csv (one row per run), OUT/refinement_table.md
(printed: per case and quantity the three finest spacings' values, the observed order, the
Richardson estimate, the distance of the h = ``--at`` value to it, the dt sensitivity) and
OUT/refinement.png.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
from pathlib import Path
from typing import Any

from ..config import Case, CaseError, case_to_toml, load_case
from ..config.loading import add_set_argument
from .refinement_report import num, plot, read_csv, write_table

CASES = ("power5W", "power15W", "power25W", "nolaser")
SPACINGS = (4.0, 2.0, 1.0, 0.5)
REFROZEN_SPACINGS = (4.0, 2.0, 1.0)
DT_FACTORS = (1.0, 0.5, 0.25)
DT_PER_UM = 2.5e-8  # s per um of h: the paper's 5e-8 s at h = 2 um, scaled like the elastic limit
# ends that count as done: a run the guard stopped would fail the same way again on the CPU
DONE = ("complete", "failed", "max_time")
COLUMNS = (
    "case",
    "stop",
    "h_um",
    "dt_factor",
    "dt_s",
    "status",
    "failure",
    # which measure the neck columns hold: the summary's contact line today; a per-contact neck
    # measure can fill the same columns under its own name
    "neck_measure",
    "neck_initial_um",
    "neck_1ms_um",
    "neck_refrozen_um",
    "neck_final_um",
    "refrozen_ms",
    "T_peak_C",
    "J_min",
    "points",
    "steps",
    "simulated_s",
    "wall_s",
    "step_wall_s",
    "folder",
)

# ------------------------------------------------------------------------------ runs


def plan(
    cases: list[str], spacings: list[float], factors: list[float], at: float
) -> list[tuple[str, float, float]]:
    """(case, h, dt factor): every spacing at the default dt, and the spacing ``at`` at every
    factor (the dt runs cost a factor 1/f each: only where the table reads them)."""
    runs = []
    for c in cases:
        runs += [(c, h, 1.0) for h in spacings]
        runs += [(c, at, f) for f in (1.0, *factors)]
    return list(dict.fromkeys(runs))


def _round(v: Any, nd: int) -> float:
    return round(num(v), nd)


def _failed_row(case: str, h: float, f: float, stop: str, status: str, why: str) -> dict:
    return {
        **dict.fromkeys(COLUMNS, ""),
        "case": case,
        "stop": stop,
        "h_um": h,
        "dt_factor": f,
        "dt_s": DT_PER_UM * h * f,
        "status": status,
        "failure": why,
    }


def _row(case: str, h: float, f: float, stop: str, folder: Path, s: dict) -> dict:
    from ..io.series import read_series

    o, fin = s.get("outcome", {}), s.get("final", {})
    series = folder / "timeseries.csv"
    j = read_series(series).get("J_min") if series.is_file() else None
    # the smallest J of the run (the guard's measure of the neck's compression), not the last
    j_min = float(min(j)) if j is not None and len(j) else num(fin.get("J_min"))
    refrozen = o.get("refrozen_s")
    return {
        "case": case,
        "stop": stop,
        "h_um": h,
        "dt_factor": f,
        "dt_s": s["dt_s"],
        "status": s["status"],
        "failure": s.get("error", ""),
        "neck_measure": "contact_line",
        "neck_initial_um": _round(o.get("neck_initial_um"), 3),
        "neck_1ms_um": _round(o.get("neck_1ms_um"), 3),
        "neck_refrozen_um": _round(o.get("neck_refrozen_um"), 3),
        "neck_final_um": _round(fin.get("contact_line_um"), 3),
        "refrozen_ms": _round(refrozen * 1e3, 4) if refrozen is not None else math.nan,
        "T_peak_C": _round(fin.get("T_peak_C"), 2),  # the running maximum of the run
        "J_min": round(j_min, 4),
        "points": s.get("points"),
        "steps": s["steps"],
        "simulated_s": round(s["simulated_s"], 9),
        "wall_s": round(s["wall_s"], 1),
        "step_wall_s": round(s["step_wall_s"], 1),
        "folder": str(folder),
    }


def _step_scaling(c: Case, f: float) -> list[str]:
    """Overrides that scale the step by ``f`` where the case chooses it itself: with
    ``time.dt_s = "auto"`` the safety fraction of the stability limit, and where an adaptive
    implicit step follows (``Case.step_adapts``) its accuracy controls too, so that a dt factor
    still refines every step of the run."""
    t = c.time
    if t.dt_s != "auto":
        return []
    keys = [f"time.safety={t.safety * f:.6g}"]
    if c.step_adapts():
        keys += [
            f"time.{k}={getattr(t, k) * f:.6g}"
            for k in ("max_temperature_change_K", "max_motion_cells", "max_strain_increment")
        ]
    return keys


def run_one(
    case: str, h: float, f: float, out: Path, refrozen: bool, sets: list[str]
) -> dict[str, Any]:
    """One run (or the one already finished in its folder) as a row; a run the guard stops, or
    a case refused before it starts, is a row with its failure."""
    from ..jobs.case_run import complete_summary, run_case

    stop = "solidified" if refrozen else "end"
    folder = out / Path(case).stem / f"h{h:g}um_dt{f:g}"  # a case file: its name, not its path
    own = [f"grid.spacing_um={h}", f"time.dt_s={DT_PER_UM * h * f:.6g}"]
    own += ["time.stop=solidified"] if refrozen else ["time.end_s=1e-3"]
    own += ["output.png=false", "output.gif=false"]  # the frames would cost more than the steps
    try:
        c = load_case(case, [*own, *sets])
        if f != 1.0:  # a --set time.dt_s=auto replaced the study's dt: scale what sets the step
            c = load_case(case, [*own, *sets, *_step_scaling(c, f)])
        s = complete_summary(folder, DONE)
        toml = folder / "case.toml"
        if s is not None and (not toml.is_file() or toml.read_text() != case_to_toml(c.given or c)):
            print(f"{folder}: its case.toml differs from this study's: run again", file=sys.stderr)
            s = None
        if s is None:
            s = run_case(c, folder, progress=False)
    except CaseError as e:
        return _failed_row(case, h, f, stop, "refused", str(e))
    except Exception as e:  # noqa: BLE001 -- a run that breaks is a row, never the study's end
        return _failed_row(case, h, f, stop, "error", f"{type(e).__name__}: {e}")
    return _row(case, h, f, stop, folder, s)


def write_csv(rows: list[dict], path: Path) -> None:
    """Atomically: an interrupted study leaves the rows it had."""
    tmp = path.with_suffix(".csv.tmp")
    with tmp.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    tmp.replace(path)


def run_study(
    out: Path,
    cases: list[str],
    spacings: list[float],
    factors: list[float],
    at: float,
    refrozen: bool = False,
    sets: list[str] | None = None,
) -> list[dict]:
    """Every run of :func:`plan`, OUT/refinement.csv rewritten after each; returns the rows."""
    out.mkdir(parents=True, exist_ok=True)
    rows: list[dict] = []
    for case, h, f in plan(cases, spacings, factors, at):
        row = run_one(case, h, f, out, refrozen, sets or [])
        rows.append(row)
        write_csv(rows, out / "refinement.csv")
        print(
            f"{case:10s} h {h:g} um dt {num(row['dt_s']):.3g} s {row['status']:10s} neck "
            f"{row['neck_initial_um']} -> {row['neck_1ms_um']} (1 ms) {row['neck_refrozen_um']} "
            f"(refrozen), T {row['T_peak_C']} C, J_min {row['J_min']}, {row['steps']} steps, "
            f"{row['wall_s']} s {row['failure'][:120]}",
            file=sys.stderr,
            flush=True,
        )
        if row["status"] == "interrupted":  # Ctrl-C ends the study, not just the run
            break
    return rows


# ------------------------------------------------------------------------------ command line

DESCRIPTION = (
    "The paper's cases under refinement: each case at each spacing to 1 ms (dt = 2.5e-8 s per "
    "um of h), and at h = --at at every dt factor; writes refinement.csv, refinement_table.md "
    "(observed order, Richardson estimate, dt sensitivity) and refinement.png. Finished runs "
    "are read, not run again. Run time goes as points x steps, plus the compilation of each "
    "run: each halving of h takes 4x the points and 2x the steps, so the finest spacing costs "
    "most; --refrozen runs on to refreezing (20-40 ms, 20-40x the steps). "
    "docs/record/convergence.md records such runs."
)


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser(
        "refinement",
        help="the paper's cases under grid and dt refinement: observed order, Richardson",
        description=DESCRIPTION,
    )
    ap.add_argument("--out", help="folder for the runs and outputs (default out/refinement)")
    ap.add_argument(
        "--cases",
        nargs="+",
        default=list(CASES),
        metavar="CASE",
        help="bundled cases or case files (default: power5W power15W power25W nolaser)",
    )
    ap.add_argument(
        "--spacings",
        nargs="+",
        type=float,
        metavar="H_UM",
        help="spacings (default 4 2 1 0.5; refrozen 4 2 1)",
    )
    ap.add_argument(
        "--dt-factors",
        nargs="+",
        type=float,
        default=list(DT_FACTORS),
        metavar="F",
        help="dt multiples run at h = --at (default 1 0.5 0.25)",
    )
    ap.add_argument(
        "--at", type=float, default=2.0, help="spacing of the dt runs and the distance (2 um)"
    )
    ap.add_argument(
        "--refrozen",
        action="store_true",
        help='run until refrozen (time.stop = "solidified"), default h = 4 2 1, into '
        "out/refinement_refrozen",
    )
    add_set_argument(ap, "case override for every run")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out or ("out/refinement_refrozen" if args.refrozen else "out/refinement"))
    spacings = args.spacings or list(REFROZEN_SPACINGS if args.refrozen else SPACINGS)
    rows = run_study(out, args.cases, spacings, args.dt_factors, args.at, args.refrozen, args.set)
    print(write_table(out / "refinement.csv", out / "refinement_table.md", args.at))
    plot(read_csv(out / "refinement.csv"), out / "refinement.png", args.at)
    print(f"wrote {out / 'refinement.csv'}, refinement_table.md, refinement.png", file=sys.stderr)
    return 1 if any(r["status"] == "interrupted" for r in rows) else 0
