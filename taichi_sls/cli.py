"""The command line: ``taichi-sls SUBCOMMAND ...`` (also ``python -m taichi_sls``).

    run CASE         run a case file (or a bundled case by name) with every output
    sweep SWEEP      a parameter sweep on Dask
    bench STUDY      speed, compile (each bundled case's, cold and warm), cost, implicit (both
                     integrators side by side), hold (a melt that
                     sinters for a second, against Hopper), accuracy, paper (the Table 2 cases),
                     neck (the melted-pair study), refinement (the paper's cases under grid and
                     dt refinement), packing3d (the 3D bed generator's packing fraction),
                     process (a PA12 layer's density against energy density and bed
                     temperature, and its sensitivities), symmetry (a 3D pair's quarter under
                     two mirror walls against the full domain), speed3d (explicit 3D throughput)
    robustness       the stress matrix of cases at the edge of stability
    case             print the case-file reference (docs/case_reference.md)

``python -m taichi_sls.run CASE ...`` is ``taichi-sls run CASE ...``; ``python -m taichi_sls.bench
STUDY ...`` is ``taichi-sls bench STUDY ...``.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
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
    from .jobs.case_run import print_outcome, run_case
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


def parser() -> argparse.ArgumentParser:
    from .studies import (
        accuracy,
        bed3d_packing,
        compile_bench,
        cost_error,
        implicit3d_bench,
        implicit_bench,
        neck_study,
        pair_window,
        paper,
        refinement,
        robustness,
        sinter_hold,
        speed,
        speed3d,
        sphere_pair,
        symmetry,
    )
    from .studies.process import study as process_study
    from .studies.sweep import runner as sweep

    ap = argparse.ArgumentParser(
        prog="taichi-sls", description="Particle-scale MPM simulation of selective laser sintering."
    )
    sub = ap.add_subparsers(dest="command", required=True, metavar="SUBCOMMAND")
    p = sub.add_parser("run", help="run a case with every output")
    add_run_arguments(p)
    p.set_defaults(func=run_command)
    sweep.add_parser(sub)
    bench = sub.add_parser(
        "bench",
        help="benchmarks and studies: speed, compile, cost, implicit, implicit3d, hold, window, "
        "accuracy, paper, neck, refinement, packing3d, process, symmetry, speed3d, spherepair",
    )
    studies = bench.add_subparsers(dest="study", required=True, metavar="STUDY")
    for module in (
        speed,
        compile_bench,
        cost_error,
        implicit_bench,
        implicit3d_bench,
        sinter_hold,
        pair_window,
        accuracy,
        paper,
        neck_study,
        refinement,
        bed3d_packing,
        process_study,
        symmetry,
        speed3d,
        sphere_pair,
    ):
        module.add_parser(studies)
    robustness.add_parser(sub)
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
