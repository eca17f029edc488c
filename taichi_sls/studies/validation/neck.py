"""The pair's computed neck beside a measured one (``output.validation``): an observer of the run
that keeps a / R frame by frame (a = half the contact line, R the discs' radius) and, at the
end, writes ``validation.csv`` (the computed a / R at each measured time, linear between frames,
the measured a / R, their difference and its source) and ``validation.png`` (a / R and the
pair's temperature against time, the measured points beside them), and adds the comparison to
the summary (docs/validation.md). No parameter is fitted: the measured points are only read.

The command line's run attaches it when the case asks (:func:`validation_observers`); a
script passes ``observers=validation_observers(case, out)`` to ``run_case``.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ...config import Case, CaseError
from ...io.atomic import write_rows
from ...jobs.run_loop import Frame, Observer, RunEnd
from .measured import NeckPoint, TemperaturePoint, load_pulse_neck, load_pulse_temperature

CSV_NAME = "validation.csv"
PNG_NAME = "validation.png"
COLUMNS = ["t_s", "computed_a_over_R", "measured_a_over_R", "error", "source"]

# output.validation -> the measured neck and temperature it names (taichi_sls/data/pa12)
RECORDS: dict[str, tuple[Callable[[], list[NeckPoint]], Callable[[], list[TemperaturePoint]]]] = {
    "pulse_pair_R125": (load_pulse_neck, load_pulse_temperature),
}


@dataclass(frozen=True)
class Comparison:
    """One measured time: the computed a / R there (NaN past the run's end), the measured one,
    computed - measured, and the measured point's source."""

    t_s: float
    computed: float
    measured: float
    source: str

    @property
    def error(self) -> float:
        return self.computed - self.measured


def pair_radius_um(case: Case) -> float:
    """R of the compared pair: bodies 0 and 1, discs (or cylinders, spheres) of one radius."""
    bodies = case.bodies
    radii = [getattr(b, "radius_um", None) for b in bodies[:2]]
    if len(bodies) < 2 or None in radii or not math.isclose(radii[0], radii[1], rel_tol=1e-9):
        shapes = ", ".join(f"{b.shape} {getattr(b, 'radius_um', '-')}" for b in bodies[:2])
        raise CaseError(
            f"output.validation = {case.output.validation!r}: bodies 0 and 1 are {shapes or 'none'}"
            " (radius um); allowed: a pair of round bodies of one radius"
        )
    return float(radii[0])


def compare(t_s: np.ndarray, a_over_R: np.ndarray, measured: list[NeckPoint]) -> list[Comparison]:
    """The computed a / R at each measured time, linear between the run's frames (NaN after
    the last frame or before the first)."""
    out = []
    for p in measured:
        inside = len(t_s) > 0 and t_s[0] <= p.t_s <= t_s[-1]
        value = float(np.interp(p.t_s, t_s, a_over_R)) if inside else math.nan
        out.append(Comparison(p.t_s, value, p.neck_over_radius, p.source))
    return out


def largest_error(rows: list[Comparison], up_to_s: float) -> float:
    """The largest |computed - measured| a / R over the measured times up to ``up_to_s`` that
    the run reached (NaN if none)."""
    errs = [abs(r.error) for r in rows if r.t_s <= up_to_s and math.isfinite(r.computed)]
    return max(errs) if errs else math.nan


class NeckValidation(Observer):
    """The observer of the module docstring, for the record ``case.output.validation`` names."""

    key = "validation"
    records_failed_frame = True

    def __init__(self, case: Case, out_dir: str | Path) -> None:
        self.case, self.out_dir = case, Path(out_dir)
        self.radius_um = pair_radius_um(case)
        neck, temperature = RECORDS[case.output.validation]
        self.measured = neck()
        self.measured_T = temperature()
        self.t: list[float] = []
        self.a_over_R: list[float] = []
        self.T_C: list[float] = []

    def frame(self, frame: Frame) -> None:
        m = frame.monitors
        self.t.append(float(frame.sim.t))
        self.a_over_R.append(0.5 * m["contact_line_um"] / self.radius_um)
        self.T_C.append(float(m["T_mean_C"]))

    def finish(self, end: RunEnd) -> None:
        if not self.t:
            return
        rows = compare(np.array(self.t), np.array(self.a_over_R), self.measured)
        write_rows(
            self.out_dir / CSV_NAME,
            [
                {
                    "t_s": r.t_s,
                    "computed_a_over_R": _cell(r.computed),
                    "measured_a_over_R": r.measured,
                    "error": _cell(r.error),
                    "source": r.source,
                }
                for r in rows
            ],
            COLUMNS,
        )
        up_to = self.case.output.validation_up_to_s
        end.summary["validation"] = {
            "record": self.case.output.validation,
            "radius_um": self.radius_um,
            "a_over_R_start": self.a_over_R[0],
            "a_over_R_end": self.a_over_R[-1],
            "end_s": self.t[-1],
            "up_to_s": up_to,
            "max_abs_error": largest_error(rows, up_to),
            "compared": sum(math.isfinite(r.computed) for r in rows),
        }
        if end.interrupted:
            return
        try:
            plot_validation(self, rows, self.out_dir / PNG_NAME)
        except Exception as e:  # noqa: BLE001 -- a plot must never cost the run's outputs
            print(f"warning: {PNG_NAME} not drawn ({type(e).__name__}: {e})", file=sys.stderr)

    def state(self) -> dict[str, Any]:
        return {"t": self.t, "a_over_R": self.a_over_R, "T_C": self.T_C}

    def restore(self, state: dict[str, Any]) -> None:
        self.t = list(state.get("t", []))
        self.a_over_R = list(state.get("a_over_R", []))
        self.T_C = list(state.get("T_C", []))


def _cell(x: float) -> float | str:
    return x if math.isfinite(x) else ""


def _short(source: str) -> str:
    """A source's authors, for a legend: the text before its first parenthesis or comma."""
    return source.split("(")[0].split(",")[0].strip()


def plot_validation(obs: NeckValidation, rows: list[Comparison], path: Path) -> None:
    """a / R (top) and the pair's temperature (bottom) against time: the run's lines, the
    measured points (labelled with their source, digitised) and the error at each of them."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from ...io.frame_panels import save_png

    fig = Figure(figsize=(7.5, 6.5))
    ax, axT = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    t = np.array(obs.t)
    ax.plot(t, obs.a_over_R, color="#1f77b4", label="computed (2D, held at the measured T)")
    m_t = [p.t_s for p in obs.measured]
    m_a = [p.neck_over_radius for p in obs.measured]
    label = f"measured: {_short(obs.measured[0].source)} et al. (digitised)"
    ax.plot(m_t, m_a, "o", color="#d62728", label=label)
    for r in rows:
        if math.isfinite(r.computed):
            ax.plot([r.t_s, r.t_s], [r.measured, r.computed], color="#999999", lw=0.8)
    err = largest_error(rows, obs.case.output.validation_up_to_s)
    ax.set_ylabel("neck a / R")
    ax.set_title(
        f"{obs.case.case.name}: largest |error| {err:.3f} up to "
        f"{obs.case.output.validation_up_to_s:g} s",
        fontsize=10,
    )
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)
    axT.plot(t, obs.T_C, color="#1f77b4", label="held (every point)")
    axT.plot(
        [p.t_s for p in obs.measured_T],
        [p.T_C for p in obs.measured_T],
        ".",
        color="#d62728",
        label="measured (thermal imaging, digitised)",
    )
    axT.set_xlabel("time after the pulse (s)")
    axT.set_ylabel("T (C)")
    axT.legend(loc="upper right", fontsize=8)
    axT.grid(alpha=0.3)
    fig.tight_layout()
    save_png(fig, path, 100)


def validation_observers(case: Case, out_dir: str | Path) -> list[Observer]:
    """The observers ``case.output.validation`` asks for (none for "none")."""
    if case.output.validation == "none":
        return []
    return [NeckValidation(case, out_dir)]
