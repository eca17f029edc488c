"""The melted pair under surface tension alone, by the melt's Poisson ratio and initial stress.

    taichi-sls bench neck [--out renders] [--end-us 1000]

Runs the paper's fine scene (cases/nolaser.toml) fully melted and isothermal at 200 C (no laser,
no thermal or transformation strain at work: surface tension alone on the soft melt), started
stress-free, for the melt's Poisson ratio nu_m = 0.42 (the paper's one nu), 0.46 and 0.49, and
with the defaults (nu_m = 0.49, discs started in equilibrium with their Laplace pressure:
``surface_tension.initial_stress = "laplace"``); ``nolaser`` stress-free and with the defaults;
and the 5 / 15 / 25 W cases under the paper's reading (nu_m = 0.42, stress-free), nu_m = 0.49
alone, and the defaults. Prints the contact line every 50 us (a run the guard stops says so)
and writes OUT/neck_study.csv (one row per run and time) and OUT/neck_study.png.

The fully melted pair bounds what surface tension can do to the paper's soft elastic melt in a
run's time: the neck it reaches is the elastic (and plastic) response of the melt to the
capillary pull, since the melt relaxes viscously only over 0.05-0.5 s.
"""

from __future__ import annotations

import argparse
import csv
import time
from pathlib import Path

MELT = ["thermal.initial_C=200", "boundary.bottom.temperature_C=200"]
PAPER = ["materials.PA12.poisson_liquid=0.42", "surface_tension.initial_stress=none"]
NU49 = ["materials.PA12.poisson_liquid=0.49", "surface_tension.initial_stress=none"]
RUNS = [
    ("melt 200 C, nu_m 0.42", "nolaser", [*MELT, *PAPER]),
    (
        "melt 200 C, nu_m 0.46",
        "nolaser",
        [*MELT, "materials.PA12.poisson_liquid=0.46", "surface_tension.initial_stress=none"],
    ),
    ("melt 200 C, nu_m 0.49", "nolaser", [*MELT, *NU49]),
    ("melt 200 C, default", "nolaser", MELT),
    ("nolaser, stress-free", "nolaser", PAPER),
    ("nolaser, default", "nolaser", []),
] + [
    (f"{p} W, {label}", f"power{p}W", sets)
    for label, sets in (("paper", PAPER), ("nu_m 0.49", NU49), ("default", []))
    for p in (5, 15, 25)
]


MONITORS = ("contact_line_um", "kinetic_energy_J_per_m", "J_min", "T_peak_C")


def run_one(case_name: str, sets: list[str], end_s: float, every_s: float) -> list[dict]:
    """The monitors every ``every_s``; a run the guard stops ends with a row that says so."""
    from taichi_sls.config import load_case
    from taichi_sls.solver.guard import SimulationError
    from taichi_sls.solver.simulation import Simulation

    case = load_case(case_name, [*sets, f"time.end_s={end_s}"])
    sim = Simulation(case)
    n = round(every_s / sim.dt)
    rows = []
    last = round(end_s / every_s)
    for k in range(last + 1):
        try:
            if k:
                sim.advance_to(sim.t + n * sim.dt)
            m = sim.monitors()
        except SimulationError as e:
            m, status = dict.fromkeys(MONITORS, float("nan")), f"failed: {e}"
        else:
            status = "running" if k < last else "complete"
        rows.append(
            {"t_us": round(sim.t * 1e6, 3), **{key: m[key] for key in MONITORS}, "status": status}
        )
        if status.startswith("failed"):
            break
    return rows


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser(
        "neck", help="the melted pair under surface tension alone, by Poisson ratio"
    )
    ap.add_argument("--out", default="renders", help="folder for neck_study.csv and .png")
    ap.add_argument("--end-us", type=float, default=1000.0, help="simulated time per run (us)")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    table = []
    for label, case_name, sets in RUNS:
        t0 = time.perf_counter()
        rows = run_one(case_name, sets, args.end_us * 1e-6, 50e-6)
        ok = [r for r in rows if not r["status"].startswith("failed")]
        cl = [r["contact_line_um"] for r in ok]
        print(
            f"{label:24s} contact line {cl[0]:.2f} -> {cl[-1]:.2f} um "
            f"(min {min(cl):.2f}, max {max(cl):.2f}), J_min {ok[-1]['J_min']:.3f}, "
            f"KE at {ok[-1]['t_us']:.0f} us {ok[-1]['kinetic_energy_J_per_m']:.1e} J/m, "
            f"{rows[-1]['status'][:160]}, {time.perf_counter() - t0:.0f} s",
            flush=True,
        )
        table += [{"run": label, **r} for r in rows]
    path = out / "neck_study.csv"
    tmp = path.with_suffix(".csv.tmp")
    with tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(table[0]))
        w.writeheader()
        w.writerows(table)
    tmp.replace(path)
    plot(table, out / "neck_study.png")
    print(f"wrote {path} and {out / 'neck_study.png'}")
    return 0


def plot(table: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    for label in dict.fromkeys(r["run"] for r in table):
        rows = [r for r in table if r["run"] == label]
        ax = axs[1] if " W, " in label else axs[0]
        style = "--" if ("0.42" in label or "paper" in label or "free" in label) else "-"
        ax.plot([r["t_us"] for r in rows], [r["contact_line_um"] for r in rows], style, label=label)
    axs[0].set_title("surface tension alone: melted at 200 C, or nolaser (140 C)")
    axs[1].set_title("Table 2 stationary beams (dashed: the paper's reading)")
    for ax in axs:
        ax.set_xlabel("t [us]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    axs[0].set_ylabel("contact line [um]")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
