"""The fusion outcome of a run: the neck at the start, at 1 ms, when the melt has frozen again,
and at the end; how long the points stayed above T_m; and the verdict ``fused`` by one rule.

The rule is the one every contact is judged by (jobs/fusion_rule.py: ``contact_verdict``): the
pair of bodies 0 and 1 is fused when its neck region -- the points within ``neck_region_cells``
cells of the mid-plane between them at the start -- melted through (``melted_through`` of its
points were fully molten at some time) and the final neck (contact line) exceeds the reference
neck by ``neck_growth``. The pair's reference is its baseline (``fusion.baseline``): the neck
the same pair reaches unheated (jobs/unheated.py: a soft solid with a surface energy adheres and
grows its contact without any laser), or the initial neck; the summary gives both, and the
growth against each. The verdict needs a laser that heated and a solidified end state (the run
completed with no melt left); a case without a laser, or a run that ends molten or fails, has
``fused = null`` and says why in ``no_verdict``. Every input of the rule is in the summary, so
that a user can apply another one."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..config import Case
from .fusion_rule import contact_verdict, melted_fraction, neck_growth, rule_text

ONE_MS = 1e-3


class NeckHistory:
    """Follows the monitors frame by frame for the quantities of the outcome."""

    def __init__(self) -> None:
        self.initial: float | None = None
        self.at_1ms: float | None = None
        self.refrozen: float | None = None  # the first frame with no melt after some
        self.refrozen_t: float | None = None
        self.molten_peak = 0.0
        self.molten_peak_t = 0.0

    def add(self, mon: dict[str, float]) -> None:
        t, neck, molten = mon["t_s"], mon["contact_line_um"], mon["molten_fraction"]
        if self.initial is None:
            self.initial = neck
        if self.at_1ms is None and t >= ONE_MS * (1 - 1e-9):
            self.at_1ms = neck
        if molten > self.molten_peak:
            self.molten_peak, self.molten_peak_t = molten, t
        if self.refrozen is None and self.molten_peak > 0.0 and molten == 0.0:
            self.refrozen, self.refrozen_t = neck, t


def neck_region(case: Case, x0: np.ndarray, body: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """Which points (by their start positions, m) lie in the neck region of bodies 0 and 1."""
    if len(case.bodies) < 2:
        return np.zeros(len(x0), dtype=bool)
    cx = [float(np.sum(x0[body == b, 0] * mass[body == b]) / mass[body == b].sum()) for b in (0, 1)]
    mid = 0.5 * (cx[0] + cx[1])
    half = case.fusion.neck_region_cells * case.grid.spacing_um * 1e-6
    return (np.abs(x0[:, 0] - mid) <= half) & ((body == 0) | (body == 1))


def laser_acted(case: Case) -> bool:
    """Whether a laser put heat into the case: the verdict asks whether a laser setting fused the
    pair, so a case without one (an isothermal coalescence) gets none."""
    return case.physics.thermal and any(
        las.power_W * las.absorptivity > 0.0 and las.off_s > las.on_s for las in case.lasers
    )


def outcome(
    case: Case,
    history: NeckHistory,
    final: dict[str, float],
    time_molten: np.ndarray,
    in_neck: np.ndarray,
    solidified: bool,
    baseline_um: float | None = None,
) -> dict[str, Any]:
    """The outcome record of the summary (lengths in um, times in s). ``baseline_um``: the
    unheated run's neck (jobs/unheated.py), when one was made."""
    f = case.fusion
    neck0 = history.initial if history.initial is not None else math.nan
    neck_end = final["contact_line_um"]
    melted = melted_fraction(time_molten, in_neck)
    unheated = baseline_um if baseline_um is not None else math.nan
    reference, reference_name = neck0, "initial neck"
    if f.baseline == "unheated":
        reference, reference_name = unheated, "unheated neck"
    verdict = contact_verdict(
        melted,
        neck_end,
        reference,
        solidified=solidified,
        heated=laser_acted(case),
        melted_through=f.melted_through,
        margin=f.neck_growth,
        reference_name=reference_name,
    )
    melted_clause, grown_clause = rule_text(f.melted_through, f.neck_growth, reference_name)
    return {
        "fused": verdict.fused,
        "no_verdict": verdict.no_verdict,
        "rule": (
            f"{melted_clause} and {grown_clause}; needs a solidified end state and a laser that "
            "heated"
        ),
        "solidified": solidified,
        "baseline": f.baseline,
        "neck_initial_um": neck0,
        "neck_unheated_um": unheated,
        "neck_growth_over_unheated": neck_growth(neck_end, unheated),
        "neck_1ms_um": history.at_1ms,
        "neck_refrozen_um": history.refrozen,
        "refrozen_s": history.refrozen_t,
        "neck_final_um": neck_end,
        "neck_growth": neck_growth(neck_end, neck0),
        "neck_region_melted_fraction": melted,
        "neck_region_points": int(in_neck.sum()),
        "time_above_melt_s": {
            "max": float(time_molten.max()) if len(time_molten) else 0.0,
            "mean": float(time_molten.mean()) if len(time_molten) else 0.0,
            "neck_region_mean": float(time_molten[in_neck].mean()) if in_neck.any() else 0.0,
        },
        "molten_fraction_peak": history.molten_peak,
        "molten_fraction_peak_s": history.molten_peak_t,
        "T_peak_C": final.get("T_peak_C"),
    }


def describe(o: dict[str, Any]) -> str:
    """The outcome as lines for the run's printout."""
    verdict = {True: "FUSED", False: "NOT FUSED"}.get(
        o["fused"], f"no verdict ({o.get('no_verdict') or 'not solidified'})"
    )

    def um(v: float | None) -> str:
        return "-" if v is None or not math.isfinite(v) else f"{v:.2f} um"

    return (
        f"outcome: {verdict}; neck {um(o['neck_initial_um'])} at the start, "
        f"{um(o['neck_1ms_um'])} at 1 ms, {um(o['neck_refrozen_um'])} when refrozen, "
        f"{um(o['neck_final_um'])} at the end ({o['neck_growth']:+.1%})"
        + (
            f", {um(o['neck_unheated_um'])} unheated ({o['neck_growth_over_unheated']:+.1%})"
            if math.isfinite(o.get("neck_unheated_um", math.nan))
            else ""
        )
        + f"; neck region melted "
        f"{o['neck_region_melted_fraction']:.0%}, peak T {o['T_peak_C']:.1f} C, longest time "
        f"above T_m {o['time_above_melt_s']['max'] * 1e3:.3g} ms\n  rule: {o['rule']}"
    )
