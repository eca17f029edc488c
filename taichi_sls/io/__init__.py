"""Run outputs: atomic files, frame images, GIF, time series, VTU, summary. This layer knows
no physics and no solver: it writes numbers and arrays it is handed."""
