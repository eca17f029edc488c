"""A bed run's layer file (``layer.npz``): its points at the end, the base of a next layer
(``bed.previous_layer``); written by a run that ended, not by one stopped or failed."""

from __future__ import annotations

from pathlib import Path

from ...config.layer_file import CARRIED_STATE, OPTIONAL_STATE
from ...io.layer_output import write_layer
from ...physics.materials import KELVIN
from ...solver.simulation import Simulation
from ..run_loop import Observer, RunEnd

LAYER_FILE = "layer.npz"


class LayerFile(Observer):
    """Writes ``layer.npz`` at the end of a complete or max_time run."""

    def __init__(self, out_dir: Path) -> None:
        self.out_dir = out_dir

    def finish(self, end: RunEnd) -> None:
        if end.status in ("failed", "interrupted") or end.interrupted:
            return
        try:
            write_layer_file(self.out_dir / LAYER_FILE, end.sim, end.status)
            end.summary["layer_file"] = LAYER_FILE
        except Exception as e:  # noqa: BLE001 -- never cost the run's other outputs
            end.warnings.append(f"layer file not written ({type(e).__name__}: {e})")


def write_layer_file(path: Path, sim: Simulation, status: str) -> None:
    """The points as they are now, for a case that deposits a layer on them (bed.previous_layer)."""
    carried = (*CARRIED_STATE, *OPTIONAL_STATE)
    pt, sc = sim.point_arrays(("x", "volume0", "J", "T", *carried)), sim.scene
    dim = sim.case.domain.dim
    write_layer(
        path,
        x_um=pt["x"] * 1e6,
        volume=pt["volume0"] * pt["J"] * 1e6**dim,
        body=sc.body,
        material=sc.material,
        material_names=sc.material_names,
        T_C=pt["T"] - KELVIN,
        info={"case": sim.case.case.name, "t_s": sim.t, "status": status},
        volume0=pt["volume0"] * 1e6**dim,
        state={k: pt[k] for k in carried},
    )
