"""Figures from a sweep's ``results.csv`` (matplotlib Agg, PNG).

- :func:`plot_power`: the paper's Fig. 5, the contact line at 1 ms (the paper's snapshot) and at
  the end (a run to solidification: what the part keeps), and the peak temperature, against
  laser power (stationary rows at the most common spot radius, 50 um in the bundled sweeps);
- :func:`plot_radius_scan`: Fig. 8, the same against spot radius (stationary rows at the most
  common power) and stationary against scanning beams at that power and 50 um, as bars;
- :func:`plot_process_map`: laser power (y) against scan speed or spot radius (x), coloured by
  the final neck's growth over the unheated pair's neck where the rows collected it
  (``neck_unheated_um``, the verdict's baseline), else over the initial one, the verdict of
  each run marked (o fused, x not, ? undecided), the melt line T_peak = T_m drawn as a contour.

Each row's laser power, spot radius and speed, and its initial contact line, come from the case's
own outputs (``OUT/<id>/case.toml``, ``OUT/<id>/summary.json``); without them, from the row's
columns (the base value of an unswept key is then unknown and the row is left out).
``draw.draw_all`` draws every figure the rows support (the process map only for a complete
power x speed grid). Rows with status
``complete`` are drawn as filled markers, ``failed`` ones (the guard stopped the run; values at
that time) as open ones.
"""

from __future__ import annotations

import json
import tomllib
from collections import Counter
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.figure import Figure

from .results import read_results

MELT_C = 175.0  # PA12 T_m; a case's own materials override it
INITIAL_CONTACT_UM = {2.0: 8.27, 4.0: 8.54}  # by grid spacing, when summary.json is missing
DPI = 110


def load_rows(results_csv: str | Path) -> list[dict[str, Any]]:
    """Rows of results.csv with ``P_W``, ``r0_um``, ``v_m_s``, ``contact0_um`` and ``melt_C``
    added (None where unknown). Only rows with status complete, max_time or failed."""
    path = Path(results_csv)
    rows = []
    for r in read_results(path):
        if r.get("status") not in ("complete", "max_time", "failed"):
            continue
        folder = path.parent / str(r["id"])
        r = dict(r)
        las: dict[str, Any] = {}
        spacing = None
        r["melt_C"] = MELT_C
        with_case = folder / "case.toml"
        if with_case.is_file():
            case = tomllib.loads(with_case.read_text())
            las = (case.get("lasers") or [{}])[0]
            spacing = case.get("grid", {}).get("spacing_um")
            mats = case.get("materials", {})
            if mats:
                r["melt_C"] = min(m.get("melt_C", MELT_C) for m in mats.values())
        for name, key, col in (
            ("P_W", "power_W", "lasers.0.power_W"),
            ("r0_um", "spot_radius_um", "lasers.0.spot_radius_um"),
            ("v_m_s", "speed_m_s", "lasers.0.speed_m_s"),
        ):
            v = las.get(key, r.get(col, ""))
            r[name] = float(v) if isinstance(v, (int, float)) else None
        r["contact0_um"] = None
        summ = folder / "summary.json"
        if summ.is_file():
            init = json.loads(summ.read_text()).get("initial") or {}
            r["contact0_um"] = init.get("contact_line_um")
        if r["contact0_um"] is None and spacing is not None:
            r["contact0_um"] = INITIAL_CONTACT_UM.get(float(spacing))
        rows.append(r)
    return rows


def _num(r: dict[str, Any], key: str) -> float:
    v = r.get(key)
    return float(v) if isinstance(v, (int, float)) else float("nan")


def _mode(values: list[float | None]) -> float | None:
    vals = [v for v in values if v is not None]
    return Counter(vals).most_common(1)[0][0] if vals else None


def _series(ax, rows: list[dict], xkey: str, ykey: str, color: str, label: str) -> None:
    rows = sorted(rows, key=lambda r: r[xkey])
    x = [r[xkey] for r in rows]
    y = [_num(r, ykey) for r in rows]
    ax.plot(x, y, "-", color=color, lw=1.2, alpha=0.6)
    ok = [(a, b) for a, b, r in zip(x, y, rows, strict=True) if r["status"] == "complete"]
    bad = [(a, b) for a, b, r in zip(x, y, rows, strict=True) if r["status"] != "complete"]
    if ok:
        ax.plot(*zip(*ok, strict=True), "o", color=color, label=label)
    if bad:
        ax.plot(*zip(*bad, strict=True), "o", mfc="none", color=color, label=f"{label} (failed)")


def _pair(fig: Figure, rows: list[dict], xkey: str, xlabel: str, title: str, axes=None) -> None:
    """Contact line (left) and peak temperature (right) against ``xkey``."""
    a1, a2 = axes if axes is not None else fig.subplots(1, 2)
    if not rows:
        for a in (a1, a2):
            a.text(0.5, 0.5, "no rows", ha="center", va="center", transform=a.transAxes)
        return
    if any(r.get("neck_1ms_um") not in (None, "") for r in rows):
        _series(a1, rows, xkey, "neck_1ms_um", "C1", "at 1 ms")
        _series(a1, rows, xkey, "neck_final_um", "C0", "end (refrozen)")
    else:
        _series(a1, rows, xkey, "contact_line_um", "C0", "end of run")
    c0 = [r["contact0_um"] for r in rows if r["contact0_um"] is not None]
    if c0:
        a1.axhline(float(np.mean(c0)), color="0.5", ls="--", lw=1, label="initial")
    a1.set(xlabel=xlabel, ylabel="contact line [um]", title=f"{title}: contact line")
    a1.legend(fontsize=8)
    _series(a2, rows, xkey, "T_peak_C", "C3", "peak")
    a2.axhline(rows[0]["melt_C"], color="0.5", ls="--", lw=1, label="T_m")
    a2.set(xlabel=xlabel, ylabel="peak temperature [C]", title=f"{title}: peak temperature")
    a2.legend(fontsize=8)
    for a in (a1, a2):
        a.grid(alpha=0.3)


def plot_power(results_csv: str | Path, png: str | Path) -> Path:
    """Fig. 5: contact line at the end and peak temperature against laser power (stationary)."""
    rows = [r for r in load_rows(results_csv) if r["v_m_s"] == 0 and r["P_W"] is not None]
    r0 = _mode([r["r0_um"] for r in rows])
    rows = [r for r in rows if r["r0_um"] == r0]
    fig = Figure(figsize=(9, 3.6), layout="constrained")
    _pair(fig, rows, "P_W", "laser power [W]", f"stationary, r0 = {r0:g} um" if r0 else "")
    return _save(fig, png)


def plot_radius_scan(results_csv: str | Path, png: str | Path) -> Path:
    """Fig. 8: against spot radius (stationary), and stationary vs scanning at one power, 50 um."""
    rows = [r for r in load_rows(results_csv) if r["P_W"] is not None and r["v_m_s"] is not None]
    P = 15.0 if any(r["P_W"] == 15.0 for r in rows) else _mode([r["P_W"] for r in rows])
    at_P = [r for r in rows if r["P_W"] == P]
    stat = [r for r in at_P if r["v_m_s"] == 0 and r["r0_um"] is not None]
    fig = Figure(figsize=(9, 7), layout="constrained")
    axes = fig.subplots(2, 2)
    _pair(fig, stat, "r0_um", "spot radius r0 [um]", f"stationary, {P:g} W", axes=axes[0])
    r0 = 50.0 if any(r["r0_um"] == 50.0 for r in at_P) else _mode([r["r0_um"] for r in at_P])
    bars = sorted((r for r in at_P if r["r0_um"] == r0), key=lambda r: r["v_m_s"])
    labels = ["stationary" if r["v_m_s"] == 0 else f"{r['v_m_s']:g} m/s" for r in bars]
    final = (
        "neck_final_um"
        if any(r.get("neck_final_um") not in (None, "") for r in bars)
        else ("contact_line_um")
    )
    for ax, key, color, ylabel in (
        (axes[1][0], final, "C0", "contact line at the end [um]"),
        (axes[1][1], "T_peak_C", "C3", "peak temperature [C]"),
    ):
        if not bars:
            ax.text(0.5, 0.5, "no rows", ha="center", va="center", transform=ax.transAxes)
            continue
        vals = [_num(r, key) for r in bars]
        hatch = ["" if r["status"] == "complete" else "//" for r in bars]
        for i, (v, h) in enumerate(zip(vals, hatch, strict=True)):
            ax.bar(i, v, color=color, alpha=0.8 if not h else 0.4, hatch=h)
            ax.text(i, v, f"{v:.3g}", ha="center", va="bottom", fontsize=8)
        ax.set_xticks(range(len(bars)), labels)
        spot = f", r0 = {r0:g} um" if r0 is not None else ""  # unknown without the run folders
        ax.set(ylabel=ylabel, title=f"stationary vs scanning, {P:g} W{spot}")
        if key == "T_peak_C":
            ax.axhline(bars[0]["melt_C"], color="0.5", ls="--", lw=1)
            ax.set_ylim(bottom=min(140.0, min(vals) - 10))
        ax.grid(alpha=0.3, axis="y")
    return _save(fig, png)


def neck_growth(rows: list[dict[str, Any]], neck: str) -> tuple[list[float], str]:
    """Each row's ``neck`` (um) over the neck its verdict was judged by: the unheated pair's
    (``neck_unheated_um``) where every row collected one, else the initial contact line; and
    which of the two it was."""
    unheated = bool(rows) and all(np.isfinite(_num(r, "neck_unheated_um")) for r in rows)
    base = "neck_unheated_um" if unheated else "contact0_um"
    return [_num(r, neck) - _num(r, base) for r in rows], "unheated" if unheated else "initial"


def plot_process_map(results_csv: str | Path, png: str | Path, xkey: str = "v_m_s") -> Path:
    """Power (y) against scan speed (``xkey = "v_m_s"``) or spot radius (``"r0_um"``), coloured
    by the final neck's growth; the verdicts marked; the melt line T_peak = T_m as a contour."""
    rows = [
        r
        for r in load_rows(results_csv)
        if r["P_W"] is not None and r[xkey] is not None and r["contact0_um"] is not None
    ]
    if xkey == "r0_um":
        rows = [r for r in rows if r["v_m_s"] == 0]
    fig = Figure(figsize=(6.4, 4.8), layout="constrained")
    ax = fig.subplots()
    xs = sorted({r[xkey] for r in rows})
    powers = sorted({r["P_W"] for r in rows})
    if len(xs) < 2 or len(powers) < 2:
        ax.text(0.5, 0.5, "needs 2+ values on each axis", ha="center", transform=ax.transAxes)
        return _save(fig, png)
    growth = np.full((len(powers), len(xs)), np.nan)
    tpeak = np.full_like(growth, np.nan)
    verdicts = []
    kept = ("neck_final_um", "neck_refrozen_um")  # what the part keeps, where collected
    neck = next(
        (k for k in kept if any(r.get(k) not in (None, "") for r in rows)), "contact_line_um"
    )
    grown, reference = neck_growth(rows, neck)
    for r, g in zip(rows, grown, strict=True):
        i, j = powers.index(r["P_W"]), xs.index(r[xkey])
        growth[i, j] = g
        tpeak[i, j] = _num(r, "T_peak_C")
        fused = r.get("fused")
        mark = {True: "o", False: "x", "True": "o", "False": "x"}.get(fused, "?")
        verdicts.append((j, r["P_W"], mark if r["status"] == "complete" else "!"))
    lo, hi = float(np.nanmin(growth)), float(np.nanmax(growth))
    if lo >= 0:  # growth only: a sequential scale from zero
        scale = {"cmap": "Reds", "vmin": 0.0, "vmax": hi or 1.0}
    else:  # shrinking too: diverging, white at zero
        lim = max(-lo, hi)
        scale = {"cmap": "RdBu_r", "vmin": -lim, "vmax": lim}
    # the x values as equally spaced columns labelled with their values
    X, Y = np.meshgrid(np.arange(len(xs)), powers)
    mesh = ax.pcolormesh(X, Y, growth, shading="nearest", **scale)
    fig.colorbar(mesh, ax=ax, label=f"neck growth, final - {reference} [um]")
    for j, P, mark in verdicts:
        i = powers.index(P)
        text = f"{growth[i, j]:+.1f}" if np.isfinite(growth[i, j]) else ""
        ax.text(j, P, f"{mark} {text}", ha="center", va="center", fontsize=8)
    melt = rows[0]["melt_C"]
    ok = np.isfinite(tpeak)
    if ok.all() and tpeak.min() < melt < tpeak.max():
        ax.contour(X, Y, tpeak, levels=[melt], colors="k", linewidths=2)
        ax.plot([], [], "k-", lw=2, label=f"T_peak = T_m = {melt:g} C")
        ax.legend(loc="upper right", fontsize=8, framealpha=0.9)
    else:
        why = "outside the map" if ok.all() else "grid incomplete"
        ax.text(0.01, 0.01, f"T_peak = T_m = {melt:g} C: {why}", transform=ax.transAxes)
    ax.set_xticks(range(len(xs)), [f"{v:g}" for v in xs])
    xlabel = "scan speed [m/s] (0 = stationary)" if xkey == "v_m_s" else "spot radius r0 [um]"
    ax.set(xlabel=xlabel, ylabel="laser power [W]")
    ax.set_title(
        "Neck kept after refreezing (o fused, x not, ? undecided, ! failed)"
        if neck in kept
        else "Contact-line growth over the run",
        fontsize=9,
    )
    return _save(fig, png)


def _save(fig: Figure, png: str | Path) -> Path:
    png = Path(png)
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=DPI)
    return png
