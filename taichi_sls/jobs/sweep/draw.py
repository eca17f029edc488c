"""Every figure a sweep's ``results.csv`` supports: a bed sweep's map (:mod:`.bed_plots`), else
the pair's figures (:mod:`.plots`)."""

from __future__ import annotations

from pathlib import Path

from .bed_plots import FUSED, plot_bed_map
from .plots import load_rows, plot_power, plot_process_map, plot_radius_scan


def draw_all(out_dir: str | Path) -> list[Path]:
    """Draw every figure that OUT/results.csv supports into OUT/; return the PNG paths."""
    out = Path(out_dir)
    csv_path = out / "results.csv"
    rows = load_rows(csv_path)
    if any(r.get(FUSED) not in (None, "") for r in rows):  # a bed sweep
        return [plot_bed_map(csv_path, out / "bed_map.png")]
    written = []
    stationary = [r for r in rows if r["v_m_s"] == 0]
    if len({r["P_W"] for r in stationary}) >= 2:
        written.append(plot_power(csv_path, out / "fig5_power.png"))
    if any(r["v_m_s"] not in (0, None) for r in rows) or len({r["r0_um"] for r in rows}) >= 2:
        written.append(plot_radius_scan(csv_path, out / "fig8_radius_scan.png"))
    for xkey, name in (("v_m_s", "process_map.png"), ("r0_um", "process_map_radius.png")):
        sel = [r for r in rows if xkey == "v_m_s" or r["v_m_s"] == 0]
        cells = {(r[xkey], r["P_W"]) for r in sel if None not in (r[xkey], r["P_W"])}
        n_x, n_P = len({c[0] for c in cells}), len({c[1] for c in cells})
        if n_x >= 2 and n_P >= 2 and len(cells) == n_x * n_P:  # a complete grid
            written.append(plot_process_map(csv_path, out / name, xkey))
    return written
