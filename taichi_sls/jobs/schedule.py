"""When a run writes its frames and checks whether to stop: linear over ``time.end_s`` or
log-spaced from ``output.first_frame_s`` (the fusion outcome spans microseconds to tenths of a
second), and the stop rule of ``time.stop``.

A laser case that does not set ``output.frames`` is log-spaced even to a fixed ``end_s``: the
pair is molten within 20 us and its neck set within 0.1 ms, so 20 linear frames over 1 ms would
put the whole transient between the first two frames and rows."""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence

from ..config import Case
from .outcome import laser_acted

DEFAULT_LINEAR_FRAMES = 20  # linear spacing when output.frames is not set


def uses_log_spacing(case: Case) -> bool:
    """``output.spacing``; auto: log for a run to solidification, or for a case a laser heats
    unless it asks for a number of linear frames."""
    o = case.output
    if o.spacing == "auto":
        return case.time.stop == "solidified" or (o.frames is None and laser_acted(case))
    return o.spacing == "log"


def frame_steps(case: Case, dt: float) -> Iterator[int]:
    """The step count of each frame after the first (frame 0 is the start), increasing.

    Linear: ``output.frames`` frames of whole, equal step counts that reach ``time.end_s``.
    Log: ``frames_per_decade`` per decade from ``first_frame_s`` (1 ms is on that grid when
    first_frame_s is a power of ten), up to ``time.end_s`` for stop = "end", or ``time.max_s``
    for stop = "solidified" (the run may stop before)."""
    t = case.time
    if not uses_log_spacing(case):
        frames = case.output.frames or DEFAULT_LINEAR_FRAMES
        per = max(1, math.ceil(t.end_s / frames / dt - 1e-9))
        yield from (per * k for k in range(1, frames + 1))
        return
    end = t.max_s if t.stop == "solidified" else t.end_s
    o = case.output
    last = 0
    k = 0
    while True:
        tk = min(o.first_frame_s * 10.0 ** (k / o.frames_per_decade), end)
        step = max(last + 1, round(tk / dt))
        yield step
        last = step
        if tk >= end:
            return
        k += 1


def frame_times(case: Case, dt: float) -> list[float]:
    """The time of each frame after the first (s): the steps of :func:`frame_steps` times the
    run's first dt (an adaptive run lands on these times; a fixed one takes these steps)."""
    return [step * dt for step in frame_steps(case, dt)]


SETTLED_FRAMES = 3  # frames before the last that an unheated case's neck must agree with


def settled(
    mon: dict[str, float], case: Case, t: float, before: Sequence[dict[str, float]] = ()
) -> bool:
    """The stop rule of ``time.stop = "solidified"``: every laser is off, every point solid and
    the kinetic energy (with the inertia scale) below ``settled_kinetic_fraction`` of the
    surface energy. A case no laser heats is solid from the start, and the kinetic energy of
    its first adhesive contact swings through that fraction while the neck still moves by
    percents (two frames may even catch the swing at one neck), so there the kinetic energy must
    have stayed below it, and the first contact's neck within ``settled_neck_change`` of the
    last, over the ``SETTLED_FRAMES`` frames ``before`` the last (a doubling of the time at ten
    frames a decade)."""

    def quiet(m: dict[str, float]) -> bool:
        return (
            t >= case.lasers_off_s()
            and m["molten_fraction"] == 0.0
            and m["T_max_C"] <= min(mat.crystallization_C for mat in case.materials.values())
            and m.get("kinetic_ratio", 0.0) < case.time.settled_kinetic_fraction
        )

    now = quiet(mon)
    if not now or laser_acted(case):
        return now
    recent = list(before)[-SETTLED_FRAMES:]
    if len(recent) < SETTLED_FRAMES or not all(quiet(m) for m in recent):
        return False
    neck = mon.get("contact_line_um", math.nan)
    if not math.isfinite(neck):
        return True  # no contact to follow: the kinetic energy decides
    tol = case.time.settled_neck_change * neck
    return all(abs(m.get("contact_line_um", math.nan) - neck) <= tol for m in recent)
