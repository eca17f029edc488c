"""A bed's contacts (jobs/bed_outcome.py): each contact's neck and melt followed frame by frame
(contacts.csv, and the bed's columns of the time series), the summary's ``bed`` record, its
verdict per contact (jobs/fusion_rule.py, the pair's rule) and the contacts and outcome plots at
the end."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ...io.bed_outcome_plot import plot_bed_outcome
from ...io.contacts_plot import plot_contacts
from ...io.contacts_table import write_contacts
from ...solver.simulation import Simulation
from ..bed_outcome import ContactHistory, bed_monitors, bed_summary, layer_density
from ..run_loop import Frame, Observer, RunEnd

CONTACTS = "contacts.csv"


class Contacts(Observer):
    """The bed's record; put first, so that its columns join each frame's monitors."""

    key = "contacts"

    def __init__(self, sim: Simulation, out_dir: Path) -> None:
        self.history = ContactHistory(sim)
        self.out_dir = out_dir
        self.rows: list[dict[str, float]] = []
        self.density: dict[str, float] | None = None  # the layer's at the last frame

    def frame(self, frame: Frame) -> None:
        self.history.add(frame.sim)
        self.rows = self.history.rows(frame.sim)
        write_contacts(self.out_dir / CONTACTS, self.rows)
        self.density = layer_density(frame.sim)
        frame.monitors.update(bed_monitors(frame.sim, self.rows, self.density))  # its series

    def finish(self, end: RunEnd) -> None:
        sim, case = end.sim, end.sim.case
        end.summary["outcome"] = {
            "fused": None,
            "no_verdict": f"{len(case.bodies)} bodies: the verdict is per contact (summary "
            "bed, contacts.csv)",
        }
        if case.domain.dim == 3:  # the 3D generator's own report
            end.summary["bed_generator"] = case.bed_report
        try:  # an interrupted run keeps its last frame's table and density: no new reading
            final = self.density if end.interrupted else None
            if not end.interrupted:
                self.rows = self.history.rows(sim)
                write_contacts(self.out_dir / CONTACTS, self.rows)
            initial = self.history.density_initial
            end.summary["bed"] = bed_summary(sim, self.rows, initial, final)
            if not end.interrupted:
                self._plots(sim, end.summary["bed"]["relative_density"])
        except Exception as e:  # noqa: BLE001 -- never cost the run's other outputs
            end.warnings.append(f"bed outcome not made ({type(e).__name__}: {e})")

    def _plots(self, sim: Simulation, density: dict[str, float]) -> None:
        case = sim.case
        arrays = sim.point_arrays(("x", "time_molten"))
        xy_um = arrays["x"][:, :2] * 1e6  # 3D: projected onto x-y (a view along z)
        plot_contacts(self.out_dir, self.rows, xy_um)
        plot_bed_outcome(
            self.out_dir,
            self.rows,
            xy_um,
            time_molten=arrays["time_molten"],
            density=(density["initial"], density["final"]),
            neck_growth=case.fusion.neck_growth,
            spacing_um=case.grid.spacing_um / case.grid.points_per_cell
            if case.domain.dim == 3
            else None,
        )

    def state(self) -> dict[str, Any]:
        return {**self.history.state(), "rows": self.rows, "density": self.density}

    def restore(self, state: dict[str, Any]) -> None:
        if state:
            self.history.restore_state(state)
            self.rows, self.density = state["rows"], state["density"]
