"""Run every Table 2 case (fine and coarse) plus ``nolaser`` and tabulate what the paper reports.

    taichi-sls bench paper [--out out/paper] [--optimize] [--only power25W ...] [--plots]
        [--set key=value ...]

Each case writes its usual outputs to OUT/<case>/ (a case already complete there is read, not run
again). Prints a Markdown table and writes OUT/table.csv: peak temperature, contact line at the
start, at 1 ms, when refrozen and at the end, neck span, the verdict, status, steps and wall time
(``--set time.stop=solidified`` runs every case until it has refrozen). ``--optimize``
compiles with Taichi's advanced optimisation (about 100 s once, then 1.5x faster steps).
``--plots`` draws Figs. 5 and 8 from the fine cases (nolaser as 0 W) into OUT.
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

from ..config import load_case
from ..config.loading import add_set_argument
from ..jobs.case_run import complete_summary, run_case

BASES = ["power5W", "power15W", "power25W", "radius30um", "radius70um", "scan4mps"]


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("paper", help="every Table 2 case and nolaser, tabulated")
    ap.add_argument("--out", default="out/paper", help="folder for the runs and table.csv")
    ap.add_argument("--optimize", action="store_true", help="Taichi's advanced optimisation")
    ap.add_argument("--only", nargs="*", metavar="CASE", help="only these cases")
    ap.add_argument(
        "--plots", action="store_true", help="draw Figs. 5 and 8 from the fine cases into OUT"
    )
    add_set_argument(ap, "case override for every case")
    ap.set_defaults(func=main)


def _um(v: float | None) -> float | None:
    return None if v is None else round(v, 2)


def _row(name: str, s: dict) -> dict:
    """One table row from a run's summary: the state at the end and the fusion outcome."""
    fin, ini, o = s["final"], s["initial"], s.get("outcome", {})
    return {
        "case": name,
        "status": s["status"],
        "t_end_ms": round(s["simulated_s"] * 1e3, 4),
        "T_peak_C": round(fin["T_peak_C"], 1),
        "contact_line_start_um": round(ini["contact_line_um"], 2),
        "neck_1ms_um": _um(o.get("neck_1ms_um")),
        "neck_refrozen_um": _um(o.get("neck_refrozen_um")),
        "contact_line_end_um": round(fin["contact_line_um"], 2),
        "neck_span_end_um": round(fin.get("neck_span_um", float("nan")), 2),
        "refrozen_ms": None if o.get("refrozen_s") is None else round(o["refrozen_s"] * 1e3, 2),
        "fused": o.get("fused"),
        "J_min_end": round(fin["J_min"], 3),
        "steps": s["steps"],
        "wall_s": round(s["wall_s"], 1),
        "steps_per_s": round(s["steps_per_s"]),
    }


def _figures(out: Path, rows: list[dict]) -> None:
    """Figs. 5 and 8 from the fine cases and nolaser (0 W), through the sweep's plots: their
    rows as OUT/results.csv, one id per case folder."""
    from .sweep.draw import draw_all
    from .sweep.results import write_results

    fine = [
        {**r, "id": r["case"], "neck_final_um": r["contact_line_end_um"]}
        for r in rows
        if not r["case"].endswith("_coarse")
    ]
    write_results(out, fine, ["id", "status", "T_peak_C", "neck_1ms_um", "neck_final_um", "fused"])
    for p in draw_all(out):
        print(f"wrote {p}")


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    names = [b + s for s in ("", "_coarse") for b in BASES] + ["nolaser"]
    if args.only:
        names = [n for n in names if n in args.only]
    rows = []
    for name in names:
        folder = out / name
        s = complete_summary(folder)
        if s is None:
            sets = (["solver.optimize=true"] if args.optimize else []) + args.set
            case = load_case(name, sets)
            s = run_case(case, folder, progress=False)
        rows.append(_row(name, s))
    with (out / "table.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    if args.plots:
        _figures(out, rows)
    keys = list(rows[0])
    print("| " + " | ".join(keys) + " |")
    print("|" + "---|" * len(keys))
    for r in rows:
        print("| " + " | ".join(str(r[k]) for k in keys) + " |")
    return 0
