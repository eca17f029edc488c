"""``contacts.png``: the necks of a bed run's contacts at the start and at the end (histogram),
and the bed with each contact marked by its outcome (fused, melted through but not fused, still
molten, never melted through)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .frame_panels import save_png

# (label, colour) of each contact outcome, in the order the legend lists them
KINDS = {
    "fused": "#2ca02c",
    "melted through, not fused": "#ff7f0e",
    "still molten": "#d62728",
    "not melted through": "#1f77b4",
}


def contact_kind(row: dict[str, Any]) -> str:
    """The outcome of one contacts.csv row, as KINDS names it."""
    if row["fused"]:
        return "fused"
    if not row["refrozen"]:
        return "still molten"
    return "melted through, not fused" if row["melted_through"] else "not melted through"


def plot_contacts(
    out_dir: Path, rows: list[dict[str, Any]], x_um: np.ndarray, dpi: int = 90
) -> Path | None:
    """Draw OUT/contacts.png from the contacts table's rows and the points' final positions
    (um); None without contacts."""
    if not rows:
        return None
    fig = Figure(figsize=(13, 3.8), layout="constrained")
    FigureCanvasAgg(fig)
    ax_h, ax_b = fig.subplots(1, 2, width_ratios=[1, 3])
    start = np.array([r["neck_initial_um"] for r in rows], dtype=float)
    end = np.array([r["neck_final_um"] for r in rows], dtype=float)
    both = np.concatenate([start, end])
    both = both[np.isfinite(both)]
    bins = np.linspace(both.min(), both.max(), 21) if len(both) and np.ptp(both) > 0 else 10
    ax_h.hist(start[np.isfinite(start)], bins=bins, histtype="step", lw=1.5, label="start")
    ax_h.hist(end[np.isfinite(end)], bins=bins, histtype="step", lw=1.5, label="end")
    fused = np.mean([r["fused"] for r in rows])
    ax_h.set_title(f"{len(rows)} contacts, {fused:.0%} fused", fontsize=10)
    ax_h.set_xlabel("neck [um]")
    ax_h.set_ylabel("contacts")
    ax_h.legend(fontsize=8)
    ok = np.isfinite(x_um).all(axis=1)
    ax_b.scatter(x_um[ok, 0], x_um[ok, 1], s=0.3, c="0.75", lw=0, rasterized=True)
    kinds = [contact_kind(r) for r in rows]
    for kind, colour in KINDS.items():
        sel = [k == kind for k in kinds]
        if any(sel):
            xs = [r["x_um"] for r, s in zip(rows, sel, strict=True) if s]
            ys = [r["y_um"] for r, s in zip(rows, sel, strict=True) if s]
            ax_b.plot(xs, ys, "o", ms=4, color=colour, label=f"{kind} ({sum(sel)})")
    ax_b.set_aspect("equal")
    ax_b.set_xlabel("x [um]")
    ax_b.set_ylabel("y [um]")
    ax_b.set_title("the bed at the end, contacts where they started", fontsize=10)
    if ok.any():  # room above the bed for the legend
        lo, hi = float(x_um[ok, 1].min()), float(x_um[ok, 1].max())
        ax_b.set_ylim(lo - 0.05 * (hi - lo), hi + 0.45 * (hi - lo))
    ax_b.legend(fontsize=8, loc="upper center", ncols=4, framealpha=0.9)
    out = Path(out_dir) / "contacts.png"
    save_png(fig, out, dpi=dpi)
    return out
