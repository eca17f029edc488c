"""The one fusion rule (jobs/fusion_rule.py) that judges the pair and every contact of a bed, on
constructed inputs: melted through or not, growth just under and just over the margin, a
solidified end state or not, no laser, no reference, and the one named difference between the
two callers (a zero reference neck). Pure Python: no Taichi, no run."""

import math
import subprocess
import sys

import numpy as np
import pytest

from taichi_sls.jobs.fusion_rule import (
    contact_verdict,
    melted_fraction,
    neck_growth,
    rule_text,
)

MARGIN, THROUGH = 0.05, 0.99  # the [fusion] defaults
INITIAL, UNHEATED = 18.44, 19.67  # um: a pair's neck at t = 0 and its unheated baseline


def _pair(melted, final, reference=UNHEATED, solidified=True, heated=True, name="unheated neck"):
    """The pair's call (jobs/outcome.py): its baseline as the reference, a zero one not grown."""
    return contact_verdict(
        melted,
        final,
        reference,
        solidified=solidified,
        heated=heated,
        melted_through=THROUGH,
        margin=MARGIN,
        reference_name=name,
    )


def _bed(melted, final, initial=INITIAL, refrozen=True, heated=True):
    """A bed contact's call (jobs/bed_outcome.py): its initial neck as the reference."""
    return contact_verdict(
        melted,
        final,
        initial,
        solidified=refrozen,
        heated=heated,
        melted_through=THROUGH,
        margin=MARGIN,
        zero_reference_grows=True,
    )


@pytest.mark.parametrize("judge, reference", [(_pair, UNHEATED), (_bed, INITIAL)])
def test_growth_just_over_the_margin_fuses_and_just_under_does_not(judge, reference):
    over, under = reference * (1 + MARGIN) * (1 + 1e-6), reference * (1 + MARGIN) * (1 - 1e-6)
    fused, short = judge(1.0, over, reference), judge(1.0, under, reference)
    assert fused.fused is True and fused.no_verdict is None and fused.melted_through
    assert fused.growth == pytest.approx(MARGIN, rel=1e-4) and fused.growth > MARGIN
    assert short.fused is False and short.no_verdict is None and short.growth < MARGIN


@pytest.mark.parametrize("judge, reference", [(_pair, UNHEATED), (_bed, INITIAL)])
def test_a_neck_region_not_melted_through_is_not_fused_however_it_grew(judge, reference):
    v = judge(0.98, 2.0 * reference, reference)  # 98 % of the region melted: not through
    assert v.fused is False and not v.melted_through and v.growth == pytest.approx(1.0)
    assert judge(THROUGH, 2.0 * reference, reference).fused is True  # the threshold counts


def test_the_pair_measures_growth_against_its_unheated_baseline():
    """The same final neck grows 8.5 % over the initial neck but 1.7 % over the unheated one:
    the caller's reference decides, and the pair keeps its baseline."""
    final = 20.0
    assert _pair(1.0, final, UNHEATED).fused is False
    assert _pair(1.0, final, INITIAL, name="initial neck").fused is True
    assert _bed(1.0, final, INITIAL).fused is True


def test_no_verdict_without_a_solidified_end_laser_or_reference():
    grown = UNHEATED * 1.2
    molten = _pair(1.0, grown, solidified=False)
    assert molten.fused is None and molten.no_verdict == "not solidified"
    assert molten.melted_through  # the measures are kept for the summary
    cold = _pair(1.0, grown, heated=False, solidified=False)  # no laser is named first
    assert cold.fused is None and cold.no_verdict == "no laser in this case"
    assert not cold.melted_through  # nothing melts through without heat
    failed = _pair(1.0, grown, reference=math.nan)
    assert (
        failed.fused is None and failed.no_verdict == "no unheated neck (the unheated run failed)"
    )
    assert math.isnan(failed.growth)
    # a bed contact that still holds melt, or a bed no laser heats: not fused in its table
    assert _bed(1.0, INITIAL * 1.2, refrozen=False).fused is None
    assert _bed(1.0, INITIAL * 1.2, heated=False).no_verdict == "no laser in this case"
    assert _bed(1.0, math.nan).fused is False  # a final neck not read has not grown


def test_a_zero_reference_is_the_one_named_difference():
    """A contact that did not touch at the start: the pair's relative growth over nothing is
    undefined (not grown); a bed contact's final >= (1 + margin) x 0 passes."""
    assert _pair(1.0, 5.0, reference=0.0).fused is False
    assert math.isnan(_pair(1.0, 5.0, reference=0.0).growth)
    assert _bed(1.0, 5.0, initial=0.0).fused is True
    assert _bed(0.5, 5.0, initial=0.0).fused is False  # still needs to melt through


def test_the_rule_matches_the_two_rules_it_replaces():
    """The pair's former test (growth = final / reference - 1 >= margin) exactly; a bed's former
    test (final >= (1 + margin) x initial) wherever the two roundings agree (they part only
    within a few ulps of the margin)."""
    rng = np.random.default_rng(52)
    reference = rng.uniform(1.0, 40.0, 2000)
    final = reference * rng.uniform(0.9, 1.2, 2000)
    melted = rng.choice([0.5, 0.98, 0.99, 1.0], 2000)
    for m, f, r in zip(melted, final, reference, strict=True):
        pair_before = bool(m >= THROUGH and neck_growth(f, r) >= MARGIN)
        bed_before = bool(m >= THROUGH and f >= (1.0 + MARGIN) * r)
        assert _pair(m, f, r).fused is pair_before
        assert bool(_bed(m, f, r).fused) is bed_before


def test_melted_fraction_and_rule_text():
    time_molten = np.array([0.0, 1e-5, 2e-5, 0.0, 3e-5])
    region = np.array([True, True, True, False, False])
    assert melted_fraction(time_molten, region) == pytest.approx(2.0 / 3.0)
    assert melted_fraction(time_molten, np.zeros(5, dtype=bool)) == 0.0
    melted, grown = rule_text(THROUGH, MARGIN, "unheated neck")
    assert melted == "neck region melted through (>= 0.99 of its points above T_m at some time)"
    assert grown == "final neck >= (1 + 0.05) x unheated neck"


def test_the_rule_loads_no_taichi():
    code = "import sys, taichi_sls.jobs.fusion_rule; print('taichi' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
