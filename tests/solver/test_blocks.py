"""The blocks layout (solver/blocks.py): the serial layout's result to round-off, bitwise the
same at any thread count, and points sorted again when they drift out of their block."""

import numpy as np
import pytest
from helpers import PAPER_SCENE, advance_steps, deep_update, make_case

from taichi_sls.solver.simulation import Simulation


def _run(
    layout: str, threads: int = 0, steps: int = 120, extra: dict | None = None, shift: float = 0.0
):
    data = deep_update(PAPER_SCENE, {"grid": {"spacing_um": 4.0}, "lasers": [{"power_W": 25.0}]})
    data = deep_update(data, {"solver": {"layout": layout, "threads": threads}, **(extra or {})})
    sim = Simulation(make_case(data))
    advance_steps(sim, steps // 2)
    if shift:  # every point carried along x by ``shift`` metres, as if it had flowed there
        pt = sim.state.points
        pt.x.from_numpy(pt.x.to_numpy() + [shift, 0.0])
    advance_steps(sim, steps - steps // 2)
    pt = sim.state.points
    order = np.lexsort(pt.x0.to_numpy().T)  # the blocks layout sorts the points
    out = {k: getattr(pt, k).to_numpy()[order] for k in ("x", "v", "T", "stress")}
    out["body_id"] = sim.snapshot(full=True)["body_id"][order]  # the VTU's, after any sort
    # read now: the next Simulation re-initialises Taichi and frees these fields
    sorts = sim.blocks.sorts if sim.blocks is not None else 0
    return sim.monitors(), sorts, sim.blocks is not None and sim.blocks.n_blocks, out


def test_blocks_layout_matches_the_serial_one():
    """The same physics in another summation order: equal to round-off after 120 steps (a
    heat step, surface tension, the laser)."""
    m, _, _, a = _run("serial")
    mb, _, n_blocks, b = _run("blocks")
    assert n_blocks > 1
    for k in a:
        scale = np.abs(a[k]).max()
        np.testing.assert_allclose(b[k], a[k], rtol=0, atol=1e-9 * scale, err_msg=k)
    assert mb["laser_energy_J_per_m"] == pytest.approx(m["laser_energy_J_per_m"], rel=1e-12)
    assert mb["T_peak_C"] == pytest.approx(m["T_peak_C"], rel=1e-12)


@pytest.mark.slow  # two more blocks runs; the default suite keeps blocks = serial
def test_blocks_layout_does_not_depend_on_the_thread_count():
    """Every node takes its sums in one order whatever the threads: bitwise equal."""
    one = _run("blocks", threads=1)[3]
    two = _run("blocks", threads=2)[3]
    for k in one:
        assert np.array_equal(one[k], two[k]), k


@pytest.mark.slow  # ~90 s; the resumed-after-a-sort test below sorts the drifted points too
def test_points_are_sorted_again_when_they_drift():
    """Every point carried 5 cells along x half way through the run (further than a block's
    margin): the points are sorted again and the result still matches the serial layout."""
    wide = {"domain": {"width_um": 160.0, "height_um": 48.0}}
    a = _run("serial", extra=wide, shift=20e-6)[3]
    _, sorts, _, b = _run("blocks", extra=wide, shift=20e-6)
    assert sorts > 0
    np.testing.assert_allclose(b["x"], a["x"], rtol=0, atol=1e-9 * np.abs(a["x"]).max())
    # each point's body follows it through the sorts (the VTU's body_id)
    assert sorted(set(a["body_id"])) == [0, 1]
    np.testing.assert_array_equal(b["body_id"], a["body_id"])


def test_a_run_resumed_after_a_sort_continues_bitwise(tmp_path):
    """A checkpoint written after the points were sorted again resumes in that order: mass,
    volume and body of each point follow it (area seeding makes the edge points lighter, so a
    point given another's mass changes the answer)."""
    data = deep_update(PAPER_SCENE, {"grid": {"spacing_um": 4.0, "seeding": "area"}})
    data = deep_update(
        data,
        {
            "lasers": [{"power_W": 25.0}],
            "domain": {"width_um": 160.0, "height_um": 48.0},
            "solver": {"layout": "blocks"},
        },
    )
    case = make_case(data)
    sim = Simulation(case)
    advance_steps(sim, 30)
    pt = sim.state.points
    pt.x.from_numpy(pt.x.to_numpy() + [20e-6, 0.0])  # flowed 5 cells: sorted at the next step
    advance_steps(sim, 1)
    assert sim.blocks.sorts > 0
    path = tmp_path / "checkpoint.npz"
    sim.save_checkpoint(path)
    advance_steps(sim, 30)
    keys = ("x", "v", "T", "stress", "mass", "volume0")
    want = {k: getattr(sim.state.points, k).to_numpy() for k in keys}
    want["body_id"] = sim.snapshot(full=True)["body_id"]
    want_neck = [sim.monitors(guard=False)[k] for k in ("contact_line_um", "neck_span_um")]

    again = Simulation(case)
    again.load_checkpoint(path)
    advance_steps(again, 30)
    for k in keys:
        assert np.array_equal(getattr(again.state.points, k).to_numpy(), want[k]), k
    assert np.array_equal(again.snapshot(full=True)["body_id"], want["body_id"])
    assert [
        again.monitors(guard=False)[k] for k in ("contact_line_um", "neck_span_um")
    ] == want_neck


def test_a_point_beyond_the_grid_sorts_into_the_edge_block():
    """A point thrown above the grid (or left of it) counts in the edge block, so that sorting
    never fails; the guard names the point at the next check."""
    from taichi_sls.solver.blocks import SIDE, block_of

    h, off, n_bx, n_by = 4e-6, 2, 3, 4
    x = np.array([[1.0, 1.0], [-1.0, -1.0], [0.5 * SIDE * h, 0.5 * SIDE * h]])
    assert block_of(x, h, off, n_bx, n_by).tolist() == [n_bx * n_by - 1, 0, 0]
