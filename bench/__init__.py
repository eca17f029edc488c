"""The developer's benchmarks and one-off studies: scripts that measure the code (speed, compile
time, cost against error, accuracy, robustness, ...), run from a checkout of the repository as
``taichi-sls bench NAME`` (bench/NAME.py). They are not installed with the package; the studies
a user runs (hold, window, refinement, process) are in taichi_sls/studies/."""
