"""The accuracy study: ``python -m taichi_sls.bench accuracy [--quick] [--out DIR]``.

Runs every verification case (:mod:`taichi_sls.verification`) at three or more resolutions,
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

from . import verification as ver

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
    Study("erf", (4.0, 2.0, 1.0), (4.0, 2.0), "temperature_rms", f32_at=(2.0,)),
    Study("gaussian", (4.0, 2.0, 1.0), (4.0, 2.0), "temperature_rms", f32_at=(2.0,)),
    Study("stefan", (25, 50, 100), (25,), "melt_front"),
    Study("energy", (4.0, 2.0), (4.0,), "energy_balance", f32_at=(4.0,)),
    Study("curvature", (10, 20, 40), (10, 20), "curvature_mean"),
    Study("laplace", (10, 20, 40), (10,), "pressure"),
    Study("square", (4.0, 2.0, 1.0), (4.0,), "mode4_left"),
    Study(
        "viscous_decay",
        (10, 20, 40),
        (10,),
        "decay_rate",
        sets={"time": {"end_s": 6e-5}},
        transfers_at=(20,),
    ),
    Study("inviscid", (10, 20, 40), (10,), "period", transfers_at=(20,), f32_at=(20,)),
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
            if only and s.name not in only:
                continue
            kind = ver.load(s.name).verification.kind
            res_list = s.quick if quick else s.resolutions
            jobs: list[tuple[float, dict]] = [(r, {}) for r in res_list]
            if not quick:
                own = ver._transfer_label(ver.load(s.name))
                for r in s.transfers_at:
                    jobs += [(r, {"solver": t}) for k, t in TRANSFERS.items() if k != own]
                jobs += [(r, {"solver": {"precision": "f32"}}) for r in s.f32_at]
            for res, extra in jobs:
                sets = ver.deep_update(s.sets, extra)
                try:
                    r = ver.run(ver.load(s.name, res, sets))
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


# ------------------------------------------------------------------------------ plots


def _series(rows: list[dict], case: str, measure: str, transfer: str | None, precision: str):
    pts = [
        r
        for r in rows
        if r["case"] == case
        and r["measure"] == measure
        and r["precision"] == precision
        and (transfer is None or r["transfer"] == transfer)
    ]
    return sorted(pts, key=lambda r: -float(r["h_um"]) if case != "perzyna" else -float(r["dt_s"]))


def observed_orders(hs: list[float], errs: list[float]) -> list[float]:
    """log(e_i / e_(i+1)) / log(h_i / h_(i+1)) between consecutive resolutions."""
    out = []
    for i in range(len(hs) - 1):
        e0, e1 = abs(errs[i]), abs(errs[i + 1])
        if e0 > 0 and e1 > 0 and hs[i] != hs[i + 1]:
            out.append(math.log(e0 / e1) / math.log(hs[i] / hs[i + 1]))
        else:
            out.append(math.nan)
    return out


def _default_transfer(rows: list[dict], case: str) -> str:
    """The transfer label of the case file's own solver settings (verification._transfer_label)."""
    return ver._transfer_label(ver.load(case))


def _error_line(ax, pts: list[dict], fmt: str, **kw) -> None:
    h = [float(r["h_um"]) for r in pts]
    ax.loglog(h, [max(abs(float(r["error"])), 1e-16) for r in pts], fmt, **kw)


def _panel_labels(ax, s: Study) -> None:
    ax.set_title(f"{s.name}: {s.measure}", fontsize=9)
    ax.set_xlabel("h (um)", fontsize=8)
    ax.legend(fontsize=7)


def _save(fig, title: str, path: Path) -> Path:
    import matplotlib.pyplot as plt

    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=70)
    plt.close(fig)
    return path


def plot(rows: list[dict], out: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    made = []
    cases = [s for s in STUDIES if any(r["case"] == s.name for r in rows)]
    n = len(cases)
    cols = 4
    fig, axes = plt.subplots(math.ceil(n / cols), cols, figsize=(13, 2.8 * math.ceil(n / cols)))
    for ax, s in zip(axes.flat, cases, strict=False):
        pts = _series(rows, s.name, s.measure, _default_transfer(rows, s.name), "f64")
        x = [float(r["dt_s"] if s.name == "perzyna" else r["h_um"]) for r in pts]
        e = [abs(float(r["error"])) for r in pts]
        ax.loglog(x, e, "o-")
        orders = observed_orders(x, e)
        for i, p in enumerate(orders):
            xm, ym = math.sqrt(x[i] * x[i + 1]), math.sqrt(max(e[i] * e[i + 1], 1e-300))
            ax.annotate(f"{p:.1f}", (xm, ym), fontsize=8, color="C3")
        ax.set_title(f"{s.name}: {s.measure}", fontsize=9)
        ax.set_xlabel("dt (s)" if s.name == "perzyna" else "h (um)", fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.suptitle("Error against resolution (red: observed order between neighbours)", fontsize=10)
    fig.tight_layout()
    made.append(out / "accuracy_convergence.png")
    fig.savefig(made[-1], dpi=70)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for i, s in enumerate(cases):
        pts = _series(rows, s.name, s.measure, _default_transfer(rows, s.name), "f64")
        t = [float(r["wall_s"]) for r in pts]
        e = [max(abs(float(r["error"])), 1e-16) for r in pts]
        ax.loglog(t, e, marker="o", label=s.name, color=f"C{i % 10}", ls="-" if i < 10 else "--")
    ax.set_xlabel("wall time (s, compile included)")
    ax.set_ylabel("|error|")
    ax.set_title("Run time against error (each line: refinement of one case)", fontsize=10)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    made.append(out / "accuracy_cost.png")
    fig.savefig(made[-1], dpi=70)
    plt.close(fig)

    prec = [s for s in cases if any(r["case"] == s.name and r["precision"] == "f32" for r in rows)]
    if prec:
        fig, axes = plt.subplots(1, len(prec), figsize=(3.2 * len(prec), 3), squeeze=False)
        for ax, s in zip(axes.flat, prec, strict=False):
            for p, mk in (("f64", "o-"), ("f32", "s--")):
                pts = _series(rows, s.name, s.measure, _default_transfer(rows, s.name), p)
                hs = {float(r["h_um"]) for r in _series(rows, s.name, s.measure, None, "f32")}
                pts = [r for r in pts if float(r["h_um"]) in hs]
                _error_line(ax, pts, mk, label=p)
            _panel_labels(ax, s)
        made.append(_save(fig, "f64 against f32", out / "accuracy_precision.png"))

    trans = [
        s
        for s in cases
        if s.transfers_at and len({r["transfer"] for r in rows if r["case"] == s.name}) > 1
    ]
    if trans:
        fig, axes = plt.subplots(1, len(trans), figsize=(3.4 * len(trans), 3), squeeze=False)
        for ax, s in zip(axes.flat, trans, strict=False):
            for i, t in enumerate(TRANSFERS):
                pts = [
                    r
                    for r in _series(rows, s.name, s.measure, t, "f64")
                    if float(r["resolution"]) in s.transfers_at
                ]
                _error_line(ax, pts, "o-", label=t, color=f"C{i}")
            _panel_labels(ax, s)
        made.append(
            _save(fig, "Transfers: APIC, FLIP, PIC/FLIP 0.9", out / "accuracy_transfer.png")
        )
    return made


def summary_table(rows: list[dict]) -> str:
    """Markdown: per case and measure (default transfer, f64), errors at each resolution and the
    observed orders."""
    lines = ["| case | measure | resolution: error | observed orders |", "|---|---|---|---|"]
    for s in STUDIES:
        measures = dict.fromkeys(r["measure"] for r in rows if r["case"] == s.name)
        for m in measures:
            pts = _series(rows, s.name, m, _default_transfer(rows, s.name), "f64")
            if not pts:
                continue
            x = [float(r["dt_s"] if s.name == "perzyna" else r["h_um"]) for r in pts]
            e = [float(r["error"]) for r in pts]
            cells = ", ".join(f"{float(r['resolution']):g}: {float(r['error']):+.2e}" for r in pts)
            orders = ", ".join(f"{p:.2f}" for p in observed_orders(x, e))
            lines.append(f"| {s.name} | {m} | {cells} | {orders} |")
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------------ paper case


PAPER_COLUMNS = ("h_um", "dt_s", "steps", "contact_line_um", "T_peak_C", "wall_s", "status")


def run_paper(spacings: list[float], out: Path, end_s: float = 1e-3) -> list[dict]:
    """cases/power25W.toml at each spacing, dt = 2.5e-8 s per um of h (the paper's 5e-8 s at
    h = 2 um, scaled with the elastic limit), to ``end_s``: contact line and peak temperature."""
    from .case import load_case
    from .simulation import Simulation, SimulationError

    out.mkdir(parents=True, exist_ok=True)
    path = out / "paper_refinement.csv"
    rows = []
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=PAPER_COLUMNS)
        w.writeheader()
        for h in spacings:
            case = load_case(
                ver.CASES.parent / "power25W.toml",
                [f"grid.spacing_um={h}", f"time.dt_s={2.5e-8 * h}", f"time.end_s={end_s}"],
            )
            t0 = time.perf_counter()
            sim = Simulation(case)
            status = "complete"
            try:
                n = int(round(end_s / sim.dt))
                for k in range(10):  # monitors (and the guard) ten times over the run
                    sim.advance(n * (k + 1) // 10 - n * k // 10)
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
    t0 = time.perf_counter()
    rows = run_study(args.quick, out, args.only)
    for p in plot(rows, out):
        print(f"wrote {p}", file=sys.stderr)
    print(summary_table(rows))
    print(f"accuracy study: {len(rows)} rows in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    return 0
