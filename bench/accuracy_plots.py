"""Plots and the Markdown table of the accuracy study (:mod:`.accuracy`, which hands in its plan:
the studies, each with ``name``, ``measure`` and ``transfers_at``, and the transfer labels)."""

from __future__ import annotations

import math
from pathlib import Path

from taichi_sls.studies import verification as ver
from taichi_sls.studies.verification.common import transfer_label

# point-level cases: their resolution is the time step, not the grid
POINT_LEVEL = ("perzyna", "finite_strain")


def _series(
    rows: list[dict],
    case: str,
    measure: str,
    transfer: str | None,
    precision: str,
    method: str | None = None,
):
    """The rows of one line: a case's measure at one transfer, precision and capillary method
    (None: any)."""
    pts = [
        r
        for r in rows
        if r["case"] == case
        and r["measure"] == measure
        and r["precision"] == precision
        and (transfer is None or r["transfer"] == transfer)
        and (method is None or r.get("method", "") == method)
    ]
    return sorted(
        pts, key=lambda r: -float(r["h_um"]) if case not in POINT_LEVEL else -float(r["dt_s"])
    )


def observed_orders(hs: list[float], errs: list[float]) -> list[float]:
    """log(e_i / e_(i+1)) / log(h_i / h_(i+1)) between consecutive resolutions."""
    out = []
    for i in range(len(hs) - 1):
        e0, e1 = abs(errs[i]), abs(errs[i + 1])
        if e0 > 0 and e1 > 0 and hs[i] != hs[i + 1]:
            out.append(math.log(e0 / e1) / math.log(hs[i] / hs[i + 1]))
        else:
            out.append(math.nan)
    return out


def _own(s) -> tuple[str, str]:
    """(transfer label, capillary method) of a study's case file as it stands."""
    case = ver.load(s.file).case
    return transfer_label(case), case.surface_tension.method if case.physics.surface_tension else ""


def _error_line(ax, pts: list[dict], fmt: str, **kw) -> None:
    h = [float(r["h_um"]) for r in pts]
    ax.loglog(h, [max(abs(float(r["error"])), 1e-16) for r in pts], fmt, **kw)


def _panel_labels(ax, s) -> None:
    ax.set_title(f"{s.name}: {s.measure}", fontsize=9)
    ax.set_xlabel("h (um)", fontsize=8)
    ax.legend(fontsize=7)


def _save(fig, title: str, path: Path) -> Path:
    import matplotlib.pyplot as plt

    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=70)
    plt.close(fig)
    return path


def plot(rows: list[dict], out: Path, studies: tuple, transfers: dict) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    made = []
    cases = [s for s in studies if any(r["case"] == s.name for r in rows)]
    n = len(cases)
    cols = 4
    fig, axes = plt.subplots(math.ceil(n / cols), cols, figsize=(13, 2.8 * math.ceil(n / cols)))
    for ax, s in zip(axes.flat, cases, strict=False):
        pts = _series(rows, s.name, s.measure, *_own(s)[:1], "f64", _own(s)[1])
        x = [float(r["dt_s"] if s.name in POINT_LEVEL else r["h_um"]) for r in pts]
        e = [abs(float(r["error"])) for r in pts]
        ax.loglog(x, e, "o-")
        orders = observed_orders(x, e)
        for i, p in enumerate(orders):
            xm, ym = math.sqrt(x[i] * x[i + 1]), math.sqrt(max(e[i] * e[i + 1], 1e-300))
            ax.annotate(f"{p:.1f}", (xm, ym), fontsize=8, color="C3")
        ax.set_title(f"{s.name}: {s.measure}", fontsize=9)
        ax.set_xlabel("dt (s)" if s.name in POINT_LEVEL else "h (um)", fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.suptitle("Error against resolution (red: observed order between neighbours)", fontsize=10)
    fig.tight_layout()
    made.append(out / "accuracy_convergence.png")
    fig.savefig(made[-1], dpi=70)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for i, s in enumerate(cases):
        pts = _series(rows, s.name, s.measure, _own(s)[0], "f64", _own(s)[1])
        t = [float(r["wall_s"]) for r in pts]
        e = [max(abs(float(r["error"])), 1e-16) for r in pts]
        ax.loglog(t, e, marker="o", label=s.name, color=f"C{i % 10}", ls="-" if i < 10 else "--")
    ax.set_xlabel("wall time (s, compile included)")
    ax.set_ylabel("|error|")
    ax.set_title("Run time against error (each line: refinement of one case)", fontsize=10)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    made.append(out / "accuracy_cost.png")
    fig.savefig(made[-1], dpi=70)
    plt.close(fig)

    prec = [s for s in cases if any(r["case"] == s.name and r["precision"] == "f32" for r in rows)]
    if prec:
        fig, axes = plt.subplots(1, len(prec), figsize=(3.2 * len(prec), 3), squeeze=False)
        for ax, s in zip(axes.flat, prec, strict=False):
            for p, mk in (("f64", "o-"), ("f32", "s--")):
                pts = _series(rows, s.name, s.measure, _own(s)[0], p, _own(s)[1])
                hs = {float(r["h_um"]) for r in _series(rows, s.name, s.measure, None, "f32")}
                pts = [r for r in pts if float(r["h_um"]) in hs]
                _error_line(ax, pts, mk, label=p)
            _panel_labels(ax, s)
        made.append(_save(fig, "f64 against f32", out / "accuracy_precision.png"))

    trans = [
        s
        for s in cases
        if s.transfers_at and len({r["transfer"] for r in rows if r["case"] == s.name}) > 1
    ]
    if trans:
        fig, axes = plt.subplots(1, len(trans), figsize=(3.4 * len(trans), 3), squeeze=False)
        for ax, s in zip(axes.flat, trans, strict=False):
            for i, t in enumerate(transfers):
                pts = [
                    r
                    for r in _series(rows, s.name, s.measure, t, "f64", _own(s)[1])
                    if float(r["resolution"]) in s.transfers_at
                ]
                _error_line(ax, pts, "o-", label=t, color=f"C{i}")
            _panel_labels(ax, s)
        made.append(
            _save(fig, "Transfers: APIC, FLIP, PIC/FLIP 0.9", out / "accuracy_transfer.png")
        )

    methods = [s for s in cases if s.csf_at]
    if methods:
        fig, axes = plt.subplots(1, len(methods), figsize=(3.3 * len(methods), 3), squeeze=False)
        for ax, s in zip(axes.flat, methods, strict=False):
            for i, m in enumerate(("surface_energy", "csf")):
                pts = _series(rows, s.name, s.measure, _own(s)[0], "f64", m)
                _error_line(ax, pts, "o-" if i == 0 else "s--", label=m, color=f"C{i}")
            _panel_labels(ax, s)
        made.append(
            _save(
                fig,
                "Capillary force: surface energy against the paper's CSF",
                out / "accuracy_methods.png",
            )
        )
    return made


def summary_table(rows: list[dict], studies: tuple) -> str:
    """Markdown: per case and measure (default transfer, f64), errors at each resolution and the
    observed orders."""
    lines = [
        "| case | measure | method | resolution: error | observed orders |",
        "|---|---|---|---|---|",
    ]
    for s in studies:
        measures = dict.fromkeys(r["measure"] for r in rows if r["case"] == s.name)
        transfer, own = _own(s)
        for m in measures:
            for method in dict.fromkeys([own, *(["csf"] if s.csf_at else [])]):
                pts = _series(rows, s.name, m, transfer, "f64", method)
                if not pts:
                    continue
                x = [float(r["dt_s"] if s.name in POINT_LEVEL else r["h_um"]) for r in pts]
                e = [float(r["error"]) for r in pts]
                cells = ", ".join(
                    f"{float(r['resolution']):g}: {float(r['error']):+.2e}" for r in pts
                )
                orders = ", ".join(f"{p:.2f}" for p in observed_orders(x, e))
                lines.append(f"| {s.name} | {m} | {method or '-'} | {cells} | {orders} |")
    return "\n".join(lines) + "\n"
