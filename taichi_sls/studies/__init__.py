"""Studies on top of the solver: verification cases against analytic solutions (their references
in :mod:`.references`), parameter sweeps on Dask (:mod:`.sweep`), the process studies of a PA12
layer, the melt held by a warm bed and the pair in the sintering window against Hopper, and the
paper's cases under refinement. The developer's benchmarks are in bench/ of a checkout."""
