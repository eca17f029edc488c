"""``python -m taichi_sls.run CASE.toml [--out DIR] [--set key=value ...]``: the main job
(``taichi-sls run``; see :mod:`taichi_sls.cli`)."""

import sys

from .cli import run_main

if __name__ == "__main__":
    sys.exit(run_main())
