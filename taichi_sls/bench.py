"""``python -m taichi_sls.bench NAME ...`` is ``taichi-sls bench NAME ...``: a study from the
package (hold, window, refinement, process) or a developer's benchmark, bench/NAME.py in a
checkout of the repository (see :mod:`taichi_sls.cli`)."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))
