"""A bed sweep's figure from its ``results.csv``: what the layer became across the process window.

:func:`plot_bed_map` draws, for the rows that collected a bed's record (``bed.fused_fraction``,
``bed.relative_density.initial`` and ``.final``; docs/record/beds.md), the fused fraction of the
contacts and the relative density gained as maps of laser power (y) against scan speed (x), and
both against the line energy P / v (J/m) that sets how much heat a unit length of track takes.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from .plots import _num, _save, load_rows

FUSED = "bed.fused_fraction"
DENSITY_BEFORE = "bed.relative_density.initial"
DENSITY_AFTER = "bed.relative_density.final"


def bed_rows(results_csv: str | Path) -> list[dict[str, Any]]:
    """Rows of a scanning bed sweep (power, speed > 0 and the bed's fused fraction known), each
    with ``line_energy_J_m`` = P / v and ``density_gain`` = final - initial relative density."""
    rows = []
    for r in load_rows(results_csv):
        if r["P_W"] is None or not r["v_m_s"] or r.get(FUSED) in (None, ""):
            continue
        r["line_energy_J_m"] = r["P_W"] / r["v_m_s"]
        r["density_gain"] = _num(r, DENSITY_AFTER) - _num(r, DENSITY_BEFORE)
        rows.append(r)
    return rows


def _map(fig: Figure, ax, rows: list[dict], key: str, label: str, cmap: str) -> None:
    speeds = sorted({r["v_m_s"] for r in rows})
    powers = sorted({r["P_W"] for r in rows})
    grid = np.full((len(powers), len(speeds)), np.nan)
    for r in rows:
        grid[powers.index(r["P_W"]), speeds.index(r["v_m_s"])] = _num(r, key)
    X, Y = np.meshgrid(np.arange(len(speeds)), powers)
    mesh = ax.pcolormesh(X, Y, grid, shading="nearest", cmap=cmap)
    fig.colorbar(mesh, ax=ax, label=label)
    for r in rows:
        mark = "" if r["status"] == "complete" else f" ({r['status']})"
        j = speeds.index(r["v_m_s"])
        ax.text(j, r["P_W"], f"{_num(r, key):.3g}{mark}", ha="center", va="center", fontsize=8)
    ax.set_xticks(range(len(speeds)), [f"{v:g}" for v in speeds])
    ax.set(xlabel="scan speed [m/s]", ylabel="laser power [W]", title=label)


def plot_bed_map(results_csv: str | Path, png: str | Path) -> Path:
    """Fused fraction and density gain as power x speed maps and against the line energy."""
    rows = bed_rows(results_csv)
    fig = Figure(figsize=(13, 4.2), layout="constrained")
    a1, a2, a3 = fig.subplots(1, 3)
    if not rows:
        for a in (a1, a2, a3):
            a.text(0.5, 0.5, "no bed rows", ha="center", va="center", transform=a.transAxes)
        return _save(fig, png)
    _map(fig, a1, rows, FUSED, "fused fraction of the contacts", "Greens")
    _map(fig, a2, rows, "density_gain", "relative density gained", "Blues")
    rows = sorted(rows, key=lambda r: r["line_energy_J_m"])
    e = [r["line_energy_J_m"] for r in rows]
    a3.plot(e, [_num(r, FUSED) for r in rows], "o", color="C2", label="fused fraction")
    a3.set(
        xscale="log", xlabel="line energy P / v [J/m]", ylabel="fused fraction", ylim=(-0.05, 1.05)
    )
    twin = a3.twinx()
    twin.plot(e, [r["density_gain"] for r in rows], "s", color="C0", label="density gained")
    twin.set_ylabel("relative density gained", color="C0")
    a3.set_title("against the line energy")
    a3.grid(alpha=0.3)
    handles = a3.get_legend_handles_labels()[0] + twin.get_legend_handles_labels()[0]
    a3.legend(handles=handles, fontsize=8, loc="upper left")
    return _save(fig, png)
