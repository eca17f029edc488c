"""Parameter sweeps on Dask: ``python -m taichi_sls.sweep SWEEP.toml [options]``.

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

Keys are those of ``--set`` in ``python -m taichi_sls.run`` (list items by index). The sweep's
cases are the grid's product followed by the explicit cases; duplicates (same overrides) run once.
A case's overrides apply after ``set``. Unless ``set`` or a case names them, ``output.png`` and
``output.gif`` are set to false (frames cost more than the coarse runs themselves).

``base`` is resolved, first match wins: as written if absolute, else relative to the sweep file's
folder, then to that folder's parent (so ``sweeps/x.toml`` may name ``cases/...`` of the
repository), then to the current directory.

Each case has an id: the first 10 hex digits of the SHA-1 of the base as written and the sorted
overrides (``set`` included), so the id is stable across restarts and machines; its outputs go to
``OUT/<id>/`` (``summary.json``, ``timeseries.csv``, ``case.toml``, ``run.log`` ...).

``OUT/results.csv`` (and ``OUT/results.parquet`` when pyarrow is importable) gets one row per
finished case, rewritten atomically as results arrive. Columns: ``id``, every swept key (named by
the key; empty where a case leaves it at the base value), the collected quantities (from the
summary's ``final`` monitors, else its top level, e.g. ``steps``), ``status``, ``error`` and
``wall_s`` (wall time of the whole case, compilation included). Status: ``complete``, ``failed``
(the solver's guard stopped the run; its message in ``error``), ``interrupted`` or ``error`` (an
exception, e.g. an override the loader refuses; the message in ``error``). No case stops the
sweep.

Restart: run the same command again. Cases whose id already has a row with a final status
(``complete``, ``failed`` or ``error``: the solver is deterministic, so these would repeat) are
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
import csv
import hashlib
import itertools
import json
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .case import CaseError, load_case, read_toml
from .output import _atomic_path

STATUS_FINAL = ("complete", "failed", "error")  # skipped on restart (without --retry)
IMAGE_KEYS = ("output.png", "output.gif")
_SWEEP_KEYS = {"name", "base", "collect", "set"}


class SweepError(ValueError):
    """The sweep file is invalid; the message names the key and what is allowed."""


@dataclass
class SweepCase:
    id: str
    overrides: list[str]  # every override, ``set`` included, in application order
    params: dict[str, Any]  # the swept keys of this case -> values (the CSV columns)


@dataclass
class Sweep:
    name: str
    base: Path  # resolved, absolute
    base_text: str  # as written (part of the ids)
    collect: list[str]
    keys: list[str]  # every swept key, in order of first appearance
    cases: list[SweepCase] = field(default_factory=list)

    @property
    def quantities(self) -> list[str]:
        """Collected columns apart from status and error (which every row has)."""
        return [c for c in self.collect if c not in ("status", "error", "id", "wall_s")]

    @property
    def columns(self) -> list[str]:
        return ["id", *self.keys, *self.quantities, "status", "error", "wall_s"]


# --------------------------------------------------------------------------- sweep file


def toml_value(v: Any) -> str:
    """A Python value as TOML value syntax (the right-hand side of an override)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)  # 1e-05, inf, nan: all TOML
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    raise SweepError(f"value {v!r}: only numbers, booleans, strings and lists can be swept")


def case_id(base_text: str, overrides: list[str]) -> str:
    """Stable id of a case: a short hash of its base (as written) and sorted overrides."""
    blob = json.dumps([base_text, sorted(overrides)], separators=(",", ":"))
    return hashlib.sha1(blob.encode()).hexdigest()[:10]


def _resolve_base(text: str, sweep_path: Path) -> Path:
    p = Path(text).expanduser()
    if p.is_absolute():
        tried = [p]
    else:
        folder = sweep_path.resolve().parent
        tried = [folder / p, folder.parent / p, Path.cwd() / p]
    for t in tried:
        if t.is_file():
            return t.resolve()
    raise SweepError(f"sweep.base = {text!r}: no such file; tried {', '.join(map(str, tried))}")


def _split_override(text: str, where: str) -> tuple[str, str]:
    if "=" not in text:
        raise SweepError(f"{where} {text!r}: expected section.key=value")
    k, v = text.split("=", 1)
    return k.strip(), v.strip()


def _axis(name: str, values: Any) -> list[dict[str, Any]]:
    """One grid axis as a list of {key: value} settings."""
    if not isinstance(values, list) or not values:
        raise SweepError(f"grid.{name!r} = {values!r}: expected a non-empty list")
    if all(isinstance(v, dict) for v in values):
        return [dict(v) for v in values]
    if any(isinstance(v, dict) for v in values):
        raise SweepError(f"grid.{name!r}: mixes tables and values")
    return [{name: v} for v in values]


def load_sweep(path: str | Path, extra_set: list[str] | None = None) -> Sweep:
    """Read and check a sweep file; ``extra_set`` overrides apply to every case after ``set``."""
    path = Path(path)
    data = read_toml(path, "sweep file", SweepError)
    unknown = sorted(set(data) - {"sweep", "grid", "cases"})
    if unknown:
        raise SweepError(f"unknown table {unknown[0]!r}; allowed: sweep, grid, cases")
    head = data.get("sweep", {})
    unknown = sorted(set(head) - _SWEEP_KEYS)
    if unknown:
        raise SweepError(
            f"unknown key sweep.{unknown[0]}; allowed: {', '.join(sorted(_SWEEP_KEYS))}"
        )
    if "base" not in head:
        raise SweepError("sweep.base: required (the case file every run starts from)")
    base_text = str(head["base"])
    base = _resolve_base(base_text, path)
    collect = head.get("collect", ["T_peak_C", "contact_line_um", "neck_span_um", "status"])
    if not isinstance(collect, list) or not all(isinstance(c, str) for c in collect):
        raise SweepError(f"sweep.collect = {collect!r}: expected a list of names")
    common_list = list(head.get("set", [])) + list(extra_set or [])
    common: dict[str, str] = {k: "false" for k in IMAGE_KEYS}
    for text in common_list:
        k, v = _split_override(str(text), "sweep.set")
        common[k] = v

    grid = data.get("grid", {})
    explicit = data.get("cases", [])
    if not isinstance(explicit, list) or not all(isinstance(c, dict) for c in explicit):
        raise SweepError("cases: expected [[cases]] tables of key = value")
    settings: list[dict[str, Any]] = []
    if grid:
        axes = [_axis(name, vals) for name, vals in grid.items()]
        for combo in itertools.product(*axes):
            merged: dict[str, Any] = {}
            for part in combo:
                merged.update(part)
            settings.append(merged)
    settings += [dict(c) for c in explicit]
    if not settings:
        settings = [{}]  # the base case alone (with ``set``)

    sweep = Sweep(
        name=str(head.get("name", path.stem)),
        base=base,
        base_text=base_text,
        collect=list(collect),
        keys=[],
    )
    seen: set[str] = set()
    for s in settings:
        ov = dict(common)
        for k, v in s.items():
            if isinstance(v, dict):
                raise SweepError(f"{k!r} = {v!r}: expected a value, not a table")
            ov[k] = toml_value(v)
            if k not in sweep.keys:
                sweep.keys.append(k)
        overrides = [f"{k}={v}" for k, v in ov.items()]
        cid = case_id(base_text, overrides)
        if cid not in seen:
            seen.add(cid)
            sweep.cases.append(SweepCase(cid, overrides, dict(s)))
    return sweep


# --------------------------------------------------------------------------- worker side


def _collect(summary: dict[str, Any], names: list[str]) -> dict[str, Any]:
    final = summary.get("final") or {}
    out: dict[str, Any] = {}
    for n in names:
        if n in ("status", "error", "id", "wall_s"):
            continue
        v = final.get(n, summary.get(n))
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
        from .simulation import resolve_dt

        resolve_dt(case)  # refuse an unstable fixed dt before compiling
        from .run import run_case

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


# --------------------------------------------------------------------------- results table


def _number(text: str) -> Any:
    """CSV cell -> int/float where it reads as one, else the string."""
    if text == "":
        return ""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


def read_results(path: str | Path) -> list[dict[str, Any]]:
    """Rows of a results.csv (numbers parsed; empty cells as ""); [] if it does not exist."""
    path = Path(path)
    if not path.is_file():
        return []
    with path.open(newline="") as f:
        return [
            {k: (v if k in ("id", "status", "error") else _number(v)) for k, v in r.items()}
            for r in csv.DictReader(f)
        ]


def write_results(out: Path, rows: list[dict[str, Any]], columns: list[str]) -> None:
    """Write results.csv (and results.parquet if pyarrow is importable), each atomically."""
    cols = list(columns)
    for r in rows:
        cols += [k for k in r if k not in cols]
    with _atomic_path(out / "results.csv") as tmp:
        with tmp.open("w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=cols, extrasaction="ignore")
            w.writeheader()
            for r in rows:
                w.writerow({c: "" if r.get(c) is None else r[c] for c in cols})
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return
    table: dict[str, list] = {}
    for c in cols:
        vals = [r.get(c) for r in rows]
        present = [v for v in vals if v not in (None, "")]
        if present and all(isinstance(v, (int, float)) for v in present):
            table[c] = [float(v) if v not in (None, "") else None for v in vals]
        else:
            table[c] = [None if v is None else str(v) for v in vals]
    with _atomic_path(out / "results.parquet") as tmp:
        pq.write_table(pa.table(table), tmp)


# --------------------------------------------------------------------------- driver


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


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m taichi_sls.sweep",
        description="Run a parameter sweep of taichi_sls cases on Dask (see the module doc).",
    )
    ap.add_argument("sweep", help="sweep file (TOML)")
    ap.add_argument("--out", help="output folder (default: out/sweeps/<sweep name>)")
    ap.add_argument(
        "--scheduler", metavar="ADDRESS", help="running Dask scheduler, tcp://HOST:PORT"
    )
    ap.add_argument("--workers", type=int, default=2, help="local worker processes (default 2)")
    ap.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override for every case, after the sweep file's set (changes the ids)",
    )
    ap.add_argument("--retry", action="store_true", help="rerun rows not complete")
    ap.add_argument("--plots", action="store_true", help="draw the figures after the sweep")
    ap.add_argument("--plot-only", action="store_true", help="draw figures from results.csv only")
    ap.add_argument("--no-progress", action="store_true", help="no progress bar")
    args = ap.parse_args(argv)
    if args.workers < 1:
        ap.error("--workers must be at least 1")
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
        from .sweep_plots import draw_all

        if not (out / "results.csv").is_file():
            print(f"error: {out / 'results.csv'} does not exist", file=sys.stderr)
            return 2
        for p in draw_all(out):
            print(f"wrote {p}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
