"""``outcome.png``: the neck and the molten fraction against time on a log axis over the whole
run, and the final shape of the points over the initial one."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .frames import save_png
from .series import read_series


def plot_outcome(
    out_dir: Path, x_initial: np.ndarray, x_final: np.ndarray, body: np.ndarray
) -> Path | None:
    """Draw OUT/outcome.png from OUT/timeseries.csv and the point positions (m); None when the
    series has fewer than two rows."""
    out_dir = Path(out_dir)
    path = out_dir / "timeseries.csv"
    if not path.is_file():
        return None
    s = read_series(path)
    if len(s.get("t_s", [])) < 2:
        return None
    fig = Figure(figsize=(12, 3.6), layout="constrained")
    FigureCanvasAgg(fig)
    ax_neck, ax_shape = fig.subplots(1, 2, width_ratios=[1.2, 1])
    t = s["t_s"]
    keep = t > 0
    ax_neck.semilogx(t[keep], s["contact_line_um"][keep], "C0o-", ms=3, label="contact line")
    ax_neck.set_xlabel("t [s]")
    ax_neck.set_ylabel("contact line [um]", color="C0")
    ax_neck.grid(True, which="both", alpha=0.3)
    ax_m = ax_neck.twinx()
    ax_m.semilogx(t[keep], s["molten_fraction"][keep], "C3s--", ms=3, label="molten fraction")
    ax_m.set_ylabel("molten fraction", color="C3")
    ax_m.set_ylim(-0.02, 1.02)
    if np.isfinite(s["contact_line_um"][0]):
        ax_neck.axhline(s["contact_line_um"][0], color="C0", lw=0.8, ls=":")
    ax_neck.set_title("neck and melt over the run (dotted: the start)", fontsize=10)
    xi, xf = np.asarray(x_initial) * 1e6, np.asarray(x_final) * 1e6
    lo, hi = xi.min(axis=0), xi.max(axis=0)
    span = hi - lo
    # points that flew off (a failed run) would stretch the axes beyond drawing
    ok = np.isfinite(xf).all(axis=1) & np.all(np.abs(xf - 0.5 * (lo + hi)) < 2 * span, axis=1)
    ax_shape.scatter(xi[:, 0], xi[:, 1], s=2, c="0.75", marker="s", lw=0, label="start")
    ax_shape.scatter(
        xf[ok, 0],
        xf[ok, 1],
        s=1,
        c=body[ok],
        cmap="tab10",
        vmin=0,
        vmax=9,
        marker=".",
        lw=0,
        label="end",
    )
    ax_shape.set_aspect("equal")
    ax_shape.set_xlabel("x [um]")
    ax_shape.set_ylabel("y [um]")
    ax_shape.set_title("final shape (colour, by body) over the initial one (grey)", fontsize=10)
    out = out_dir / "outcome.png"
    save_png(fig, out, dpi=90)
    return out
