"""A 3D layer's answers over grids and bed draws: ``taichi-sls bench bedgrid [--base CASE]
[--spacings 5 4 3.2] [--seeds 1 2 3] [--at H] [--out out/bedgrid] [--set KEY=VALUE ...]``.

Runs the base case (default ``machine_layer3d``: 48 spheres of median 20 um through the
machine's cycle and its 10 s layer time) at each grid spacing with its own bed (its
``bed.seed``), and at the spacing ``--at`` (default the case's own) with each seed: the same
sizes drawn and deposited again. Reads each run's bed record: the final relative density, its
gain over the layer time, the fraction of contacts melted through and fused, the median neck.
Then, per quantity, the observed order of the three finest spacings and the Richardson estimate
(studies/refinement_report.py; spacings in a constant ratio), the estimate were the error first
order (the wider bound where the observed order is high but rests on two small differences),
the distance of the ``--at`` value to both, and the spread over the seeds (range and sample
standard deviation).

Each run writes its usual outputs to OUT/h<h>um_seed<seed>/; a run already complete there with
the same case.toml (outputs aside) is read, not run again, so an interrupted study resumes and
the process study's runs of the same bed can be copied in. Writes
OUT/bedgrid.csv (one row per run), OUT/bedgrid.md (the table, printed) and OUT/bedgrid.png (each
quantity against h, the estimate and the seeds' range). A run of the default base at h = 4 um
takes some 11 min on 2 cores; the cost grows as about h^-3.5 (docs/record/convergence.md, "A 3D
layer over grids and seeds").
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import tomllib
from pathlib import Path

from taichi_sls.config import Case, CaseError, case_to_toml, load_case
from taichi_sls.config.loading import add_set_argument
from taichi_sls.io.atomic import atomic_write_text, write_rows
from taichi_sls.jobs.case_run import complete_summary, run_case
from taichi_sls.studies.refinement_report import num, rel_change, richardson

SPACINGS_UM = (5.0, 4.0, 3.2)
SEEDS = (1, 2, 3)
QUANTITIES = (
    ("density_final", "relative density at the end"),
    ("density_gain", "density gain over the layer"),
    ("melted_through_fraction", "contacts melted through"),
    ("fused_fraction", "contacts fused"),
    ("neck_median_um", "median neck at the end (um)"),
)
COLUMNS = [
    "h_um",
    "cells_across_d50",
    "seed",
    "status",
    "points",
    "contacts",
    *(key for key, _ in QUANTITIES),
    "steps",
    "wall_s",
    "folder",
]


def same_run(toml: Path, case: Case) -> bool:
    """Whether the run whose case.toml is ``toml`` is ``case``'s, outputs aside (frames, GIF:
    they change no answer), so that the process study's runs of the same bed count."""
    if not toml.is_file():
        return False
    stored, mine = tomllib.loads(toml.read_text()), tomllib.loads(case_to_toml(case.given or case))
    stored.pop("output", None)
    mine.pop("output", None)
    return stored == mine


def run_one(base: str, h: float, seed: int, out: Path, sets: list[str]) -> dict:
    """One run (or the one already complete in its folder) as a row."""
    folder = out / f"h{h:g}um_seed{seed}"
    row = {**dict.fromkeys(COLUMNS, ""), "h_um": h, "seed": seed, "folder": str(folder)}
    try:
        case = load_case(base, [*sets, f"grid.spacing_um={h}", f"bed.seed={seed}"])
    except CaseError as e:
        return row | {"status": f"refused: {e}"}
    s = complete_summary(folder)
    if s is not None and not same_run(folder / "case.toml", case):
        print(f"{folder}: its case.toml differs from this study's: run again", file=sys.stderr)
        s = None
    if s is None:
        s = run_case(case, folder, progress=False)
    row |= {"status": s["status"], "points": s.get("points"), "steps": s.get("steps")}
    row |= {"wall_s": round(s.get("wall_s", math.nan), 1)}
    bed = s.get("bed")
    if s["status"] != "complete" or bed is None:
        return row
    density = bed["relative_density"]
    n = bed["contacts"]
    return row | {
        "cells_across_d50": round((case.given or case).bed.median_diameter_um / h, 3),
        "contacts": n,
        "density_final": round(density["final"], 5),
        "density_gain": round(density["final"] - density["initial"], 5),
        "melted_through_fraction": round(bed["melted_through"] / n, 4) if n else math.nan,
        "fused_fraction": round(bed["fused_fraction"], 4),
        "neck_median_um": round(bed["neck_final_um"]["median"], 3),
    }


def analyse(rows: list[dict], at: float, seed: int) -> list[dict]:
    """Per quantity: the three finest spacings' values (the base's ``seed``), their order and
    Richardson estimate, the ``at`` value's distance to it, the seeds' spread at ``at``."""
    grid = {r["h_um"]: r for r in rows if r["seed"] == seed and r["status"] == "complete"}
    hs = sorted(grid, reverse=True)[-3:]
    ratios = [hs[k] / hs[k + 1] for k in range(len(hs) - 1)]
    constant = len(hs) == 3 and abs(ratios[0] - ratios[1]) <= 1e-6 * ratios[0]
    at_seeds = [r for r in rows if r["h_um"] == at and r["status"] == "complete"]
    out = []
    for key, label in QUANTITIES:
        vals = [num(grid[h][key]) for h in hs]
        ext = richardson(*vals, ratio=ratios[0]) if constant else None
        spread = [num(r[key]) for r in at_seeds]
        at_val = num(grid[at][key]) if at in grid else math.nan
        first = math.nan  # the estimate were the error first order: the wider bound
        if ext is not None and math.isfinite(ext.estimate):
            first = vals[2] + (vals[2] - vals[1]) / (ratios[0] - 1.0)
        out.append(
            {
                "quantity": label,
                "h_um": hs,
                "values": vals,
                "order": ext.order if ext else math.nan,
                "estimate": ext.estimate if ext else math.nan,
                "note": ext.note if ext else "three spacings in a constant ratio are needed",
                "at_vs_estimate": rel_change(ext.estimate, at_val) if ext else math.nan,
                "first_order": first,
                "at_vs_first_order": rel_change(first, at_val),
                "seeds": [r["seed"] for r in at_seeds],
                "seed_values": spread,
                "seed_sd": statistics.stdev(spread) if len(spread) > 1 else math.nan,
            }
        )
    return out


def table(results: list[dict], at: float) -> str:
    """The markdown table of :func:`analyse`."""
    if not results:
        return "no runs\n"
    hs = results[0]["h_um"]
    head = " | ".join(f"h = {h:g} um" for h in hs)
    lines = [
        f"| quantity | {head} | order | Richardson | h = {at:g} against it | at first order "
        f"| h = {at:g} against it | seeds at h = {at:g} | sd |",
        "|---|" + "---|" * (len(hs) + 7),
    ]

    def pct(v: float) -> str:
        return "-" if math.isnan(v) else f"{100 * v:+.1f} %"

    for r in results:
        vals = " | ".join(f"{v:.4g}" for v in r["values"])
        seeds = ", ".join(f"{v:.4g}" for v in r["seed_values"]) or "-"
        lines.append(
            f"| {r['quantity']} | {vals} | {r['order']:.2f} | {r['estimate']:.4g} {r['note']} | "
            f"{pct(r['at_vs_estimate'])} | {r['first_order']:.4g} | "
            f"{pct(r['at_vs_first_order'])} | {seeds} | {r['seed_sd']:.2g} |"
        )
    return "\n".join(lines) + "\n"


def plot(results: list[dict], path: Path, at: float) -> None:
    """Each quantity against h: the grids' values, the Richardson estimate at h = 0 and the
    seeds' range at ``at``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    shown = [r for r in results if any(math.isfinite(v) for v in r["values"])]
    fig, axes = plt.subplots(1, len(shown), figsize=(3.4 * len(shown), 3.2), squeeze=False)
    for ax, r in zip(axes[0], shown, strict=True):
        ax.plot(r["h_um"], r["values"], "o-", color="tab:blue", label="grids (one bed)")
        if math.isfinite(r["estimate"]):
            ax.plot([0.0], [r["estimate"]], "*", ms=11, color="tab:red", label="Richardson")
        if r["seed_values"]:
            lo, hi = min(r["seed_values"]), max(r["seed_values"])
            ax.errorbar(
                [at],
                [(lo + hi) / 2],
                yerr=[[(hi - lo) / 2]],
                fmt="none",
                capsize=5,
                color="tab:orange",
                label=f"{len(r['seed_values'])} beds",
            )
        ax.set(xlabel="h (um)", title=r["quantity"], xlim=(-0.3, max(r["h_um"]) * 1.1))
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("bedgrid", help="a 3D layer's density and contacts over grids and seeds")
    ap.add_argument(
        "--base", default="machine_layer3d", help="a bed case (default machine_layer3d)"
    )
    ap.add_argument(
        "--spacings",
        nargs="+",
        type=float,
        default=list(SPACINGS_UM),
        metavar="H_UM",
        help="grid spacings, coarse to fine (default 5 4 3.2)",
    )
    ap.add_argument(
        "--seeds",
        nargs="+",
        type=int,
        default=list(SEEDS),
        help="bed draws at --at (default 1 2 3)",
    )
    ap.add_argument("--at", type=float, help="the spacing of the seeds (default the case's own)")
    ap.add_argument("--out", default="out/bedgrid", help="folder for the runs and the table")
    add_set_argument(ap, "case override for every run")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    base = load_case(args.base, args.set)
    base = base.given or base  # the case as written: its bed before it becomes bodies
    if base.bed is None:
        raise CaseError(f"bench bedgrid: --base {args.base} has no [bed]: a bed case is needed")
    at = args.at if args.at is not None else base.grid.spacing_um
    seed = base.bed.seed
    plan = [(h, seed) for h in args.spacings] + [(at, s) for s in args.seeds]
    rows: list[dict] = []
    for h, s in dict.fromkeys(plan):
        rows.append(run_one(args.base, h, s, out, args.set))
        write_rows(out / "bedgrid.csv", rows, COLUMNS)
        print(", ".join(f"{k} {rows[-1][k]}" for k in COLUMNS[:-1]), file=sys.stderr, flush=True)
    results = analyse(rows, at, seed)
    text = table(results, at)
    atomic_write_text(out / "bedgrid.md", text)
    plot(results, out / "bedgrid.png", at)
    print(text)
    return 0 if all(r["status"] == "complete" for r in rows) else 1
