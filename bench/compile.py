"""``taichi-sls bench compile``: each bundled case's compile time, cold and warm, per backend.

Each measurement is a fresh process running the case briefly (``time.stop = "end"`` a few
steps in: the same kernels as the full run, its settle phase included; no frames drawn), so it
pays what a user's run pays: ``import``, the Python front end of every kernel, and the back end
(LLVM, or a load from Taichi's offline cache). Cold: an empty offline cache of its own
(``TI_OFFLINE_CACHE_FILE_PATH``); warm: the same case again on that cache. The compile time is
the summary's ``compile_s`` (solver/compile_clock.py: every kernel compiled in the run);
``compile_cpu_s`` is its CPU time, steadier on a shared machine. Writes compile.csv/json.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from taichi_sls.backend import BACKENDS, DEFAULT, ENV
from taichi_sls.config import bundled_cases

# a brief run: a few steps of the case's own step (dt "auto" resolves as in the full run)
BRIEF = ["time.stop=end", "time.end_s=1e-8", "output.png=false", "output.gif=false"]
FIELDS = (
    "case",
    "backend",
    "cache",
    "compile_s",
    "compile_cpu_s",
    "compile_front_end_s",
    "compile_back_end_s",
    "kernels_compiled",
    "process_wall_s",
    "status",
)


def measure(case: str, backend: str, cache_dir: Path, python: str = sys.executable) -> dict:
    """One fresh process running ``case`` briefly on the offline cache in ``cache_dir``."""
    env = dict(os.environ, **{ENV: backend, "TI_OFFLINE_CACHE_FILE_PATH": str(cache_dir)})
    with tempfile.TemporaryDirectory() as out:
        cmd = [python, "-m", "taichi_sls.run", case, "--no-progress", "--out", out]
        for s in BRIEF:
            cmd += ["--set", s]
        t0 = time.perf_counter()
        done = subprocess.run(cmd, env=env, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        summary_file = Path(out) / "summary.json"
        if not summary_file.is_file():
            tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
            return {"case": case, "backend": backend, "status": f"error: {tail}"}
        s = json.loads(summary_file.read_text())
    return {
        "case": case,
        "backend": backend,
        **{k: s.get(k) for k in FIELDS if k.startswith(("compile", "kernels"))},
        "process_wall_s": wall,
        "status": s.get("status"),
    }


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("compile", help="compile time of every bundled case, cold and warm")
    ap.add_argument("--cases", default="", help="comma-separated case names (default: all)")
    ap.add_argument(
        "--backends", default=DEFAULT, help=f"comma-separated, of {', '.join(BACKENDS)}"
    )
    ap.add_argument("--python", default=sys.executable, help="the interpreter of the children")
    ap.add_argument("--out", default="renders", help="folder for compile.csv/json")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    names = [c for c in args.cases.split(",") if c] or [p.stem for p in bundled_cases()]
    rows: list[dict] = []
    for backend in args.backends.split(","):
        for name in names:
            with tempfile.TemporaryDirectory() as cache:
                for label in ("cold", "warm"):
                    r = {**measure(name, backend, Path(cache), args.python), "cache": label}
                    rows.append(r)
                    print(
                        f"{name:>24s} {backend:<13s} {label:<5s} "
                        + (
                            f"compile {r['compile_s']:6.2f} s (CPU {r['compile_cpu_s']:6.2f} s, "
                            f"{r['kernels_compiled']:3d} kernels), process "
                            f"{r['process_wall_s']:6.1f} s"
                            if r.get("compile_s") is not None
                            else r["status"]
                        ),
                        flush=True,
                    )
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "compile.csv", "w", newline="") as f:
        w = csv.DictWriter(f, FIELDS, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    (out / "compile.json").write_text(json.dumps(rows, indent=1))
    return 0
