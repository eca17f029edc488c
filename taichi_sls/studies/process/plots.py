"""The process studies' figures: density against the Andrew number beside the published PA12
points, density against the bed temperature, and the tornado of the sensitivities."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

from matplotlib.figure import Figure  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

from .measured import MeasuredPoint  # noqa: E402

DPI = 110
HATCH_MARKERS = {100.0: "o", 150.0: "s", 200.0: "^"}
NOT_COMPARABLE = {
    2: "2D: a section of discs across the tracks. Compare how the density rises with energy and\n"
    "where it levels off, not its level: a 2D disc packing starts near 0.83, a 3D powder bed\n"
    "near 0.46, and a part's pores are 3D (open or closed), which no 2D section counts.",
    3: "3D: one layer of spheres after its layer time, with no layer above. A part's density is\n"
    "that of hundreds of layers, each remelted by the next and held hot for the hours of the\n"
    "build: compare how the density rises with energy and where it levels off; its level is a\n"
    "lower bound.",
}


def _save(fig: Figure, png: str | Path) -> Path:
    png = Path(png)
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=DPI)
    return png


def plot_density_energy(
    rows: list[dict[str, Any]],
    measured: list[MeasuredPoint],
    png: str | Path,
    dim: int = 2,
    bands: Sequence[tuple[str, float, float]] = (),
) -> Path:
    """Left: the simulated layer's relative density before (x) and after the layer time (filled,
    marker by hatch; other draws of the bed, rows whose ``seed`` differs from the first row's,
    hollow) against the Andrew number, with the published points: a source with an energy
    density as a labelled diamond, one without as a labelled horizontal line, and ``bands``
    (label, low, high) as shaded ranges of relative density. Right: the simulated density gain
    against the Andrew number."""
    fig = Figure(figsize=(12.5, 5.6 if dim == 2 else 6.6), layout="constrained")
    ax, gx = fig.subplots(1, 2, width_ratios=[1.15, 1])
    e_max = max([r["andrew_J_mm2"] for r in rows] + [0.06])
    first_seed = rows[0].get("seed") if rows else None
    draws = [r for r in rows if r.get("seed") != first_seed]
    rows = [r for r in rows if r.get("seed") == first_seed]
    for h in sorted({r["hatch_um"] for r in rows}):
        sel = [r for r in rows if r["hatch_um"] == h]
        kw = {"marker": HATCH_MARKERS.get(h, "D"), "ls": "none", "ms": 7}
        ax.plot(
            [r["andrew_J_mm2"] for r in sel],
            [r["bed.relative_density.final"] for r in sel],
            color="C0",
            label=f"simulated {dim}D layer, after the hold (hatch {h:g} um)",
            **kw,
        )
        gx.plot(
            [r["andrew_J_mm2"] for r in sel],
            [100 * r["gain"] for r in sel],
            color="C0",
            label=f"hatch {h:g} um",
            **kw,
        )
    if draws:
        seeds = ", ".join(str(s) for s in sorted({r["seed"] for r in draws}))
        kw = {"marker": "o", "ls": "none", "ms": 9, "mfc": "none", "color": "C0"}
        x = [r["andrew_J_mm2"] for r in draws]
        ax.plot(x, [r["bed.relative_density.final"] for r in draws], **kw)
        ax.plot([], [], label=f"the same on other beds (seeds {seeds})", **kw)
        gx.plot(x, [100 * r["gain"] for r in draws], label=f"other beds (seeds {seeds})", **kw)
    if rows:
        ax.plot(
            [r["andrew_J_mm2"] for r in rows + draws],
            [r["bed.relative_density.initial"] for r in rows + draws],
            "x",
            color="0.5",
            label=f"simulated {dim}D layer, settled powder before the scan",
        )
        # the hatch most rows share, joined: power and speed at one hatch
        common = max(
            {r["hatch_um"] for r in rows}, key=lambda h: sum(r["hatch_um"] == h for r in rows)
        )
        line = sorted((r for r in rows if r["hatch_um"] == common), key=lambda r: r["andrew_J_mm2"])
        gx.plot([r["andrew_J_mm2"] for r in line], [100 * r["gain"] for r in line], "-", lw=0.8)
    for k, (label, lo, hi) in enumerate(bands):
        ax.axhspan(lo, hi, color=f"C{len(measured) + k + 1}", alpha=0.2, label=label)
    for i, p in enumerate(measured):
        rel = p.relative_density
        if p.energy_J_mm2 is not None:
            label = f"{p.label} ({p.kind})"
            ax.plot(p.energy_J_mm2, rel, "D", color=f"C{i + 1}", ms=7, label=label)
            ax.annotate(
                p.process,
                (p.energy_J_mm2, rel),
                xytext=(8, -3),
                textcoords="offset points",
                fontsize=8,
                color=f"C{i + 1}",
            )
        else:
            ax.axhline(rel, color=f"C{i + 1}", ls="--", lw=1)
            ax.text(
                0.002,
                rel + 0.006,
                f"{p.label}: {rel:.3f} ({p.kind}; no energy density)",
                color=f"C{i + 1}",
                fontsize=8,
            )
    ax.set_xlim(-0.002, 1.1 * e_max)
    ax.set_ylim(0.40, 1.04)
    ax.set_xlabel("Andrew number P / (v h) (J/mm$^2$)")
    ax.set_ylabel("relative density")
    ax.set_title("PA12 layer: relative density against energy density")
    if dim == 2:
        ax.legend(loc="center", bbox_to_anchor=(0.5, 0.5), fontsize=8)
    else:  # the 3D layer's points span the middle of the axes: the legend below both panels
        fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=3, fontsize=8)
    ax.text(
        0.98 if dim == 2 else 0.02,
        0.16,
        NOT_COMPARABLE[dim],
        transform=ax.transAxes,
        fontsize=8,
        ha="right" if dim == 2 else "left",
        multialignment="left",
    )
    gx.set_xlim(0.0, 1.1 * e_max)
    gx.set_xlabel("Andrew number P / (v h) (J/mm$^2$)")
    gx.set_ylabel("density gained over the layer time (percentage points)")
    gx.set_title(f"simulated {dim}D layer: density gained")
    gx.legend(fontsize=8, loc="upper left")
    gx.grid(alpha=0.3)
    return _save(fig, png)


def plot_bed_temperature(summary: dict[str, Any], marks: dict[str, Any], png: str | Path) -> Path:
    """The density gained against the bed temperature, with the material's crystallisation range
    on cooling and melting onset on heating (``marks``), the machine practice band and the
    threshold of :func:`.summary.bed_summary`."""
    rows = summary["rows"]
    fig = Figure(figsize=(8.5, 5.2), layout="constrained")
    ax = fig.subplots()
    x = [r["bed_C"] for r in rows]
    ax.plot(x, [100 * r["gain"] for r in rows], "o-", color="C0", label="simulated 2D layer")
    if marks.get("crystallization_range_C"):
        lo, hi = marks["crystallization_range_C"]
        ax.axvspan(
            lo, hi, color="C1", alpha=0.2, label=f"crystallisation on cooling {lo:g}-{hi:g} C"
        )
    if marks.get("melt_onset_C") is not None:
        ax.axvline(marks["melt_onset_C"], color="C3", ls=":", label="melting onset on heating")
    lo, hi = marks.get("machine_C", (168.0, 175.0))
    ax.axvspan(lo, hi, color="0.6", alpha=0.25, label=f"machine bed temperatures {lo:g}-{hi:g} C")
    t = summary.get("threshold_C", math.nan)
    if not math.isnan(t):
        share = int(100 * summary["share"])
        ax.axvline(t, color="k", lw=0.8, label=f"densifies from {t:g} C (>= {share} % of the top)")
    ax.set_xlabel("bed temperature (powder, plate and chamber) (C)")
    ax.set_ylabel("density gained over the layer time (percentage points)")
    ax.set_title("where densification stops: density gained against the bed temperature")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    return _save(fig, png)


def plot_sensitivity(summary: dict[str, Any], png: str | Path) -> Path:
    """Tornado: the change of the density gained over the layer time (percentage points) for
    each factor's two levels, largest first; another bed draw (seed) in grey as the noise to
    read them by."""
    fig = Figure(figsize=(9.0, 5.2), layout="constrained")
    ax = fig.subplots()
    facs = summary["factors"]
    for i, f in enumerate(facs):
        y = len(facs) - 1 - i
        noise = f["factor"].startswith("another bed")
        for level, d in f["gain_changes"].items():
            lower = level.startswith(("-", "/"))  # the design's lower levels: /2, -20 %, -3 K
            color = "0.6" if noise else ("C0" if lower else "C3")
            yl = y - 0.17 if lower or (noise and level < max(f["gain_changes"])) else y + 0.17
            ax.barh(yl, 100 * d, color=color, height=0.32)
            ha = "left" if d >= 0 else "right"
            ax.text(100 * d, yl, f" {level} ", fontsize=8, va="center", ha=ha)
        for level in f.get("failed", {}):
            yl = y - 0.17 if level.startswith(("-", "/")) else y + 0.17
            ax.text(
                0,
                yl,
                f" {level}: the run failed (process.json says why)",
                fontsize=8,
                va="center",
                color="C3",
            )
    ax.set_yticks(range(len(facs)), [f["factor"] for f in reversed(facs)])
    handles = [
        Patch(color="C0", label="lower level (/2, -20 %, -3 K)"),
        Patch(color="C3", label="upper level (x2, +20 %, +3 K)"),
        Patch(color="0.6", label="another bed draw: the noise"),
    ]
    ax.legend(handles=handles, fontsize=8, loc="lower right")
    ax.axvline(0, color="k", lw=0.8)
    ref = summary["reference"]
    title = "sensitivity of the density a layer gains over its layer time"
    if ref:
        title += (
            f"\nreference: {ref['initial']:.4f} -> {ref['final']:.4f}, gained "
            f"{100 * ref['gain']:.2f} points"
        )
    ax.set_title(title)
    ax.set_xlabel("change of the density gained (percentage points of relative density)")
    ax.grid(axis="x", alpha=0.3)
    lim = max([abs(100 * d) for f in facs for d in f["gain_changes"].values()] + [0.1])
    ax.set_xlim(-1.35 * lim, 1.35 * lim)
    return _save(fig, png)
