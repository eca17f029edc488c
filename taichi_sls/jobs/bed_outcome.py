"""The outcome of a bed run (a case of more than two bodies): per contact, the neck at the start,
at the end of its melting and at the end, whether its neck region melted through and whether it
fused; for the layer, its relative density before and after and the melt track's depth and width
(jobs/bed_layer.py). The pair verdict of jobs/outcome.py reads bodies 0 and 1 only; a bed gets
this one instead (docs/record/beds.md).

Per contact (a, b) of ``Simulation.contacts``:

- the contact point: on the line of the start centres, where the radical line of the two
  bodies' equivalent circles crosses it (the tangency of two touching discs);
- the neck region: the points of a and b whose start positions lie within
  ``fusion.neck_region_cells`` cells of the line through the contact point across the line of
  centres (and within the smaller radius of that point along it): for the pair of equal discs
  this is the region of the pair verdict;
- the necks: ``Necks.pair_necks_m``, on the colour of the two bodies alone; at the start,
  at the last output frame in which the neck region held melt (a point with liquid fraction > 0:
  the neck as that contact's melting ends; NaN for a contact that never melted), and at the end;
- the verdict by the pair's rule (jobs/fusion_rule.py: ``contact_verdict``), the contact's own
  inputs named: melted through, ``fusion.melted_through`` of the region's points were fully
  molten at some time (time_molten > 0); solidified, refrozen (no melt left in the region at
  the end); fused, melted through, refrozen and the final neck at least
  (1 + ``fusion.neck_growth``) times the reference, the initial neck (a contact that did not
  touch at the start, initial neck 0, passes with any final neck: ``zero_reference_grows``);
  no verdict (no laser, not refrozen) counts as not fused. The baseline is the initial neck,
  not an unheated run: that run of a whole bed would double the cost, and the initial necks of a
  bed are the fillet's, which do not depend on h. The adhesive growth a soft solid makes without
  heat is therefore counted as growth; the same bed run without laser heat (absorptivity 0)
  measures it per contact.

In 3D (``domain.dim = 3``) the same record: the contact point on the line of the sphere centres
where the radical plane crosses it, the neck region the points within the slab of half-width
``fusion.neck_region_cells`` cells about that plane and within the smaller radius of the line of
centres, the necks read by the 3D section (solver/neck_section.py: the diameter 2 sqrt(A / pi) of
the narrowest c = 1/2 section normal to the line of centres), the relative density under the
layer's top surface over the bed area and the track's width across the scan
(jobs/bed_layer.py). The contacts and outcome plots draw the points and contacts projected onto
the x-y plane (a view along z).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ..config import Case
from ..solver.simulation import Simulation
from .bed_layer import layer_density, melt_extent
from .fusion_rule import contact_verdict, melted_fraction, rule_text
from .outcome import laser_acted

NECKS = ("neck_initial_um", "neck_melt_um", "neck_final_um")
ARRAYS = ("initial", "melt", "melt_s", "final", "molten_now")  # ContactHistory's, per contact


def is_bed(case: Case) -> bool:
    """A case whose outcome is read per contact: more than two bodies (2D or 3D)."""
    return len(case.bodies) > 2


def contact_geometry(sim: Simulation) -> tuple[np.ndarray, np.ndarray]:
    """(contact points, unit vectors a -> b) of every contact (m), from the start centres."""
    centre, radius = sim.necks.body_centres_m(initial=True), sim.necks.body_radii_m
    points, normals = [], []
    for a, b in sim.contacts:
        d_vec = centre[b] - centre[a]
        d = float(np.linalg.norm(d_vec))
        e = d_vec / d
        s = (d * d + radius[a] ** 2 - radius[b] ** 2) / (2.0 * d)  # radical line from a
        points.append(centre[a] + s * e)
        normals.append(e)
    dim = centre.shape[1]
    return np.reshape(points, (-1, dim)), np.reshape(normals, (-1, dim))


def neck_regions(sim: Simulation, points: np.ndarray, normals: np.ndarray) -> list[np.ndarray]:
    """Per contact, which points (in their current order) lie in its neck region."""
    x0 = sim.point_arrays(("x0",))["x0"]
    body = sim.scene.body
    half = sim.case.fusion.neck_region_cells * sim.state.cfg.h
    out = []
    for (a, b), p, e in zip(sim.contacts, points, normals, strict=True):
        rel = x0 - p
        along = np.abs(rel @ e)
        if len(e) == 2:
            across = np.abs(rel[:, 0] * e[1] - rel[:, 1] * e[0])
        else:  # the distance from the line of centres
            across = np.linalg.norm(rel - np.outer(rel @ e, e), axis=1)
        reach = min(sim.necks.body_radii_m[a], sim.necks.body_radii_m[b])
        out.append((along <= half) & (across <= reach) & ((body == a) | (body == b)))
    return out


class ContactHistory:
    """Follows every contact's neck and melt frame by frame (``add`` at each output frame)."""

    def __init__(self, sim: Simulation) -> None:
        self.contacts = list(sim.contacts)
        self.points, self.normals = contact_geometry(sim)
        n = len(self.contacts)
        self.initial = np.full(n, np.nan)
        self.melt = np.full(n, np.nan)
        self.melt_s = np.full(n, np.nan)
        self.final = np.full(n, np.nan)
        self.molten_now = np.zeros(n, dtype=bool)
        self.density_initial: dict[str, float] | None = None
        self.started = False
        self._regions: tuple[np.ndarray, list[np.ndarray]] | None = None  # (x0, regions)

    def regions(self, sim: Simulation) -> list[np.ndarray]:
        """:func:`neck_regions` of the contacts, read again only when the points' start
        positions in their current order change (the blocks layout sorts the points)."""
        x0 = sim.point_arrays(("x0",))["x0"]
        if self._regions is None or not np.array_equal(self._regions[0], x0):
            self._regions = (x0, neck_regions(sim, self.points, self.normals))
        return self._regions[1]

    def add(self, sim: Simulation) -> None:
        necks = np.array(sim.necks.pair_necks_m()) * 1e6
        liquid = 1.0 - sim.point_arrays(("solid_fraction",))["solid_fraction"]
        regions = self.regions(sim)
        self.molten_now = np.array([bool(np.any(liquid[r] > 0.0)) for r in regions], dtype=bool)
        if not self.started:
            self.initial = necks.copy()
            self.density_initial = layer_density(sim)
            self.started = True
        self.melt = np.where(self.molten_now, necks, self.melt)
        self.melt_s = np.where(self.molten_now, sim.t, self.melt_s)
        self.final = necks

    def state(self) -> dict[str, Any]:
        """What a checkpoint keeps (JSON lists; NaN as NaN)."""
        arrays = {k: getattr(self, k).tolist() for k in ARRAYS}
        return {**arrays, "density_initial": self.density_initial, "started": self.started}

    def restore_state(self, state: dict[str, Any]) -> None:
        """Continue a resumed run from :meth:`state` of its checkpoint."""
        for k in ARRAYS:
            setattr(self, k, np.array(state[k], dtype=bool if k == "molten_now" else float))
        self.density_initial, self.started = state["density_initial"], state["started"]

    def rows(self, sim: Simulation) -> list[dict[str, float]]:
        """The contacts table (contacts.csv), one row per contact, with the verdict."""
        f = sim.case.fusion
        tm = sim.point_arrays(("time_molten",))["time_molten"]
        regions = self.regions(sim)
        heated = laser_acted(sim.case)
        out = []
        for k, ((a, b), p) in enumerate(zip(self.contacts, self.points, strict=True)):
            melted = melted_fraction(tm, regions[k])
            refrozen = not self.molten_now[k]
            verdict = contact_verdict(
                melted,
                float(self.final[k]),
                float(self.initial[k]),  # a bed contact's reference: its initial neck
                solidified=refrozen,
                heated=heated,
                melted_through=f.melted_through,
                margin=f.neck_growth,
                zero_reference_grows=True,
            )
            out.append(
                {
                    "body_a": a,
                    "body_b": b,
                    "x_um": p[0] * 1e6,
                    "y_um": p[1] * 1e6,
                    **({"z_um": p[2] * 1e6} if len(p) == 3 else {}),
                    "neck_initial_um": self.initial[k],
                    "neck_melt_um": self.melt[k],
                    "melt_end_s": self.melt_s[k],
                    "neck_final_um": self.final[k],
                    "neck_region_melted_fraction": melted,
                    "melted_through": int(verdict.melted_through),
                    "refrozen": int(refrozen),
                    "fused": int(bool(verdict.fused)),  # no verdict counts as not fused
                }
            )
        return out


def track_across_axis(case: Case) -> int:
    """The axis the melt track's width is read along: x in 2D; in 3D the bed axis across the
    first laser's scan (z for a track along x, x for one along z)."""
    if case.domain.dim == 2 or not case.lasers:
        return 0
    return 2 if case.lasers[0].direction == "x" else 0


# the bed's columns of the time series (one value per output frame), in the order plotted
BED_SERIES = (
    "relative_density",
    "mean_top_um",
    "neck_median_um",
    "contacts",
    "contacts_melted_through",
    "contacts_molten",
    "contacts_fused",
    "fused_fraction",
)


def bed_monitors(
    sim: Simulation, rows: list[dict[str, float]], density: dict[str, float] | None = None
) -> dict[str, float]:
    """The bed's quantities at this output frame, from the measures of its outcome: the layer's
    relative density and mean top (layer_density), the median of the contacts' necks now, and
    how many contacts have melted through, hold melt now and are fused by the verdict's rule
    as it reads at this frame (a contact counts as fused once it has refrozen). ``density``:
    the layer's now, when already read."""
    d = density or layer_density(sim)
    n = len(rows)
    fused = sum(int(r["fused"]) for r in rows)
    necks = np.array([r["neck_final_um"] for r in rows], dtype=float)
    return {
        "relative_density": d["relative_density"],
        "mean_top_um": d["mean_top_m"] * 1e6,
        "neck_median_um": _quartiles(necks)["median"],
        "contacts": n,
        "contacts_melted_through": sum(int(r["melted_through"]) for r in rows),
        "contacts_molten": sum(1 - int(r["refrozen"]) for r in rows),
        "contacts_fused": fused,
        "fused_fraction": fused / n if n else math.nan,
    }


def _quartiles(v: np.ndarray) -> dict[str, float]:
    v = v[np.isfinite(v)]
    if len(v) == 0:
        return {"q25": math.nan, "median": math.nan, "q75": math.nan, "count": 0}
    q = np.percentile(v, [25, 50, 75])
    return {"q25": float(q[0]), "median": float(q[1]), "q75": float(q[2]), "count": int(len(v))}


def bed_summary(
    sim: Simulation,
    rows: list[dict[str, float]],
    density_initial: dict | None,
    density_final: dict | None = None,
) -> dict[str, Any]:
    """The summary's ``bed`` record: contacts, fused share, neck statistics, the layer's
    relative density before and after (with the generator's packing fractions) and the melt
    track (lengths in um). ``density_final``: the layer's at the end, when already read (an
    interrupted run's last frame)."""
    n = len(rows)
    col = {k: np.array([r[k] for r in rows], dtype=float) for k in (*NECKS, "fused")}
    after = density_final or layer_density(sim)
    pt = sim.point_arrays(("x0", "time_molten"))
    spacing = sim.state.cfg.h / sim.case.grid.points_per_cell
    top = sim.case.top_um() * 1e-6
    if sim.case.domain.dim == 2:
        melt = melt_extent(pt["x0"], pt["time_molten"], top, spacing)
    else:
        melt = melt_extent(pt["x0"], pt["time_molten"], top, spacing, track_across_axis(sim.case))
    rep = sim.case.bed_report or {}
    record = {
        "contacts": n,
        "fused": int(col["fused"].sum()),
        "fused_fraction": float(col["fused"].mean()) if n else math.nan,
        "melted_through": int(sum(r["melted_through"] for r in rows)),
        "still_molten": int(sum(1 - r["refrozen"] for r in rows)),
        "rule": "per contact: {}, refrozen, and {}".format(
            *rule_text(sim.case.fusion.melted_through, sim.case.fusion.neck_growth, "initial neck")
        ),
        **{k: _quartiles(col[k]) for k in NECKS},
        "relative_density": {
            "initial": (density_initial or {}).get("relative_density", math.nan),
            "final": after["relative_density"],
            "mean_top_initial_um": (density_initial or {}).get("mean_top_m", math.nan) * 1e6,
            "mean_top_final_um": after["mean_top_m"] * 1e6,
            "generator_envelope": rep.get("envelope", math.nan),
            "generator_bulk": rep.get("bulk", math.nan),
        },
        "layer_top_um": sim.case.top_um(),
        "melt_depth_um": melt["melt_depth_m"] * 1e6,
        "melt_bottom_um": melt["melt_bottom_m"] * 1e6,
        "track_width_um": melt["track_width_m"] * 1e6,
        "molten_points": melt["molten_points"],
    }
    laid = np.array([b.shape == "points" for b in sim.case.bodies])
    if laid.any():  # on a previous layer: the contacts the new discs made, apart
        a, b = (np.array([int(r[k]) for r in rows], dtype=int) for k in ("body_a", "body_b"))
        new, across = ~(laid[a] & laid[b]), laid[a] != laid[b]
        through = np.array([r["melted_through"] for r in rows], dtype=bool)
        record["new_layer"] = {
            "contacts": int(new.sum()),
            "fused": int(col["fused"][new].sum()),
            "fused_fraction": float(col["fused"][new].mean()) if new.any() else math.nan,
            "on_previous_layer": int(across.sum()),
            "on_previous_layer_melted_through": int(through[across].sum()),
            "on_previous_layer_fused": int(col["fused"][across].sum()),
            **{k: _quartiles(col[k][new]) for k in NECKS},
        }
    return record


def describe_bed(b: dict[str, Any]) -> str:
    """The bed record as lines for the run's printout."""

    def q(k: str) -> str:
        s = b[k]
        if not s["count"]:
            return "-"
        return f"{s['median']:.2f} um (quartiles {s['q25']:.2f}-{s['q75']:.2f})"

    def num(v: float | None, fmt: str) -> str:  # NaN comes back from the JSON as None
        return "-" if v is None or not math.isfinite(v) else format(v, fmt)

    def um(v: float | None) -> str:
        return "-" if v is None or not math.isfinite(v) else f"{v:.1f} um"

    d = b["relative_density"]
    return (
        f"bed: {b['contacts']} contacts, {b['fused']} fused ({num(b['fused_fraction'], '.0%')}), "
        f"{b['melted_through']} melted through, {b['still_molten']} still molten\n"
        f"  neck median: {q('neck_initial_um')} at the start, {q('neck_melt_um')} as melting "
        f"ended, {q('neck_final_um')} at the end\n"
        f"  relative density {num(d['initial'], '.3f')} -> {num(d['final'], '.3f')} (generator: "
        f"envelope {num(d['generator_envelope'], '.3f')}, bulk {num(d['generator_bulk'], '.3f')});"
        " mean top "
        f"{d['mean_top_initial_um']:.1f} -> {d['mean_top_final_um']:.1f} um\n"
        f"  melt track: depth {b['melt_depth_um']:.1f} um below the top at "
        f"{b['layer_top_um']:.1f} um (down to {um(b['melt_bottom_um'])} above the plate), "
        f"width {b['track_width_um']:.1f} um "
        f"({b['molten_points']} points ever fully molten)\n"
        + _describe_new_layer(b.get("new_layer"), num)
        + f"  rule: {b['rule']}"
    )


def _describe_new_layer(nl: dict[str, Any] | None, num: Callable[[Any, str], str]) -> str:
    """The line on the new layer's own contacts (a bed on a previous layer), else nothing."""
    if nl is None:
        return ""
    neck = nl["neck_final_um"]
    return (
        f"  new layer: {nl['contacts']} contacts, {nl['fused']} fused "
        f"({num(nl['fused_fraction'], '.0%')}), final neck median {num(neck['median'], '.2f')} "
        f"um; on the layer below: {nl['on_previous_layer']} contacts, "
        f"{nl['on_previous_layer_melted_through']} melted through, "
        f"{nl['on_previous_layer_fused']} fused\n"
    )
