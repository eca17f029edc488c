"""Benchmarks: ``python -m taichi_sls.bench SUBCOMMAND ...``; each subcommand lives in its own
module and registers itself here (``accuracy``: :mod:`taichi_sls.accuracy`)."""

from __future__ import annotations

import argparse
import sys

from . import accuracy


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m taichi_sls.bench", description=__doc__)
    sub = ap.add_subparsers(dest="command", required=True)
    accuracy.add_parser(sub)
    args = ap.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
