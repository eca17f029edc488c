"""The command line: ``taichi-sls SUBCOMMAND ...`` (also ``python -m taichi_sls``).

    run CASE         run a case file (or a bundled case by name) with every output
    sweep SWEEP      a parameter sweep on Dask
    bench NAME       a study a user runs (hold, window, refinement, process), or a developer's
                     benchmark: bench/NAME.py in a checkout of the repository (speed, compile,
                     cost, accuracy, robustness, ...; ``taichi-sls bench --help`` lists them)
    case             print the case-file reference (docs/case_reference.md)

Every subcommand but ``run`` and ``case`` is parsed by its own module, imported only when the
subcommand is named: ``taichi-sls --help`` and ``taichi-sls case`` load neither Taichi nor Dask.
``python -m taichi_sls.run CASE ...`` is ``taichi-sls run CASE ...``; ``python -m taichi_sls.bench
NAME ...`` is ``taichi-sls bench NAME ...``.
"""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .config import CaseError
from .config.loading import add_set_argument

# the command line prints its own messages; Taichi's banner would land in piped output
os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "False")


# exit status of ``run`` by the run's status: a run to solidification that gives up at
# time.max_s is not a success
EXIT_CODES = {"complete": 0, "failed": 1, "max_time": 3, "interrupted": 130}


def _interrupt(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


def add_run_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("case", help="case file (TOML), or the name of a bundled case (power25W)")
    ap.add_argument("--out", help="output folder (default: out/<case name>)")
    add_set_argument(
        ap, "override a case key, e.g. --set lasers.0.power_W=15 --set time.end_s=1e-4"
    )
    ap.add_argument("--no-progress", action="store_true", help="no progress bar")
    ap.add_argument(
        "--checkpoint-every",
        type=int,
        default=0,
        metavar="FRAMES",
        help="write OUT/checkpoint.npz (the full state) every FRAMES output frames",
    )
    ap.add_argument("--resume", metavar="CHECKPOINT", help="continue a run from its checkpoint.npz")


def writable_folder(out: Path) -> None:
    """Refuse an output folder that cannot be created or written, before any work."""
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".taichi_sls_write_test"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as e:
        raise CaseError(f"--out {str(out)!r}: cannot write there ({e.strerror or e})") from None


def run_command(args: argparse.Namespace) -> int:
    """The main job: load, check, run, print the outcome."""
    from .jobs.case_run import describe_wall, print_outcome, run_case
    from .solver.time_step import resolve_dt
    from .studies.verification import setups, spec

    hooks: dict[str, Any] = {}
    try:
        if spec.is_verification_file(args.case):  # a study's initial fields and load
            vc = spec.load_file(args.case, args.set)
            case = vc.case
            hooks = {"scene": setups.scene(vc), "before_step": setups.before_step(vc)}
        else:
            from .config import load_case

            case = load_case(args.case, args.set)
        resolve_dt(case)  # refuse an unstable fixed dt before any work
        out = Path(args.out) if args.out else Path("out") / case.case.name
        writable_folder(out)
        if args.checkpoint_every < 0:
            raise CaseError(f"--checkpoint-every {args.checkpoint_every}: must be >= 0")
        from .studies.validation.neck import validation_observers

        hooks["observers"] = validation_observers(case, out)  # output.validation
    except CaseError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    # a killed run (SIGTERM) ends like Ctrl-C: outputs closed, summary marked interrupted
    signal.signal(signal.SIGTERM, _interrupt)
    try:
        summary = run_case(
            case,
            out,
            progress=not args.no_progress,
            checkpoint_every=args.checkpoint_every,
            resume=Path(args.resume) if args.resume else None,
            **hooks,
        )
    except CaseError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # before the run's loop: its unheated baseline, its compile
        print("interrupted before the run began (no summary)", file=sys.stderr)
        return EXIT_CODES["interrupted"]
    if "final" not in summary:  # failed before the first frame (settling, say)
        print(f"error: {summary.get('error', summary['status'])}", file=sys.stderr)
        return EXIT_CODES[summary["status"]]
    fin = summary["final"]
    print(
        f"{summary['status']}: {summary['steps']} steps, {summary['simulated_s'] * 1e3:.3g} ms "
        f"simulated in {summary['step_wall_s']:.1f} s ({summary['steps_per_s']:,.0f} steps/s; "
        f"compile {summary['compile_s']:.1f} s); peak T {fin['T_peak_C']:.1f} C, contact line "
        f"{fin['contact_line_um']:.2f} um -> {out}",
        file=sys.stderr,
    )
    print_outcome(summary)
    print(describe_wall(summary["wall_breakdown_s"]), file=sys.stderr)
    if summary["status"] == "failed":
        print(f"error: {summary['error']}", file=sys.stderr)
    return EXIT_CODES[summary["status"]]


def case_command(args: argparse.Namespace) -> int:
    from .config.reference import describe_keys

    text = describe_keys()
    if args.write:
        Path(args.write).write_text(text)
    else:
        print(text, end="")
    return 0


# the studies a user runs, in the package: name -> (module, what it answers)
STUDIES = {
    "hold": ("taichi_sls.studies.sinter_hold", "a melt that sinters for a second, against Hopper"),
    "window": ("taichi_sls.studies.pair_window", "a pair in the sintering window, against Hopper"),
    "refinement": (
        "taichi_sls.studies.refinement",
        "the paper's cases under grid and dt refinement",
    ),
    "process": ("taichi_sls.studies.process.study", "a PA12 layer's density against the process"),
    "tornado": (
        "taichi_sls.studies.validation.tornado",
        "the held pulsed pair's neck across published input ranges",
    ),
    "hotstage": (
        "taichi_sls.studies.validation.hot_stage",
        "the hot-stage pairs: one calibrated temperature, ten predicted",
    ),
    "laserpair": (
        "taichi_sls.studies.validation.laser_pair",
        "the laser-pulsed pair: A calibrated on the peak, the cooling against the measured",
    ),
}
# the developer's benchmarks, bench/NAME.py in a checkout (not installed): what they measure
BENCHMARKS = {
    "speed": "cost per step against a minimal MLS-MPM step",
    "speed3d": "explicit 3D point-steps per second and bytes per point",
    "compile": "compile time of every bundled case, cold and warm",
    "cost": "run time against error over dt, inertia scale and grid",
    "implicit": "explicit and implicit integrators side by side",
    "implicit3d": "the 3D implicit step's cost against its unknowns",
    "accuracy": "verification cases against analytic solutions, by resolution",
    "robustness": "cases at the edge of stability: stable, caught or WRONG",
    "neck": "the melted pair under surface tension alone, by Poisson ratio",
    "packing3d": "the 3D bed generator's packing fraction, per seed",
    "symmetry": "a 3D pair's quarter under two mirror walls against the full domain",
    "spherepair": "3D coalescence of two liquid spheres against Frenkel and Pokluda",
    "isotropy": "a filleted pair's neck growth at 0, 30 and 45 deg to the grid",
    "bedgrid": "a 3D layer's density and contacts over grids and bed draws",
}


def bench_root() -> Path | None:
    """The checkout whose ``bench/`` holds the benchmarks: the one this package is installed
    from (``pip install -e .``), else the working folder; None for an installed package."""
    for root in (Path(__file__).resolve().parents[1], Path.cwd()):
        if (root / "bench" / "__init__.py").is_file():
            return root
    return None


def _bench_module(name: str) -> Any:
    """Import the module of ``bench NAME``: a study from the package, or bench/NAME.py."""
    if name in STUDIES:
        return importlib.import_module(STUDIES[name][0])
    root = bench_root()
    if root is None:
        raise CaseError(
            f"bench {name}: a developer's benchmark, bench/{name}.py in a checkout of the "
            f"repository (run it there after pip install -e .); this installed package "
            f"({Path(__file__).parent}) has no bench/ beside it"
        )
    if str(root) not in sys.path:
        sys.path.insert(0, str(root))
    return importlib.import_module(f"bench.{name}")


class _Parser(argparse.ArgumentParser):
    """The top-level parser: a lazy subcommand (``sweep``, ``bench NAME``) is parsed in full by
    the parser its module adds, the module imported only then; the rest parse here."""

    def parse_known_args(
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        argv = sys.argv[1:] if args is None else list(args)
        if argv[:1] == ["sweep"]:
            command, name, module = "sweep", "sweep", "taichi_sls.jobs.sweep.runner"
        elif argv[:1] == ["bench"] and argv[1:2] and argv[1] in (*STUDIES, *BENCHMARKS):
            command, name, module = "bench", argv[1], None
        else:
            return super().parse_known_args(argv, namespace)
        try:
            loaded = importlib.import_module(module) if module else _bench_module(name)
        except CaseError as e:
            self.error(str(e))
        ap = argparse.ArgumentParser(prog=self.prog if module else f"{self.prog} bench")
        loaded.add_parser(ap.add_subparsers(dest="name", required=True))
        start = 1 if module else 2
        return ap.parse_known_args([name, *argv[start:]], argparse.Namespace(command=command))


def parser() -> argparse.ArgumentParser:
    ap = _Parser(
        prog="taichi-sls", description="Particle-scale MPM simulation of selective laser sintering."
    )
    sub = ap.add_subparsers(
        dest="command", required=True, metavar="SUBCOMMAND", parser_class=argparse.ArgumentParser
    )
    p = sub.add_parser("run", help="run a case with every output")
    add_run_arguments(p)
    p.set_defaults(func=run_command)
    # sweep and bench NAME: listed here, parsed by _Parser with their modules' parsers
    sub.add_parser("sweep", help="a parameter sweep on Dask (SWEEP.toml)")
    listing = [f"  {n:<11} {h}" for n, (_, h) in STUDIES.items()]
    listing += ["", "developer's benchmarks (bench/NAME.py in a checkout of the repository):"]
    listing += [f"  {n:<11} {h}" for n, h in BENCHMARKS.items()]
    p = sub.add_parser(
        "bench",
        help="studies (hold, window, refinement, process) and benchmarks (bench/ in a checkout)",
        description="A study, or a developer's benchmark; taichi-sls bench NAME --help for its "
        "options.",
        epilog="studies:\n" + "\n".join(listing),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("study", choices=[*STUDIES, *BENCHMARKS], metavar="NAME")
    p = sub.add_parser("case", help="print the case-file reference (every key, default, unit)")
    p.add_argument("--write", metavar="FILE", help="write it to FILE instead")
    p.set_defaults(func=case_command)
    return ap


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    return args.func(args)


def run_main(argv: list[str] | None = None) -> int:
    """``python -m taichi_sls.run CASE ...``: the run subcommand alone."""
    ap = argparse.ArgumentParser(prog="python -m taichi_sls.run", description="Run a case file.")
    add_run_arguments(ap)
    return run_command(ap.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
