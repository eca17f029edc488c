"""The guard: once per output frame, stop a run whose state is no longer physical, with one
message naming the quantity, the step, the time, the worst point and the likely cause."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..config.temperature_table import read_temperature_table
from ..physics.materials import KELVIN
from .fields import NEVER, WATCHED, State
from .monitor import Trouble, grid_reach
from .step_config import T_RUNAWAY_K


def temperature_floor_K(case: Any, dim: int, coldest_start_C: float) -> float:
    """The coldest temperature a point may reach (K): its start's, a fixed wall's or the
    chamber's that the top surface loses heat to (conduction obeys a maximum principle, and the
    chamber draws the surface only towards its own temperature) or the held temperature's
    coldest (thermal.imposed_temperature_csv); -inf where heat is off."""
    if not case.physics.thermal:
        return -math.inf
    walls = [w.temperature_C for w in case.boundary.walls(dim) if w.thermal == "fixed"]
    if case.thermal.top_surface == "chamber":
        walls.append(case.thermal.chamber_temperature_C())
    if case.thermal.imposed_temperature_csv is not None:  # the held temperature's coldest
        walls.append(float(read_temperature_table(case.thermal.imposed_temperature_csv)[1].min()))
    return min([coldest_start_C, *walls]) + KELVIN


class SimulationError(RuntimeError):
    """The guard tripped: the state is no longer physical. The message says what and where."""


class Guard:
    """Checks, in the order a failing run usually breaks them; the first one that fails names
    the problem. ``T_floor_K``: the coldest start, fixed wall or chamber (conduction obeys a maximum
    principle); ``energy_tol``: the energy balance's round-off bound for the precision."""

    # a Jacobian beyond this is no longer a small-strain continuum, a point moving more than this
    # fraction of a cell per step has outrun the grid (the motion limit)
    J_ABSURD = 20.0
    MOTION_CELLS = 0.5
    T_ABSURD_K = T_RUNAWAY_K

    def __init__(
        self, state: State, dt: float, limits: dict[str, float], T_floor_K: float, energy_tol: float
    ) -> None:
        self.state = state
        self.dt = dt
        self.limits = limits
        self.T_floor_K = T_floor_K
        self.energy_tol = energy_tol
        # a fixed dt beyond a stability limit (time.allow_unstable_dt) is then the first suspect
        self.over_limit = bool(limits) and dt > min(limits.values())

    def _where(self, values: np.ndarray) -> str:
        """Location of the point where ``values`` is worst (NaN first)."""
        bad = np.where(np.isfinite(values), values, np.inf)
        i = int(np.argmax(bad))
        x = self.state.points.x.to_numpy()[i] * 1e6
        body = int(self.state.scene.body[i])
        z = f", z = {x[2]:.6g}" if len(x) == 3 else ""
        return f"point {i} (body {body}) at x = {x[0]:.6g}, y = {x[1]:.6g}{z} um"

    def check(
        self,
        mon: dict[str, float],
        internal: dict,
        steps: int,
        t: float,
        energy_error: float,
        energy_bound: float,
    ) -> None:
        """Raise SimulationError if the state is broken."""
        st, pt = self.state, self.state.points
        when = f"at step {steps}, t = {t:.6g} s"
        hint = f"time step {self.dt:.3g} s against the limits " + ", ".join(
            f"{k} {v:.3g} s" for k, v in self.limits.items()
        )
        if st.cfg.implicit:  # no stability limit: the step is too long for the flow it resolves
            hint = f"implicit time step {self.dt:.3g} s: try a smaller time.dt_s"
        problem = None
        kind = ""  # which of WATCHED the detected problem is, if any
        finite = all(math.isfinite(v) for k, v in mon.items() if not k.endswith("_um"))
        if internal["trouble"] == Trouble.NAN or not finite:
            x = pt.x.to_numpy()
            bad = ~np.isfinite(x.sum(axis=1) + pt.T.to_numpy() + pt.J.to_numpy())
            problem = (
                f"NaN or infinity in the point state, first at {self._where(bad * 1.0)}",
                hint,
            )
        elif internal["trouble"] == Trouble.LEFT_GRID:
            # how far each point lies beyond the grid's reach
            lo, hi = grid_reach(st.cfg)
            x = pt.x.to_numpy()
            r = np.maximum(lo - x, x - np.array(hi)).max(axis=1)
            problem = (f"a point left the grid: {self._where(r)}", hint)
        elif mon["J_min"] <= 0.0:
            problem = (
                f"Jacobian J = {mon['J_min']:.3g} <= 0 (inverted point) at "
                f"{self._where(-pt.J.to_numpy())}",
                f"strains of order one (a material too soft for the surface tension or load: "
                f"the small-strain model breaks down), or the {hint}",
            )
            kind = "inverted"
        elif internal["J_max"] > self.J_ABSURD:
            problem = (
                f"Jacobian J = {internal['J_max']:.3g} > {self.J_ABSURD} (a point swelled "
                f"absurdly) at {self._where(pt.J.to_numpy())}",
                hint,
            )
        elif internal["v_max"] * self.dt > self.MOTION_CELLS * st.cfg.h:
            problem = (
                f"a point moves {internal['v_max'] * self.dt / st.cfg.h:.2f} cells per step "
                f"(|v| = {internal['v_max']:.3g} m/s) at "
                f"{self._where(np.linalg.norm(pt.v.to_numpy(), axis=1))}",
                f"the motion limit; {hint}",
            )
        elif (
            internal["T_min_K"] < self.T_floor_K - 1.0 or mon["T_max_C"] + KELVIN > self.T_ABSURD_K
        ):
            T = pt.T.to_numpy()
            worst = np.maximum(self.T_floor_K - T, T - self.T_ABSURD_K)
            problem = (
                f"temperature {T[np.argmax(worst)] - KELVIN:.1f} C outside the physical range "
                f"[{self.T_floor_K - KELVIN:.1f} C (coldest start, wall or chamber), "
                f"{self.T_ABSURD_K - KELVIN:.0f} C] at {self._where(worst)}",
                f"the thermal limit; {hint}",
            )
            kind = "hot" if T.max() > self.T_ABSURD_K else ""
        elif abs(energy_error) > self.energy_tol:
            problem = (
                f"energy balance broken: laser - heat out - enthalpy rise = "
                f"{energy_error:.3g} of the energy scale",
                f"the thermal limit; {hint}",
            )
        elif mon["kinetic_energy_J_per_m"] > 10.0 * energy_bound:
            problem = (
                f"kinetic energy {mon['kinetic_energy_J_per_m']:.3g} J/m exceeds ten times every "
                f"source of energy ({energy_bound:.3g} J/m)",
                hint,
            )
        if problem is not None:
            what, cause = problem
            first = self.first_broken()
            if first is not None and first[0] != kind:
                # the frame shows the end of a chain: name its first link and that link's cause
                k, step = first
                what += f"; first at step {step} (t = {step * self.dt:.3g} s): {self._first(k)}"
                cause = self._cause(k, hint)
            if self.over_limit and kind != "hot":
                cause = hint
            raise SimulationError(f"{what} {when}; likely cause: {cause}")

    def first_broken(self) -> tuple[str, int] | None:
        """(which of WATCHED, step) that the step saw first, or None."""
        sc = self.state.scalars
        seen = {k: int(getattr(sc, f"first_{k}")[None]) for k in WATCHED}
        seen = {k: v for k, v in seen.items() if v != NEVER}
        return min(seen.items(), key=lambda kv: kv[1]) if seen else None

    def _first(self, kind: str) -> str:
        peak = float(self.state.scalars.T_peak[None]) - KELVIN
        return {
            "hot": f"a temperature passed {self.T_ABSURD_K - KELVIN:.0f} C (peak {peak:.3g} C)",
            "inverted": "a point inverted (J <= 0)",
            "nan": "a point's state became NaN",
        }[kind]

    def _cause(self, kind: str, hint: str) -> str:
        if self.over_limit and kind != "hot":
            return hint
        if kind == "hot":
            return (
                "more heat than the melt can take: the laser's power_W, absorptivity or "
                "spot_radius_um (the explicit conduction itself is stable at this step)"
            )
        if kind == "inverted":
            return (
                "strains of order one (a material too soft for the surface tension or load: "
                f"the small-strain model breaks down), or the {hint}"
            )
        return hint
