"""The progress bar of a run: simulated time against the horizon (end_s, or max_s for a run to
solidification), the phase of a process cycle (scan, then hold once every laser is off), steps
per second, the molten fraction, and an estimate of the time left."""

from __future__ import annotations

import math
import sys
import time


class Progress:
    """A tqdm bar in simulated microseconds; ``note`` takes each frame's monitors.

    The time left of a run to solidification is estimated from the cooling of the hottest point
    towards the wall temperature: over the last two frames after the peak, T_max - T_wall
    decays as exp(-t / tau); the run ends about when T_max reaches T_c (with thermal
    hysteresis, the bottom of the crystallisation range)."""

    def __init__(
        self,
        horizon_s: float,
        t0: float,
        enabled: bool = True,
        solidify: bool = False,
        T_c: float = math.nan,
        T_wall: float = math.nan,
        adaptive: bool = False,
        lasers_off_s: float = math.nan,
    ) -> None:
        self._bar = None
        # an adaptive step grows by orders of magnitude: the pace so far says nothing of the
        # time left, so the bar shows the step instead
        self.adaptive = adaptive
        self.horizon = horizon_s
        self.lasers_off_s = lasers_off_s  # nan: no laser heats, no phases to show
        self.solidify, self.T_c, self.T_wall = solidify, T_c, T_wall
        self._molten: float | None = None
        self._cooling: list[tuple[float, float]] = []  # (t, T_max) once T_max falls
        self._t0, self._wall0 = t0, time.perf_counter()
        if enabled:
            from tqdm import tqdm

            self._bar = tqdm(
                total=round(horizon_s * 1e6, 3),
                initial=round(t0 * 1e6, 3),
                unit="us",
                dynamic_ncols=True,
                file=sys.stderr,
                mininterval=0.5,
                bar_format="{l_bar}{bar}| {n:.0f}/{total:.0f} us [{elapsed}{postfix}]",
            )

    def update(self, t: float, steps_per_s: float, dt: float = math.nan) -> None:
        if self._bar is None:
            return
        self._bar.n = round(min(t, self.horizon) * 1e6, 3)
        text = f"{steps_per_s:,.0f} steps/s"
        if math.isfinite(self.lasers_off_s):  # the layer's phase: scanned, then held
            text = ("hold, " if t >= self.lasers_off_s else "scan, ") + text
        if self._molten is not None:
            text += f", molten {self._molten:.0%}"
        left = math.nan if self.adaptive else self.time_left(t)
        if self.adaptive:
            text += f", dt {dt:.2g} s"
        elif math.isfinite(left):
            text += f", ~{left:.0f} s left"
        self._bar.set_postfix_str(text, refresh=False)
        self._bar.refresh()

    def note(self, mon: dict[str, float]) -> None:
        """A frame's monitors: the molten fraction, and the cooling of the hottest point."""
        self._molten = mon["molten_fraction"]
        T = mon["T_max_C"]
        if self._cooling and T >= self._cooling[-1][1]:
            self._cooling = []  # still heating
        self._cooling.append((mon["t_s"], T))

    def end_estimate(self, t: float) -> float:
        """Simulated time at which the run should end."""
        if not self.solidify:
            return self.horizon
        if len(self._cooling) < 2:
            return self.horizon
        (t1, T1), (t2, T2) = self._cooling[-2:]
        e1, e2, ec = T1 - self.T_wall, T2 - self.T_wall, self.T_c - self.T_wall
        if not (e1 > e2 > 0 and ec > 0):
            return self.horizon
        if e2 <= ec:
            return t
        tau = (t2 - t1) / math.log(e1 / e2)
        return min(self.horizon, t2 + tau * math.log(e2 / ec))

    def time_left(self, t: float) -> float:
        """Wall seconds left at the pace so far (nan before any progress)."""
        done = t - self._t0
        if done <= 0:
            return math.nan
        pace = (time.perf_counter() - self._wall0) / done
        return pace * max(self.end_estimate(t) - t, 0.0)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
