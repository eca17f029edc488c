"""The refinement study's report: the arithmetic of convergence (observed order, Richardson
estimate, relative change), the table (``refinement_table.md``) and the plot (``refinement.png``)
from the rows of ``refinement.csv`` (see :mod:`taichi_sls.studies.refinement`)."""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

# ends whose values enter the table (max_time: not refrozen by time.max_s, its 1 ms neck holds)
VALID = ("complete", "max_time")
# the orders the Richardson estimate uses: an observed order outside is clamped into it (below
# 0.5 the extrapolation would multiply the last difference by more than 2.4; above 4 is beyond
# any order the scheme has)
P_RANGE = (0.5, 4.0)


QUANTITIES = (
    ("neck_1ms_um", "neck at 1 ms (um)"),
    ("neck_refrozen_um", "neck refrozen (um)"),
    ("T_peak_C", "peak T (C)"),
)


# ------------------------------------------------------------------------------ arithmetic


@dataclass(frozen=True)
class Extrapolation:
    """The observed order of three values on grids refined by ``ratio`` and the Richardson
    estimate of the converged value; ``note`` says why either is missing or was clamped."""

    order: float  # nan: not monotone, or a difference vanishes
    estimate: float  # nan: not converging
    note: str = ""


def richardson(
    coarse: float,
    mid: float,
    fine: float,
    ratio: float = 2.0,
    p_range: tuple[float, float] = P_RANGE,
) -> Extrapolation:
    """p = log_r((f_4h - f_2h) / (f_2h - f_h)), estimate f_h + (f_h - f_2h) / (r^p - 1) with p
    clamped into ``p_range``. Not monotone, growing differences or f_4h = f_2h != f_h: no
    estimate; f_2h = f_h: the estimate is f_h (order nan)."""
    vals = (coarse, mid, fine)
    if not all(math.isfinite(v) for v in vals):
        return Extrapolation(math.nan, math.nan, "missing value")
    d_coarse, d_fine = coarse - mid, mid - fine
    tiny = 1e-12 * max(abs(v) for v in vals)  # a difference below rounding counts as none
    if abs(d_fine) <= tiny:
        return Extrapolation(math.nan, fine, "converged: f_2h = f_h")
    if abs(d_coarse) <= tiny:
        return Extrapolation(math.nan, math.nan, "not converging: f_4h = f_2h != f_h")
    if d_coarse * d_fine < 0:
        return Extrapolation(math.nan, math.nan, "not converging: not monotone")
    p = math.log(d_coarse / d_fine) / math.log(ratio)
    if p <= 0:
        return Extrapolation(p, math.nan, "not converging: the differences do not shrink")
    used = min(max(p, p_range[0]), p_range[1])
    note = "" if used == p else f"p clamped to {used:g}"
    return Extrapolation(p, fine + (fine - mid) / (ratio**used - 1), note)


def rel_change(ref: float, new: float) -> float:
    """(new - ref) / |ref|; nan where ref is 0 or either is missing."""
    if not (math.isfinite(ref) and math.isfinite(new)) or ref == 0:
        return math.nan
    return (new - ref) / abs(ref)


def num(v: Any) -> float:
    """A float from a CSV cell or a summary value; nan where there is none."""
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def read_csv(path: Path) -> list[dict]:
    with Path(path).open(newline="") as fh:
        return list(csv.DictReader(fh))


# ------------------------------------------------------------------------------ table and plot


def analyse(rows: list[dict], at: float = 2.0) -> list[dict]:
    """Per case and quantity: the three finest spacings at the default dt, their order and
    Richardson estimate, the distance of the h = ``at`` value to it, the dt sensitivity at
    h = ``at``. ``rows`` as read from refinement.csv (strings) or as run."""
    out = []
    for case in dict.fromkeys(r["case"] for r in rows):
        mine = [r for r in rows if r["case"] == case]
        base = {num(r["h_um"]): r for r in mine if num(r["dt_factor"]) == 1.0}
        hs = sorted(base, reverse=True)[-3:]
        by_dt = sorted(
            (r for r in mine if num(r["h_um"]) == at), key=lambda r: -num(r["dt_factor"])
        )
        for key, label in QUANTITIES:

            def value(r: dict, key: str = key) -> float:
                return num(r[key]) if r["status"] in VALID else math.nan

            vals = [value(base[h]) for h in hs]
            if not any(math.isfinite(v) for v in vals):
                continue  # e.g. no refreezing within 1 ms: the quantity is not there
            if len(hs) == 3 and hs[0] / hs[1] == hs[1] / hs[2]:
                ext = richardson(*vals, ratio=hs[0] / hs[1])
            else:
                ext = Extrapolation(math.nan, math.nan, "needs three spacings in one ratio")
            bad = [f"{h:g}" for h in hs if base[h]["status"] not in VALID]
            if bad:  # say why a value is missing
                ext = Extrapolation(ext.order, ext.estimate, f"h = {', '.join(bad)} um failed")
            f_at = value(base[at]) if at in base else math.nan
            dts = [value(r) for r in by_dt]
            out.append(
                {
                    "case": case,
                    "quantity": key,
                    "label": label,
                    "h_um": hs,
                    "values": vals,
                    "statuses": [base[h]["status"] for h in hs],
                    "order": ext.order,
                    "estimate": ext.estimate,
                    "note": ext.note,
                    "at_h_um": at,
                    "off_at": abs(rel_change(ext.estimate, f_at)),
                    "dt_s": [num(r["dt_s"]) for r in by_dt],
                    "dt_values": dts,
                    "dt_half": rel_change(dts[0], dts[1]) if len(dts) > 1 else math.nan,
                    "dt_quarter": rel_change(dts[1], dts[2]) if len(dts) > 2 else math.nan,
                }
            )
    return out


def _g(v: float, fmt: str = ".4g") -> str:
    return "nan" if not math.isfinite(v) else format(v, fmt)


def _pct(v: float) -> str:
    return "-" if not math.isfinite(v) else f"{v:+.1%}"


def table(rows: list[dict], at: float = 2.0) -> str:
    """The Markdown table of :func:`analyse`."""
    lines = [
        f"| case | quantity | h (um) | values | order p | Richardson estimate | h = {at:g} um "
        "off by | dt -> dt/2 | dt/2 -> dt/4 |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for a in analyse(rows, at):
        vals = " / ".join(
            _g(v) if st in VALID else st for v, st in zip(a["values"], a["statuses"], strict=True)
        )
        est = _g(a["estimate"]) + (f" ({a['note']})" if a["note"] else "")
        off = "-" if not math.isfinite(a["off_at"]) else f"{a['off_at']:.1%}"
        lines.append(
            f"| {a['case']} | {a['label']} | {' / '.join(f'{h:g}' for h in a['h_um'])} | {vals} "
            f"| {_g(a['order'], '.2f')} | {est} | {off} | {_pct(a['dt_half'])} "
            f"| {_pct(a['dt_quarter'])} |"
        )
    return "\n".join(lines) + "\n"


def write_table(csv_path: Path, md_path: Path, at: float = 2.0) -> str:
    """refinement_table.md from refinement.csv; returns the table."""
    text = table(read_csv(csv_path), at)
    md_path.write_text(text)
    return text


def plot(rows: list[dict], path: Path, at: float = 2.0) -> None:
    """Per case: the necks against h at the default dt (Richardson estimates dotted), and
    against dt at h = ``at``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    res = [a for a in analyse(rows, at) if a["quantity"] != "T_peak_C"]
    cases = list(dict.fromkeys(r["case"] for r in rows))
    fig, axs = plt.subplots(2, len(cases), figsize=(4 * len(cases), 7), squeeze=False)
    for j, case in enumerate(cases):
        mine = [r for r in rows if r["case"] == case]
        base = sorted((r for r in mine if num(r["dt_factor"]) == 1.0), key=lambda r: num(r["h_um"]))
        by_dt = sorted((r for r in mine if num(r["h_um"]) == at), key=lambda r: num(r["dt_s"]))
        for i, (key, style) in enumerate((("neck_1ms_um", "o-"), ("neck_refrozen_um", "s--"))):
            label = dict(QUANTITIES)[key]

            def ok(r: dict, key: str = key) -> bool:
                return r["status"] in VALID and math.isfinite(num(r[key]))

            pts = [r for r in base if ok(r)]
            if pts:
                axs[0, j].plot(
                    [num(r["h_um"]) for r in pts],
                    [num(r[key]) for r in pts],
                    style,
                    color=f"C{i}",
                    label=label,
                )
            est = [a["estimate"] for a in res if a["case"] == case and a["quantity"] == key]
            if est and math.isfinite(est[0]):
                axs[0, j].axhline(est[0], color=f"C{i}", ls=":", lw=1, label="Richardson")
            pts = [r for r in by_dt if ok(r)]
            if pts:
                axs[1, j].plot(
                    [num(r["dt_s"]) for r in pts],
                    [num(r[key]) for r in pts],
                    style,
                    color=f"C{i}",
                    label=label,
                )
        bad = [f"{num(r['h_um']):g}" for r in base if r["status"] not in VALID]
        axs[0, j].set_title(case + (f" (failed: h = {', '.join(bad)})" if bad else ""), fontsize=9)
        axs[1, j].set_title(f"{case}, h = {at:g} um", fontsize=9)
        for ax, xl, xs in (
            (axs[0, j], "h [um]", [num(r["h_um"]) for r in base]),
            (axs[1, j], "dt [s]", [num(r["dt_s"]) for r in by_dt]),
        ):
            ax.set_xscale("log", base=2)
            if xs:  # ticks at the runs, in plain numbers
                ax.set_xticks(xs, [f"{x:.3g}" for x in xs])
                ax.xaxis.set_minor_formatter(NullFormatter())
            ax.set_xlabel(xl)
            ax.grid(alpha=0.3, which="both")
            if ax.has_data():
                ax.legend(fontsize=7)
        axs[0, j].set_ylabel("neck [um]")
        axs[1, j].set_ylabel("neck [um]")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
