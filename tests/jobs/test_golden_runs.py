"""Every answer unchanged through a redesign (issue #52): a fixed set of short runs of bundled
cases, 2D and 3D, pairs and beds, explicit, implicit and hybrid, settled and not, must reproduce
the summary, time series and contact table committed from the code before the redesign
(``tests/data/golden/*.json``).

Explicit runs compare bit for bit: strict floating point and one thread, as in
test_reference_2d.py (fast math and the order of atomic sums move last bits from one machine or
run to another). Runs with implicit steps compare to a relative 1e-6: the Newton and Krylov
solves stop at tolerances of 1e-8 and tighter, so a change that keeps every formula but not the
order of a reduction moves their answers far below that, and a change of physics far above it.

Regenerate only for a change meant to alter results, and say so in its commit:
``PYTHONPATH=. python tests/jobs/test_golden_runs.py --write [NAME ...]``."""

from __future__ import annotations

import csv
import json
import math
import sys
from pathlib import Path

import pytest

GOLDEN = Path(__file__).resolve().parents[1] / "data" / "golden"
COMMON = [
    "output.png=false",
    "output.gif=false",
    "output.vtu=false",
    "solver.optimize=false",  # fast compile
    "solver.fast_math=false",  # the same bits on any CPU
    "solver.threads=1",  # atomic sums in a fixed order
]
# name: (bundled case, overrides, exact)
RUNS: dict[str, tuple[str, list[str], bool]] = {
    "pair2d_explicit": ("power25W_coarse", ["time.end_s=2e-5"], True),
    "pair2d_settled_hybrid": (
        "power25W_resolved",
        ["grid.spacing_um=4", "time.stop=end", "time.end_s=2e-5"],
        False,
    ),
    "pair2d_implicit": ("sinter_hold", ["grid.spacing_um=4", "time.end_s=2e-4"], False),
    "bed2d_hybrid": ("bed_track", ["time.stop=end", "time.end_s=1e-5"], True),
    "bed2d_implicit_settled": ("machine_layer", ["time.end_s=2e-4"], False),
    "pair3d_settled_hybrid": ("pair3d_25W", ["time.stop=end", "time.end_s=4e-6"], False),
    "bed3d_explicit": ("bed3d_cooling", ["time.end_s=2e-6"], True),
}
# Intended changes of issue #52, applied to the records rather than rewriting them:
# - a 3D run's summary names its energies in J (its time series already did): the keys of
#   ``initial`` and ``final`` ending in _J_per_m end in _J;
# - a bed's verdict is per contact (summary ``bed``, contacts.csv): its ``outcome`` keeps only
#   ``fused`` (null) and ``no_verdict``; the pair numbers of bodies 0 and 1, computed to be
#   overwritten, are gone.
BED_OUTCOME_KEPT = ("fused", "no_verdict")
# Intended change of issue #53: a run with implicit steps records its linear solves in the
# summary (``linear_solves``), a block the records before it lack; checked here for its keys
# (``direct_solver``: the factorization's library, time.direct_solver, added with it;
# ``analyses``: the factorizations of a new pattern, with time.direct_pattern)
LINEAR_SOLVES_KEYS = {
    "solver",
    "direct_solver",
    "newton_iterations",
    "solves",
    "factorizations",
    "analyses",
    "cg_iterations",
    "last_residual",
}
# Intended change of issue #54 (item 5): the sections across the centres read the points' kernel
# colour (contact.neck_colour = "kernel", the new default) where these two runs read the force's
# filtered colour. Only their neck fields move (the settle stops at the same step; every other
# value is equal): the first contact's neck at each frame (the series' contact_line_um and
# neck_span_um, equal) is KERNEL_NECK_UM's, -8.6 to -9.9 % (pair2d, h = 4 um) and -6.2 to
# -7.1 % (pair3d, R/h = 5) from the record; the summary's necks follow from it: initial,
# settle and outcome's initial are the first frame's, final and outcome's final the last's,
# outcome's neck_growth their ratio less 1 (pair2d -0.0162 -> -0.0248, pair3d -0.0012 ->
# -0.0105). bed3d_cooling keeps the filtered colour by its own key (cases/bed3d_cooling.toml).
KERNEL_NECK_UM = {
    "pair2d_settled_hybrid": [
        20.53398889,
        20.49632065,
        20.47225458,
        20.43123129,
        20.37645077,
        20.31242281,
        20.25009664,
        20.19053341,
        20.14025113,
        20.07756665,
        19.95052392,
        19.91088456,
        19.94472502,
        19.98236047,
        20.0250306,
        20.0254075,
    ],
    "pair3d_settled_hybrid": [
        19.72169727,
        19.68545615,
        19.66486365,
        19.64060473,
        19.61902823,
        19.6055049,
        19.58656936,
        19.51730024,
        19.51556107,
    ],
}


def _kernel_necks(want: dict, necks: list[float]) -> None:
    """The record's neck fields read on the kernel colour: ``necks`` (um) at each frame."""
    s = want["summary"]
    for row, neck in zip(want["series"], necks, strict=True):
        row["contact_line_um"] = row["neck_span_um"] = repr(float(neck))
    first, last = float(necks[0]), float(necks[-1])
    s["settle"]["neck_um"] = s["outcome"]["neck_initial_um"] = first
    s["initial"]["contact_line_um"] = s["initial"]["neck_span_um"] = first
    s["final"]["contact_line_um"] = s["final"]["neck_span_um"] = last
    s["outcome"]["neck_final_um"] = last
    s["outcome"]["neck_growth"] = last / first - 1.0


def _intended(want: dict, name: str) -> dict:
    """The record of run ``name`` with the intended changes above."""
    if name in KERNEL_NECK_UM:
        _kernel_necks(want, KERNEL_NECK_UM[name])
    s = want["summary"]
    if "bed" in s:
        s["outcome"] = {k: v for k, v in s["outcome"].items() if k in BED_OUTCOME_KEPT}
    if "enthalpy_J" in want["series"][0]:  # a 3D run: its series named the energies so
        for block in ("initial", "final"):
            s[block] = {
                k.removesuffix("_J_per_m") + "_J" if k.endswith("_J_per_m") else k: v
                for k, v in s[block].items()
            }
    return want


# timing and compile counts vary from run to run
_VOLATILE = ("wall", "compile", "steps_per_s", "kernels_compiled")


def _clean(obj):
    """Volatile keys dropped, recursively."""
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items() if not any(w in k for w in _VOLATILE)}
    if isinstance(obj, list):
        return [_clean(v) for v in obj]
    return obj


def _table(path: Path) -> list[dict[str, str]]:
    if not path.is_file():
        return []
    with path.open() as f:
        return list(csv.DictReader(f))


def run(name: str, out: Path) -> dict:
    import taichi_sls as sls

    case_name, overrides, _ = RUNS[name]
    summary = sls.run_case(sls.load_case(case_name, COMMON + overrides), out, progress=False)
    result = {
        "summary": _clean(summary),
        "series": _table(out / "timeseries.csv"),
        "contacts": _table(out / "contacts.csv"),
    }
    # json writes floats by repr (exact round trip) and NaN as NaN: equal text, equal bits
    return json.loads(json.dumps(result, sort_keys=True))


def _number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return None


def _differences(want, got, path: str = "", rel: float = 0.0) -> list[str]:
    """Where got differs from want: exactly, or beyond ``rel`` for numbers."""
    if isinstance(want, dict) and isinstance(got, dict):
        out = [f"{path}/{k}: missing" for k in want if k not in got]
        out += [f"{path}/{k}: new" for k in got if k not in want]
        for k in want.keys() & got.keys():
            out += _differences(want[k], got[k], f"{path}/{k}", rel)
        return out
    if isinstance(want, list) and isinstance(got, list):
        if len(want) != len(got):
            return [f"{path}: {len(got)} items, want {len(want)}"]
        return [
            d
            for i, (a, b) in enumerate(zip(want, got, strict=True))
            for d in _differences(a, b, f"{path}[{i}]", rel)
        ]
    a, b = _number(want), _number(got)
    if a is not None and b is not None and not isinstance(want, bool):
        if math.isnan(a) and math.isnan(b):
            return []  # NaN (no such neck, say) in both
        if rel > 0.0 and math.isclose(a, b, rel_tol=rel, abs_tol=rel * 1e-6):
            return []
    return [] if want == got else [f"{path}: {got!r}, want {want!r}"]


# on request (-m slow): the three that settle first, the longest (~15-60 s each); 2D and 3D,
# pair and bed, explicit, implicit and hybrid steps stay in default through the other four
SLOW = {"pair3d_settled_hybrid", "bed2d_implicit_settled", "pair2d_settled_hybrid"}


@pytest.mark.parametrize(
    "name", [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n for n in sorted(RUNS)]
)
def test_short_run_matches_the_golden_record(name, tmp_path):
    want = _intended(json.loads((GOLDEN / f"{name}.json").read_text()), name)
    got = run(name, tmp_path / name)
    solves = got["summary"].pop("linear_solves", None)
    if "explicit" in name:
        assert solves is None, solves
    else:
        assert set(solves) == LINEAR_SOLVES_KEYS, solves
    diffs = _differences(want, got, rel=0.0 if RUNS[name][2] else 1e-6)
    assert not diffs, f"{name} differs from its golden record:\n" + "\n".join(diffs[:40])


if __name__ == "__main__" and sys.argv[1:2] == ["--write"]:
    import tempfile

    for name in sys.argv[2:] or sorted(RUNS):
        with tempfile.TemporaryDirectory() as d:
            result = run(name, Path(d) / name)
        (GOLDEN / f"{name}.json").write_text(json.dumps(result, sort_keys=True, indent=1) + "\n")
        print("wrote", name, flush=True)
