"""The fusion verdict of one contact: the one rule (``[fusion]``) that judges the pair of a
two-body case (jobs/outcome.py) and every contact of a bed (jobs/bed_outcome.py).

A contact is fused when a laser heated, its end state is solidified, its neck region melted
through (``fusion.melted_through`` of the region's points were fully molten at some time) and
its final neck grew over a reference neck by at least ``fusion.neck_growth`` (5 %). The caller
names what each input means for it:

- the reference neck: the pair's baseline (``fusion.baseline``: the unheated neck,
  jobs/unheated.py, or the initial neck); a bed contact's initial neck (an unheated run of a
  whole bed would double its cost);
- solidified: the pair's run completed and holds no melt at its last frame; a bed contact's
  neck region holds no liquid at its last frame (the bed's other contacts may still be molten).

Without a laser that heated, without a solidified end state or without a finite reference the
rule gives no verdict (``fused = None``) and says why; a bed's contacts table writes that as
not fused (0). The two callers differ in one answer only, kept as the named parameter
``zero_reference_grows``: a reference neck of exactly 0 (a contact that did not touch at the
start). The pair's relative growth over nothing is undefined, so it has not grown
(``False``); a bed contact's rule reads final >= (1 + margin) x 0, so any final neck passes
(``True``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ContactVerdict:
    """One contact's verdict: ``fused`` is None when the rule gives none (``no_verdict`` says
    why); ``melted_through`` (a laser heated and the region melted through) and ``growth``
    (final / reference - 1, NaN without a finite nonzero reference) are its two measures."""

    fused: bool | None
    no_verdict: str | None
    melted_through: bool
    growth: float


def neck_growth(final: float, reference: float) -> float:
    """The final neck's growth over the reference, final / reference - 1; NaN for a reference
    that is zero or not finite."""
    return final / reference - 1.0 if reference and math.isfinite(reference) else math.nan


def melted_fraction(time_molten: np.ndarray, region: np.ndarray) -> float:
    """The share of the neck region's points that were fully molten at some time (0 for an
    empty region)."""
    return float(np.mean(time_molten[region] > 0.0)) if region.any() else 0.0


def contact_verdict(
    melted: float,
    final_neck_um: float,
    reference_neck_um: float,
    *,
    solidified: bool,
    heated: bool,
    melted_through: float,
    margin: float,
    reference_name: str = "initial neck",
    zero_reference_grows: bool = False,
) -> ContactVerdict:
    """The verdict of one contact by the rule of the module's docstring. ``melted``: the share
    of its neck region's points ever fully molten; ``melted_through``: the share that counts as
    melted through (``fusion.melted_through``); ``margin``: the growth over the reference neck
    that counts as grown (``fusion.neck_growth``); ``reference_name`` names the reference in the
    reason for no verdict; ``zero_reference_grows``: whether a final neck grew over a reference
    of exactly 0 (a bed contact: yes; the pair: no)."""
    through = heated and melted >= melted_through
    growth = neck_growth(final_neck_um, reference_neck_um)
    no_verdict = None
    if not heated:
        no_verdict = "no laser in this case"
    elif not solidified:
        no_verdict = "not solidified"
    elif not math.isfinite(reference_neck_um):
        no_verdict = f"no {reference_name} (the unheated run failed)"
    if no_verdict is not None:
        return ContactVerdict(None, no_verdict, through, growth)
    if reference_neck_um == 0.0 and zero_reference_grows:
        grown = final_neck_um >= 0.0  # (1 + margin) x 0
    else:
        grown = growth >= margin
    return ContactVerdict(bool(through and grown), None, through, growth)


def rule_text(melted_through: float, margin: float, reference_name: str) -> tuple[str, str]:
    """The rule's two clauses as the summary states them: (melted through, grown)."""
    return (
        f"neck region melted through (>= {melted_through:g} of its points above T_m at some time)",
        f"final neck >= (1 + {margin:g}) x {reference_name}",
    )
