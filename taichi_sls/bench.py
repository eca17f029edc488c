"""Benchmarks: ``python -m taichi_sls.bench speed`` (cost per step and per point-step) and
``python -m taichi_sls.bench accuracy`` (verification cases against analytic solutions)."""

from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    commands = ("speed", "accuracy")
    if not argv or argv[0] not in commands:
        print(f"usage: python -m taichi_sls.bench {{{','.join(commands)}}} [options]; -h for help")
        return 2
    if argv[0] == "speed":
        from .speed import main as run
    else:
        from .accuracy import main as run
    return run(argv[1:])


if __name__ == "__main__":
    raise SystemExit(main())
