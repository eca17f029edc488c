"""The robustness matrix: ``taichi-sls bench robustness [--quick] [--out out/robustness]``.

Runs a matrix of cases at the edge of stability -- time step from 0.25x to 4x the automatic
limit, laser power 1 to 100 W, grid spacing 4 to 0.5 um, 10 ms and 40 ms runs, inertia scales
64 and 1024, APIC, the paper's CSF and total stress form, very soft and very stiff materials, a
body touching every wall -- and classifies each row:

- ``stable``: ran to its end, the guard silent, and the independent checks below pass;
- ``caught``: the guard stopped it (its message is recorded);
- ``WRONG``: ran to its end with the guard silent, but an independent check fails: energy balance
  beyond 1e-6, a temperature below the coldest start, wall or chamber, J outside (0, 20), a
  non-finite monitor. The goal is no such row.

Writes ``robustness.csv`` and ``robustness.md`` (the table of docs/record/robustness.md) to the
output folder.
"""

from __future__ import annotations

import argparse
import csv
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

from taichi_sls.config import Case, Rect, bundled_case, load_case
from taichi_sls.physics.materials import KELVIN
from taichi_sls.solver.guard import SimulationError
from taichi_sls.solver.simulation import Simulation
from taichi_sls.solver.time_step import time_step_limits


@dataclass
class Row:
    name: str
    base: str
    sets: list[str] = field(default_factory=list)
    dt_factor: float | None = None  # fixed dt as a multiple of the smallest stability limit
    quick: bool = False
    box: bool = False  # replace the bodies by one rectangle filling the domain


def matrix() -> list[Row]:
    rows = [
        Row(f"dt x{f:g}", "power25W_coarse", ["time.end_s=2e-4"], dt_factor=f, quick=f in (0.5, 4))
        for f in (0.25, 0.5, 1.0, 2.0, 4.0)
    ]
    rows += [
        Row(f"power {p:g} W", "power25W_coarse", [f"lasers.0.power_W={p}", "time.end_s=5e-4"])
        for p in (1, 5, 25, 50, 100)
    ]
    rows += [
        Row(f"h = {h:g} um", "power25W", [f"grid.spacing_um={h}", "time.dt_s=auto"] + e)
        for h, e in (
            (4.0, ["time.end_s=2e-4"]),
            (2.0, ["time.end_s=2e-4"]),
            (1.0, ["time.end_s=5e-5"]),
            (0.5, ["time.end_s=1e-5"]),
        )
    ]
    rows += [
        Row("10 ms, 25 W", "power25W_coarse", ["time.end_s=1e-2"]),
        Row("10 ms, no laser", "power25W_coarse", ["time.end_s=1e-2", "lasers.0.power_W=0"]),
        Row("40 ms, 25 W (refrozen)", "power25W_coarse", ["time.end_s=4e-2"]),
    ]
    rows += [
        Row(f"inertia scale {s}", "power25W_coarse", [f"solver.mass_scale={s}", "time.end_s=5e-4"])
        for s in (64, 1024)
    ]
    rows += [
        Row(name, "power25W_coarse", [key, "time.end_s=5e-4"])
        for name, key in (
            ("APIC", "solver.transfer=apic"),
            ("the paper's CSF", "surface_tension.method=csf"),
            ("total stress form", "solver.stress_form=total"),
        )
    ]
    soft = ["materials.PA12.youngs_solid_Pa=1e3", "materials.PA12.youngs_liquid_Pa=1e2"]
    stiff = ["materials.PA12.youngs_solid_Pa=1e7", "materials.PA12.youngs_liquid_Pa=1e6"]
    rows += [
        Row("very soft (E / 100)", "power25W_coarse", soft + ["time.end_s=2e-4"]),
        Row("very stiff (E x 100)", "power25W_coarse", stiff + ["time.end_s=2e-4"]),
    ]
    rows.append(
        Row(
            "body touching every wall", "power25W_coarse", ["time.end_s=2e-4"], box=True, quick=True
        )
    )
    return rows


def _case(row: Row) -> Case:
    sets = list(row.sets) + ["output.png=false", "output.gif=false"]
    case = load_case(bundled_case(row.base), sets)
    if row.box:
        W, H = case.domain.width_um, case.domain.height_um
        case.bodies = [Rect(shape="rect", min_um=[0.0, 0.0], max_um=[W, H])]
    if row.dt_factor is not None:
        case.time.dt_s = row.dt_factor * min(time_step_limits(case).values())
        case.time.allow_unstable_dt = True
    return case


def independent_checks(sim: Simulation, first: dict, last: dict) -> list[str]:
    """Checks that do not trust the guard."""
    bad = []
    rise = last["enthalpy_J_per_m"] - first["enthalpy_J_per_m"]
    net = last["laser_energy_J_per_m"] - last["heat_out_J_per_m"]
    scale = abs(first["enthalpy_J_per_m"]) + last["laser_energy_J_per_m"]
    if abs(net - rise) > 1e-6 * scale:
        bad.append(f"energy balance off by {(net - rise) / scale:.2e}")
    T = sim.state.points.T.to_numpy() - KELVIN
    walls = [
        w.temperature_C
        for w in sim.case.boundary.walls(sim.case.domain.dim)
        if w.thermal == "fixed"
    ]
    floor = min([float(sim.scene.T0_C.min()), *walls])
    if T.min() < floor - 1.0:
        bad.append(f"T_min {T.min():.1f} C below {floor:.1f} C")
    J = sim.state.points.J.to_numpy()
    if not (J.min() > 0 and J.max() < 20):
        bad.append(f"J in [{J.min():.3g}, {J.max():.3g}]")
    if not all(math.isfinite(v) for k, v in last.items() if not k.endswith("_um")):
        bad.append("non-finite monitor")
    return bad


def run_row(row: Row, frames: int = 10) -> dict:
    case = _case(row)
    t0 = time.perf_counter()
    sim = Simulation(case)
    first = sim.monitors()
    n = max(1, math.ceil(case.time.end_s / frames / sim.dt))
    result, note = "stable", ""
    last = first
    try:
        for _ in range(frames):
            sim.advance_to(sim.t + n * sim.dt)
            last = sim.monitors()
    except SimulationError as e:
        result, note = "caught", str(e)
    if result == "stable":
        bad = independent_checks(sim, first, last)
        if bad:
            result, note = "WRONG", "; ".join(bad)
    return {
        "row": row.name,
        "dt_s": f"{sim.dt:.3g}",
        "t_end_s": f"{sim.t:.3g}",
        "result": result,
        "T_peak_C": round(last["T_peak_C"], 1),
        "J_min": round(last["J_min"], 3),
        "wall_s": round(time.perf_counter() - t0, 1),
        "message": note,
    }


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("robustness", help="cases at the edge of stability: stable, caught or WRONG")
    p.add_argument("--out", default="out/robustness", help="folder for robustness.csv and .md")
    p.add_argument("--quick", action="store_true", help="only the rows the test suite runs")
    p.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    results = []
    for row in matrix():
        if args.quick and not row.quick:
            continue
        r = run_row(row)
        print(f"{r['row']:28s} {r['result']:7s} {r['wall_s']:7.1f} s  {r['message'][:120]}")
        results.append(r)
    with (out / "robustness.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(results[0]))
        w.writeheader()
        w.writerows(results)
    lines = ["| case | dt (s) | reached (s) | result | peak T (C) | J_min | message |"]
    lines.append("|---|---|---|---|---|---|---|")
    for r in results:
        msg = r["message"].replace("|", "/")
        lines.append(
            f"| {r['row']} | {r['dt_s']} | {r['t_end_s']} | {r['result']} | {r['T_peak_C']} "
            f"| {r['J_min']} | {msg} |"
        )
    (out / "robustness.md").write_text("\n".join(lines) + "\n")
    return 1 if any(r["result"] == "WRONG" for r in results) else 0
