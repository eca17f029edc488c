"""Parameter sweeps on Dask: sweep files (:mod:`.spec`), the runner (:mod:`.runner`), the
results table (:mod:`.results`) and the figures (:mod:`.plots`). Dask is imported only when a
sweep runs."""
