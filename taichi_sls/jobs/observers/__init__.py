"""What a run hands its frames to (jobs/run_loop.py), one idea per module: the summary's
record (record.py), the time series (series.py), the frames and VTU (frames.py), the pair's
verdict (verdict.py), a bed's contacts (contacts.py) and layer file (layer_file.py), the stop
rule (stop_rule.py), warnings (warnings.py), the progress bar (progress.py) and checkpoints
(checkpoints.py)."""
