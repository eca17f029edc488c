"""Speed benchmark: cost per step and per point-step of the paper's case and of synthetic powder
layers, against the same physics laid out one kernel per stage and a minimal elastic MLS-MPM step
of the same size (``taichi-sls bench speed``).

Every ratio is measured side by side in one run (the machines are shared and noisy); the step
count of each measurement is chosen to take about ``--seconds`` of wall time.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import resource
import time
from pathlib import Path

import numpy as np

from bench.baseline import MinimalMPM
from taichi_sls.backend import ti
from taichi_sls.config import (
    Case,
    apply_override,
    bundled_case,
    case_from_dict,
    case_to_dict,
    load_case,
)
from taichi_sls.config.loading import add_set_argument
from taichi_sls.solver.fields import State
from taichi_sls.solver.scene import build_scene
from taichi_sls.solver.simulation import Simulation
from taichi_sls.solver.step import advance, advance_staged

PAPER_CASE = bundled_case("power25W")

# the paper's fine case without and with each skip this project adds (each switch measured)
SWITCHES = {
    "full physics (defaults)": [],
    "heat every step": ["time.heat_every=1"],
    "the paper's CSF": ["surface_tension.method=csf"],
    "the paper's CSF, curvature every step": [
        "surface_tension.method=csf",
        "surface_tension.curvature_every=1",
    ],
    "CSF, heat and curvature every step (as printed)": [
        "surface_tension.method=csf",
        "time.heat_every=1",
        "surface_tension.curvature_every=1",
    ],
    "laser off": ["lasers.0.power_W=0"],
    "no surface tension": ["physics.surface_tension=false"],
    "no plasticity": ["physics.plasticity=false"],
    "no thermal strain": ["physics.thermal_strain=false"],
    "no gravity": ["physics.gravity_m_s2=[0.0, 0.0]"],
    "no heat (mechanics only)": ["physics.thermal=false"],
    "no mechanics (heat only)": ["physics.mechanics=false"],
    "f32": ["solver.precision=f32"],
    "domain 4x taller, active region": ["domain.height_um=192"],
    "domain 4x taller, every node": ["domain.height_um=192", "solver.active_region=false"],
}


def layer_case(n_target: int) -> dict:
    """A powder layer: rows of 40 um PA12 discs (the paper's particles) touching their
    neighbours, on the 140 C plate under a 25 W beam centred on the layer; about n_target points
    on the paper's fine grid (1264 points per disc)."""
    n_disc = max(2, round(n_target / 1264))
    cols = max(2, math.ceil(math.sqrt(2 * n_disc)))
    rows = max(1, math.ceil(n_disc / cols))
    d = 40.0
    bodies = [
        {"center_um": [d / 2 + d * i, d / 2 + d * j], "radius_um": d / 2}
        for j in range(rows)
        for i in range(cols)
    ][:n_disc]
    W, H = cols * d, rows * d + 8.0
    return {
        "case": {"name": f"layer{n_target}"},
        "grid": {"spacing_um": 2.0},
        "domain": {"width_um": W, "height_um": H},
        "bodies": bodies,
        "time": {"dt_s": 5e-8},
        "lasers": [{"power_W": 25.0, "x_start_um": W / 2, "off_s": 20e-6}],
    }


def build(case: Case, shuffle: bool = False) -> Simulation:
    """A Simulation of the case (Taichi re-initialised), its step kernel compiled."""
    scene = build_scene(case)
    if shuffle:  # points in random order: what sorting by cell is worth
        scene = scene.reordered(np.random.default_rng(0).permutation(scene.n_points))
    return Simulation(case, scene=scene)


def field_bytes(obj: object) -> int:
    """Bytes held by the Taichi fields among an object's attributes (struct members and the
    fields of nested data-oriented objects included)."""
    total = 0
    for v in vars(obj).values():
        if isinstance(v, ti.lang.struct.StructField):
            total += sum(field_bytes_of(getattr(v, k)) for k in v.keys)
        elif isinstance(v, ti.Field):
            total += field_bytes_of(v)
        elif hasattr(v, "__dict__") and type(v).__module__.startswith("taichi_sls"):
            total += field_bytes(v)
    return total


def field_bytes_of(f) -> int:
    comps = getattr(f, "n", 1) * getattr(f, "m", 1)
    size = 4 if str(f.dtype) in ("f32", "i32", "u32") else 8
    return int(np.prod(f.shape)) * comps * size


def timed(fn, per_call: int, seconds: float, warm: int = 1) -> tuple[float, int]:
    """(seconds per step, steps run): ``warm`` steps first (every kernel variant compiled), then
    calls of ``per_call`` steps until ``seconds`` pass. The fastest call counts: on a shared
    machine a slow call measures the neighbours, not the step."""
    fn(warm)
    ti.sync()
    steps = 0
    best = math.inf
    t0 = time.perf_counter()
    while True:
        t1 = time.perf_counter()
        fn(per_call)
        ti.sync()
        best = min(best, (time.perf_counter() - t1) / per_call)
        steps += per_call
        if time.perf_counter() - t0 >= seconds and steps >= 3 * per_call:
            return best, steps


def peak_rss_mb() -> float:
    """The process's peak resident memory so far (MB): every field and Taichi's own share."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _per_call(n_points: int) -> int:
    return max(1, min(200, 500_000 // max(n_points, 1)))


def _row(label: str, st: State, variant: str, t: float, steps: int, **extra) -> dict:
    n = st.n_points
    return {
        "scene": label,
        "points": n,
        "nodes": st.cfg.nx * st.cfg.ny,
        "variant": variant,
        "us_per_step": t * 1e6,
        "point_steps_per_s": n / t,
        "steps": steps,
    } | extra


def _time_state(s: Simulation, seconds: float, staged: bool = False) -> tuple[float, int]:
    st = s.state
    # one full cycle of the heat and curvature clocks compiles every variant of a layout
    cycle = st.cfg.heat_every * st.cfg.geom_every + 1
    fn = (lambda m: advance_staged(st, m)) if staged else (lambda m: advance(st, m))
    return timed(fn, _per_call(st.n_points), seconds, cycle)


# (layout, threads) measured on every scene; 0 threads: every core
LAYOUTS = [("serial", 1), ("blocks", 1), ("blocks", 0), ("parallel", 0)]


def _variant(layout: str, threads: int) -> str:
    return f"full physics, {layout} layout, {'every core' if threads == 0 else '1 thread'}"


def measure_scene(label: str, case: Case, seconds: float, compare: bool) -> list[dict]:
    """Full physics in the layout ``solver.layout = "auto"`` picks; with ``compare`` also every
    layout on one thread and on every core (the speed-up of the cores), one kernel call per
    stage, and the minimal MLS-MPM step on the same points and grid."""
    s = build(case)
    st = s.state
    auto = (st.cfg.layout.name.lower(), 0 if st.cfg.parallel and case.solver.threads != 1 else 1)
    t_full, k = _time_state(s, seconds)
    extra = {
        "bytes_per_point": field_bytes(st) / st.n_points,
        "compile_s": s.compile_s,
        "peak_rss_MB": peak_rss_mb(),
    }
    rows = [_row(label, st, _variant(*auto) + " (auto)", t_full, k, ratio=1.0, **extra)]
    if not compare:
        return rows
    x, nx, ny, h = st.points.x.to_numpy(), st.cfg.nx, st.cfg.ny, st.cfg.h
    dt = float(st.scalars.dt[None])
    data = case_to_dict(case)
    best = {1: t_full if auto[1] == 1 else math.inf, 0: t_full if auto[1] == 0 else math.inf}
    for lay, threads in LAYOUTS:
        if (lay, threads) == auto:
            continue
        so = build(_case_from(data, [f"solver.layout={lay}", f"solver.threads={threads}"]))
        t_o, k = _time_state(so, seconds)
        best[threads] = min(best[threads], t_o)
        rows.append(_row(label, so.state, _variant(lay, threads), t_o, k, ratio=t_o / t_full))
    rows.append(
        {
            "scene": label,
            "points": st.n_points,
            "variant": "speed-up: fastest on every core over fastest on 1 thread",
            "us_per_step": best[0] * 1e6,
            "point_steps_per_s": st.n_points / best[0],
            "speedup": best[1] / best[0],
        }
    )
    sp = build(_case_from(data, ["solver.layout=parallel"]))
    t_s, k = _time_state(sp, seconds, staged=True)
    rows.append(_row(label, sp.state, "one kernel call per stage", t_s, k, ratio=t_s / t_full))
    for lay in ("serial", "parallel"):
        fl = MinimalMPM(x, nx, ny, h, dt)
        t0 = time.perf_counter()
        fl.advance(0, lay == "parallel")
        c_fl = time.perf_counter() - t0
        t_f, k = timed(
            lambda m, f=fl, p=lay == "parallel": f.advance(m, p), _per_call(len(x)), seconds
        )
        rows.append(
            _row(
                label,
                st,
                f"minimal elastic MLS-MPM, {lay} layout",
                t_f,
                k,
                bytes_per_point=fl.nbytes() / len(x),
                compile_s=c_fl,
                ratio=t_f / t_full,
            )
        )
    return rows


def measure_sorting(case: Case, seconds: float) -> list[dict]:
    """The same layer with its points in cell order (as seeded) and shuffled."""
    out = []
    for shuffle in (False, True):
        s = build(case, shuffle=shuffle)
        n = s.state.n_points
        t, k = _time_state(s, seconds)
        out.append(
            {
                "scene": case.case.name,
                "points": n,
                "variant": "points shuffled" if shuffle else "points in cell order",
                "us_per_step": t * 1e6,
                "point_steps_per_s": n / t,
                "steps": k,
            }
        )
    out[1]["ratio"] = out[1]["us_per_step"] / out[0]["us_per_step"]
    return out


def measure_switches(seconds: float, only: list[str] | None = None) -> list[dict]:
    rows = []
    ref = None
    for name, over in SWITCHES.items():
        if only and name not in only:
            continue
        case = load_case(PAPER_CASE, over)
        s = build(case)
        n = s.state.n_points
        t, k = _time_state(s, seconds)
        ref = ref or t
        rows.append(
            {
                "scene": "paper fine 25 W",
                "points": n,
                "variant": name,
                "us_per_step": t * 1e6,
                "point_steps_per_s": n / t,
                "compile_s": s.compile_s,
                "steps": k,
                "ratio": t / ref,
            }
        )
    return rows


def _case_from(data: dict, overrides: list[str]) -> Case:
    for o in overrides:
        apply_override(data, o)
    return case_from_dict(data)


COLUMNS = [
    "scene",
    "points",
    "nodes",
    "variant",
    "us_per_step",
    "point_steps_per_s",
    "ratio",
    "speedup",
    "bytes_per_point",
    "compile_s",
    "peak_rss_MB",
    "steps",
]


def plot(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    series: dict[str, list[tuple[int, float]]] = {}
    for r in rows:
        if "nodes" not in r:
            continue
        v = r["variant"].removesuffix(" (auto)").removeprefix("full physics, ")
        series.setdefault(v, []).append((r["points"], 1e9 / r["point_steps_per_s"]))
    for v, pts in series.items():
        pts.sort()
        ax.loglog([a for a, _ in pts], [b for _, b in pts], "o-", label=v)
    ax.set_xlabel("points")
    ax.set_ylabel("ns per point-step")
    ax.set_title("Cost per point-step (2-core CPU)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("speed", help="cost per step against the minimal MLS-MPM step")
    ap.add_argument("--sizes", default="10000,100000,1000000", help="synthetic layer sizes")
    ap.add_argument("--seconds", type=float, default=2.0, help="wall time per measurement")
    ap.add_argument("--out", default="renders", help="folder for speed.csv/json/png")
    ap.add_argument("--no-switches", action="store_true", help="skip the per-switch table")
    add_set_argument(ap, "case override for every scene")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows: list[dict] = []

    def report(new: list[dict]) -> None:
        for r in new:
            print(
                f"{r['scene']:>16s} {r['points']:>8d}  {r['variant']:<42s} "
                f"{r['us_per_step']:>11.1f} us/step "
                f"{r['point_steps_per_s'] / 1e6:>7.2f} M pt-steps/s"
                + (f"  x{r['ratio']:.2f}" if "ratio" in r else "")
                + (f"  speed-up {r['speedup']:.2f}" if "speedup" in r else ""),
                flush=True,
            )
        rows.extend(new)

    report(measure_scene("paper fine 25 W", load_case(PAPER_CASE, args.set), args.seconds, True))
    sizes = [int(s) for s in args.sizes.split(",") if s]
    for n in sizes:
        c = _case_from(layer_case(n), args.set)
        report(measure_scene(f"layer {n // 1000}k", c, args.seconds, True))
    if sizes:
        report(measure_sorting(_case_from(layer_case(max(sizes)), args.set), args.seconds))
    if not args.no_switches:
        report(measure_switches(args.seconds))
    with open(out / "speed.csv.tmp", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    (out / "speed.csv.tmp").replace(out / "speed.csv")
    (out / "speed.json").write_text(json.dumps(rows, indent=1))
    plot(rows, out / "speed.png")
    print(f"wrote {out / 'speed.csv'}, {out / 'speed.json'}, {out / 'speed.png'}")
    return 0
