"""Benchmarks: ``python -m taichi_sls.bench SUBCOMMAND ...``.

``speed``: cost per step and per point-step against the one-kernel-per-stage layout and a minimal
MLS-MPM step (:mod:`taichi_sls.speed`); ``accuracy``: the verification cases against analytic
solutions at several resolutions (:mod:`taichi_sls.accuracy`)."""

from __future__ import annotations

import argparse
import sys


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["speed"]:  # parses its own options
        from .speed import main as speed

        return speed(argv[1:])
    from . import accuracy

    ap = argparse.ArgumentParser(prog="python -m taichi_sls.bench", description=__doc__)
    sub = ap.add_subparsers(dest="command", required=True)
    accuracy.add_parser(sub)
    sub.add_parser("speed", help="speed benchmark (python -m taichi_sls.bench speed -h)")
    args = ap.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
