"""``python -m taichi_sls.bench STUDY ...``: the benchmarks and studies (``taichi-sls bench``:
speed, cost, accuracy, paper, neck, refinement; see :mod:`taichi_sls.cli`)."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))
