"""Parameter sweeps on Dask: ``taichi-sls sweep SWEEP.toml [options]``.

Options: ``--out DIR`` (default ``out/sweeps/<name>/``), ``--workers N`` (local worker processes,
default 2), ``--scheduler ADDRESS`` (use a running cluster instead, e.g. ``tcp://HOST:8786``),
``--set KEY=VALUE`` (extra override for every case, after the file's ``set``), ``--retry``
(rerun rows whose status is not ``complete``), ``--plots`` (draw the figures after the sweep),
``--plot-only`` (draw them from an existing ``results.csv``, run nothing), ``--no-progress``.

Sweep file (TOML)::

    [sweep]
    name = "paper"                    # default: the file's stem
    base = "cases/power15W.toml"      # the case every run starts from
    collect = ["T_peak_C", "contact_line_um", "neck_span_um", "status"]
    set = ["output.png=false"]        # overrides applied to every case (optional)

    [grid]                            # cartesian product of the axes (optional)
    "lasers.0.power_W" = [5, 15, 25]
    # an axis whose values are inline tables sets several keys at once (the axis name is a label)
    scan = [{ "lasers.0.speed_m_s" = 0 }, { "lasers.0.speed_m_s" = 4, "lasers.0.x_start_um" = 0 }]

    [[cases]]                         # explicit cases, each a table of key = value (optional)
    "lasers.0.spot_radius_um" = 30

Keys are those of ``--set`` in ``taichi-sls run`` (list items by index). The sweep's
cases are the grid's product followed by the explicit cases; duplicates (same overrides) run once.
A case's overrides apply after ``set``. Unless ``set`` or a case names them, ``output.png`` and
``output.gif`` are set to false (frames cost more than the coarse runs themselves).

``base`` is resolved, first match wins: as written if absolute, else relative to the sweep file's
folder, then to that folder's parent (so ``sweeps/x.toml`` may name ``cases/...`` of the
repository), then to the current directory, then as a bundled case (``cases/power15W.toml`` or
``power15W``). A sweep file is also found by name among the bundled ones (``paper``).

Each case has an id: the first 10 hex digits of the SHA-1 of the base as written and the sorted
overrides (``set`` included), so the id is stable across restarts and machines; its outputs go to
``OUT/<id>/`` (``summary.json``, ``timeseries.csv``, ``case.toml``, ``run.log`` ...).

``OUT/results.csv`` (and ``OUT/results.parquet`` when pyarrow is importable) gets one row per
finished case, rewritten atomically as results arrive. Columns: ``id``, every swept key (named by
the key; empty where a case leaves it at the base value), the collected quantities (from the
summary's ``final`` monitors, else its fusion ``outcome``, e.g. ``fused`` or ``neck_final_um``,
else its top level, e.g. ``steps``; a dotted name is a path into the summary, e.g.
``bed.fused_fraction`` or ``bed.relative_density.final``), ``status``, ``error`` and ``wall_s``
(wall time of the whole case, compilation included). Status: ``complete``, ``max_time`` (a run
to solidification that gave up), ``failed`` (the solver's guard stopped the run; its message in
``error``), ``interrupted`` or ``error`` (an exception, e.g. an override the loader refuses; the
message in ``error``). No case stops the sweep.

Restart: run the same command again. Cases whose id already has a row with a final status
(``complete``, ``max_time``, ``failed`` or ``error``: the solver is deterministic, so these would
repeat) are
skipped; ``interrupted`` rows and missing cases run. ``--retry`` reruns everything not
``complete``. Rows of cases no longer in the sweep file are kept.

Dask: by default a ``LocalCluster`` of ``--workers`` processes with one thread each (Taichi allows
one simulation per process: ``ti.init`` resets every field). With ``--scheduler`` the workers of
a running cluster (``dask scheduler``; ``dask worker tcp://HOST:8786 --nthreads 1``) run the
cases: they need ``taichi_sls`` importable and must see the base case file and ``OUT`` at the
same paths (shared file system); the client passes absolute paths.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import sys
import time
from pathlib import Path
from typing import Any

from ...config import CaseError, load_case
from ...config.loading import add_set_argument
from .results import read_results, write_results
from .spec import Sweep, SweepError, load_sweep

STATUS_FINAL = ("complete", "max_time", "failed", "error")  # skipped on restart (without --retry)


def _collect(summary: dict[str, Any], names: list[str]) -> dict[str, Any]:
    """The named quantities of a run: from its final monitors, else its fusion outcome, else
    the summary's top level."""
    final = summary.get("final") or {}
    outcome = summary.get("outcome") or {}
    out: dict[str, Any] = {}
    for n in names:
        if n in ("status", "error", "id", "wall_s"):
            continue
        if "." in n:  # a path into the summary, e.g. bed.relative_density.final
            v: Any = summary
            for part in n.split("."):
                v = v.get(part) if isinstance(v, dict) else None
        else:
            v = final.get(n, outcome.get(n, summary.get(n)))
        out[n] = v if isinstance(v, (int, float, str, bool)) or v is None else json.dumps(v)
    return out


def run_one(
    cid: str, base: str, overrides: list[str], out_dir: str, collect: list[str]
) -> dict[str, Any]:
    """Run one case on a worker: load it with its overrides, run it into ``out_dir``, return its
    row. Never raises: an exception becomes a row with status ``error`` and its message."""
    t0 = time.perf_counter()
    row: dict[str, Any] = {"id": cid, "status": "error", "error": ""}
    try:
        case = load_case(base, overrides)
        from ...jobs.case_run import run_case
        from ...solver.time_step import resolve_dt

        resolve_dt(case)  # refuse an unstable fixed dt before compiling

        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        # the solver's messages go to the case's log, not the worker's terminal
        with (
            open(out / "run.log", "w") as log,
            contextlib.redirect_stdout(log),
            contextlib.redirect_stderr(log),
        ):
            summary = run_case(case, out, progress=False)
        row.update(_collect(summary, collect))
        row["status"] = summary["status"]
        row["error"] = summary.get("error", "")
    except Exception as e:  # every failure becomes a row; the sweep goes on
        row.update(status="error", error=f"{type(e).__name__}: {e}")
    row["wall_s"] = round(time.perf_counter() - t0, 3)
    return row


def run_sweep(
    sweep: Sweep,
    out: str | Path,
    *,
    scheduler: str | None = None,
    workers: int = 2,
    retry: bool = False,
    progress: bool = True,
) -> list[dict[str, Any]]:
    """Run every case of ``sweep`` not yet done in ``out``; return all rows of results.csv."""
    out = Path(out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    keep = ("complete",) if retry else STATUS_FINAL
    rows: dict[str, dict[str, Any]] = {r["id"]: r for r in read_results(out / "results.csv")}
    todo = [c for c in sweep.cases if rows.get(c.id, {}).get("status") not in keep]
    order = [c.id for c in sweep.cases] + [i for i in rows if i not in {c.id for c in sweep.cases}]

    def save() -> None:
        write_results(out, [rows[i] for i in order if i in rows], sweep.columns)

    n_done = len(sweep.cases) - len(todo)
    print(
        f"sweep {sweep.name}: {len(sweep.cases)} cases, {n_done} done, {len(todo)} to run -> {out}",
        file=sys.stderr,
    )
    if not todo:
        save()
        return [rows[i] for i in order if i in rows]

    from dask.distributed import Client, LocalCluster, as_completed
    from tqdm import tqdm

    cluster = None
    if scheduler:
        client = Client(scheduler)
    else:
        cluster = LocalCluster(
            n_workers=workers,
            processes=True,
            threads_per_worker=1,
            host="127.0.0.1",
            dashboard_address=None,
        )
        client = Client(cluster)
    try:
        by_key = {}
        for c in todo:
            fut = client.submit(
                run_one,
                c.id,
                str(sweep.base),
                c.overrides,
                str(out / c.id),
                sweep.collect,
                key=f"taichi_sls-{sweep.name}-{c.id}-{time.time_ns()}",
                pure=False,
            )
            by_key[fut.key] = (c, fut)
        bar = tqdm(
            as_completed([f for _, f in by_key.values()]),
            total=len(todo),
            unit="case",
            desc=sweep.name,
            disable=not progress,
            file=sys.stderr,
        )
        for fut in bar:
            c, _ = by_key[fut.key]
            try:
                row = fut.result()
            except Exception as e:  # the worker died (e.g. KilledWorker) or the result was lost
                row = {"id": c.id, "status": "error", "error": f"{type(e).__name__}: {e}"}
            rows[c.id] = {"id": c.id, **c.params, **row}
            save()
            bar.set_postfix_str(f"{c.id} {row['status']}")
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return [rows[i] for i in order if i in rows]


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("sweep", help="a parameter sweep of cases on Dask")
    ap.add_argument("sweep", help="sweep file (TOML)")
    ap.add_argument("--out", help="output folder (default: out/sweeps/<sweep name>)")
    ap.add_argument(
        "--scheduler", metavar="ADDRESS", help="running Dask scheduler, tcp://HOST:PORT"
    )
    ap.add_argument("--workers", type=int, default=2, help="local worker processes (default 2)")
    add_set_argument(ap, "override for every case, after the sweep file's set (changes the ids)")
    ap.add_argument("--retry", action="store_true", help="rerun rows not complete")
    ap.add_argument("--plots", action="store_true", help="draw the figures after the sweep")
    ap.add_argument("--plot-only", action="store_true", help="draw figures from results.csv only")
    ap.add_argument("--no-progress", action="store_true", help="no progress bar")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    if args.workers < 1:
        print(f"error: --workers {args.workers}: must be at least 1", file=sys.stderr)
        return 2
    try:
        sweep = load_sweep(args.sweep, args.set)
        load_case(sweep.base)  # a broken base fails here, not once per case
    except (SweepError, CaseError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    out = Path(args.out) if args.out else Path("out") / "sweeps" / sweep.name
    if not args.plot_only:
        try:
            rows = run_sweep(
                sweep,
                out,
                scheduler=args.scheduler,
                workers=args.workers,
                retry=args.retry,
                progress=not args.no_progress,
            )
        except KeyboardInterrupt:
            print("interrupted; finished cases are in results.csv", file=sys.stderr)
            return 130
        counts: dict[str, int] = {}
        for r in rows:
            counts[r["status"]] = counts.get(r["status"], 0) + 1
        print(
            ", ".join(f"{n} {s}" for s, n in sorted(counts.items())) + f" -> {out / 'results.csv'}",
            file=sys.stderr,
        )
    if args.plots or args.plot_only:
        from .draw import draw_all

        if not (out / "results.csv").is_file():
            print(f"error: {out / 'results.csv'} does not exist", file=sys.stderr)
            return 2
        for p in draw_all(out):
            print(f"wrote {p}", file=sys.stderr)
    return 0
