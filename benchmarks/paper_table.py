"""Run every Table 2 case (fine and coarse) plus ``nolaser`` and tabulate what the paper reports.

    python benchmarks/paper_table.py [--out out/paper] [--optimize] [--only power25W ...]
        [--set key=value ...]

Each case writes its usual outputs to OUT/<case>/ (a case already complete there is read, not run
again). Prints a Markdown table and writes OUT/table.csv: peak temperature, contact line and neck
span at the end, status, steps per second. ``--optimize`` compiles with Taichi's advanced
optimisation (about 100 s once, then 1.5x faster steps).
"""

from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

from taichi_sls.case import load_case
from taichi_sls.run import run_case

ROOT = Path(__file__).resolve().parents[1]
BASES = ["power5W", "power15W", "power25W", "radius30um", "radius70um", "scan4mps"]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="out/paper")
    ap.add_argument("--optimize", action="store_true")
    ap.add_argument("--only", nargs="*")
    ap.add_argument("--set", action="append", default=[], help="case override for every case")
    args = ap.parse_args()
    out = Path(args.out)
    names = [b + s for s in ("", "_coarse") for b in BASES] + ["nolaser"]
    if args.only:
        names = [n for n in names if n in args.only]
    rows = []
    for name in names:
        folder = out / name
        summ = folder / "summary.json"
        s = json.loads(summ.read_text()) if summ.is_file() else None
        if s is None or s.get("status") != "complete":
            sets = (["solver.optimize=true"] if args.optimize else []) + args.set
            case = load_case(ROOT / "cases" / f"{name}.toml", sets)
            s = run_case(case, folder, progress=False)
        fin, ini = s["final"], s["initial"]
        rows.append(
            {
                "case": name,
                "status": s["status"],
                "t_end_ms": round(s["simulated_s"] * 1e3, 4),
                "T_peak_C": round(fin["T_peak_C"], 1),
                "contact_line_start_um": round(ini["contact_line_um"], 2),
                "contact_line_end_um": round(fin["contact_line_um"], 2),
                "neck_span_end_um": round(fin.get("neck_span_um", float("nan")), 2),
                "J_min_end": round(fin["J_min"], 3),
                "steps_per_s": round(s["steps_per_s"]),
            }
        )
    with (out / "table.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    keys = list(rows[0])
    print("| " + " | ".join(keys) + " |")
    print("|" + "---|" * len(keys))
    for r in rows:
        print("| " + " | ".join(str(r[k]) for k in keys) + " |")


if __name__ == "__main__":
    main()
