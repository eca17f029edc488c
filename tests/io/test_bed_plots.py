"""A bed run's pictures (io/series.BED_PANELS, io/bed_outcome_plot.py, io/frames.py): the time
series plots the bed's own columns, the outcome draws the contacts map and the necks, frames of
a wide layer stack their panels and show the cold powder; a pair keeps its pictures. Synthetic
data only (no solver): the bed's series as a run writes them are checked in
tests/jobs/test_bed_outcome.py."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from matplotlib.colors import to_rgb

from taichi_sls.io.bed_outcome_plot import MELTED_COLOUR, NECK_HISTS, bed_outcome_figure
from taichi_sls.io.frames import STACK_ASPECT, Frame2DPainter
from taichi_sls.io.series import (
    BED_PANELS,
    BED_PANELS_PER_ROW,
    MONITORED,
    SERIES_LABELS,
    START_LABEL,
    SeriesWriter,
    series_figure,
)
from taichi_sls.io.writer import OutputWriter
from taichi_sls.jobs.bed_outcome import BED_SERIES

MELT_C = 178.0
BED_C = 140.0
BED_DOMAIN = (-8.0, 408.0, -8.0, 80.0)  # a layer: 416 x 88 um, wider than STACK_ASPECT
PAIR_DOMAIN = (0.0, 80.0, 0.0, 48.0)
DISCS = [(20.0 + 40.0 * i, 20.0 + 18.0 * (i % 2), 19.0) for i in range(10)]  # zig-zag row


def layer_points(h: float = 2.0) -> np.ndarray:
    """Points on an h lattice inside the discs of DISCS (um)."""
    g = np.arange(-30.0, 30.0 + h / 2, h)
    xx, yy = np.meshgrid(g, g)
    lattice = np.column_stack([xx.ravel(), yy.ravel()])
    return np.vstack([lattice[(lattice**2).sum(axis=1) <= r * r] + (cx, cy) for cx, cy, r in DISCS])


def bed_rows(n: int = 9) -> list[dict[str, float]]:
    """A contacts table between neighbouring discs: the first three fused, then melted
    through but not fused, then never melted."""
    rows = []
    for k in range(n):
        (xa, ya, _), (xb, yb, _) = DISCS[k], DISCS[k + 1]
        fused, through = int(k < 3), int(k < 6)
        rows.append(
            {
                "body_a": k,
                "body_b": k + 1,
                "x_um": 0.5 * (xa + xb),
                "y_um": 0.5 * (ya + yb),
                "neck_initial_um": 10.0 + 0.1 * k,
                "neck_melt_um": 11.0 + 0.2 * k if through else math.nan,
                "melt_end_s": 1e-4 if through else math.nan,
                "neck_final_um": 12.0 - 0.2 * k,
                "neck_region_melted_fraction": float(through),
                "melted_through": through,
                "refrozen": 1,
                "fused": fused,
            }
        )
    return rows


def write_bed_series(path: Path, frames: int = 12) -> dict[str, np.ndarray]:
    """A bed's time series on log-spaced times (as a run writes it); its columns."""
    t = np.concatenate([[0.0], np.logspace(-6, -2, frames - 1)])
    cols = {
        "t_s": t,
        "molten_fraction": np.clip(np.sin(np.linspace(0, 3, frames)), 0, None),
        "T_max_C": 140.0 + 200.0 * np.exp(-np.linspace(0, 4, frames)),
        "contact_line_um": 84.0 + np.sin(np.arange(frames)),  # the pair's measure: not plotted
        "relative_density": np.linspace(0.80, 0.86, frames),
        "mean_top_um": np.linspace(100.0, 95.0, frames),
        "neck_median_um": np.linspace(17.0, 18.5, frames),
        "contacts": np.full(frames, 101.0),
        "contacts_melted_through": np.minimum(np.arange(frames) * 5.0, 40.0),
        "contacts_molten": np.linspace(0.0, 30.0, frames),
        "contacts_fused": np.linspace(0.0, 20.0, frames),
        "fused_fraction": np.linspace(0.0, 20.0, frames) / 101.0,
    }
    w = SeriesWriter(path)
    for i in range(frames):
        w.row({k: float(v[i]) for k, v in cols.items()})
    return cols


def test_the_bed_series_figure_plots_the_beds_columns(tmp_path: Path) -> None:
    """One panel per bed quantity, each holding exactly its column against t (the log axis
    drops t = 0), the contacts in one panel with a legend, the beam's end marked; no panel of
    the pair's contact line."""
    cols = write_bed_series(tmp_path / "timeseries.csv")
    fig = series_figure(
        tmp_path / "timeseries.csv", BED_PANELS, BED_PANELS_PER_ROW, {"beam off": 2.5e-4}, True
    )
    assert fig is not None
    axes = [ax for ax in fig.axes if ax.get_visible()]
    labels = [ax.get_ylabel() for ax in axes]
    assert labels == [
        SERIES_LABELS["relative_density"],
        SERIES_LABELS["molten_fraction"],
        SERIES_LABELS["T_max_C"],
        SERIES_LABELS["neck_median_um"],
        "contacts",
        SERIES_LABELS["mean_top_um"],
    ]
    assert SERIES_LABELS["contact_line_um"] not in labels
    t_us, keep = cols["t_s"] * 1e6, cols["t_s"] > 0
    ax_column = {ax: p for ax, p in zip(axes, BED_PANELS, strict=True) if isinstance(p, str)}
    starts = [ax for ax in axes if START_LABEL in [ln.get_label() for ln in ax.get_lines()]]
    assert starts == list(ax_column)  # every one-column panel shows its start
    assert "beam off at 250 us" in fig.get_suptitle()
    plotted = {}
    for ax in axes:
        assert ax.get_xscale() == "log"
        for line in ax.get_lines():
            x = np.asarray(line.get_xdata(), dtype=float)
            if line.get_label() == "beam off":
                assert np.allclose(x, 250.0)
                continue
            if line.get_label() == START_LABEL:  # the t = 0 value the log axis cannot show
                assert np.allclose(line.get_ydata(), cols[ax_column[ax]][0])
                continue
            np.testing.assert_allclose(x, t_us[keep])
            plotted[line.get_label()] = np.asarray(line.get_ydata(), dtype=float)
    for name in (
        "relative_density",
        "molten_fraction",
        "T_max_C",
        "neck_median_um",
        "mean_top_um",
        "contacts",
        "contacts_melted_through",
        "contacts_molten",
        "contacts_fused",
    ):
        np.testing.assert_allclose(plotted[SERIES_LABELS[name]], cols[name][keep], err_msg=name)
    contacts_ax = axes[labels.index("contacts")]
    legend = [t.get_text() for t in contacts_ax.get_legend().get_texts()]
    assert legend == ["all", "melted through", "holding melt", "fused", "beam off"]


def test_the_bed_panels_cover_the_beds_series() -> None:
    """Every column the run adds for a bed (jobs/bed_outcome.BED_SERIES) but the fused share
    (the fused count's panel shows it against all contacts) is drawn."""
    drawn = set()
    for p in BED_PANELS:
        drawn |= {p} if isinstance(p, str) else set(p[1])
    assert set(BED_SERIES) - drawn == {"fused_fraction"}


def test_a_bed_writer_draws_the_bed_series_and_a_pair_writer_todays(tmp_path: Path) -> None:
    """timeseries.png of a bed: two rows of three panels; of a pair: contact line and peak
    temperature side by side (1 row of 2 panels of 4.2 x 3.2 in at 100 dpi), as before."""
    bed_painter = Frame2DPainter(BED_DOMAIN, MELT_C, "displacement", bed=True)
    bed = OutputWriter(tmp_path / "bed", painter=bed_painter, gif=False, bed=True)
    write_bed_series(bed.out_dir / "timeseries.csv")
    bed.series.resume()
    bed.finish({"beam off": 1e-4})
    pair_painter = Frame2DPainter(PAIR_DOMAIN, MELT_C, "displacement")
    pair = OutputWriter(tmp_path / "pair", painter=pair_painter, gif=False)
    write_bed_series(pair.out_dir / "timeseries.csv")
    pair.series.resume()
    pair.finish()
    assert iio.imread(bed.out_dir / "timeseries.png").shape[:2] == (640, 1260)
    assert iio.imread(pair.out_dir / "timeseries.png").shape[:2] == (320, 840)
    fig = series_figure(pair.out_dir / "timeseries.csv", list(MONITORED))
    assert [ax.get_ylabel() for ax in fig.axes] == [SERIES_LABELS[c] for c in MONITORED]


def _draw(domain: tuple[float, ...], bed: bool, x: np.ndarray, T: np.ndarray) -> Frame2DPainter:
    painter = Frame2DPainter(domain, MELT_C, "displacement", dpi=80, bed=bed)
    lf = np.clip((T - MELT_C) / 5.0, 0.0, 1.0)
    painter.draw(1e-5, x, {"T_C": T, "deform": np.zeros(len(x)), "liquid_fraction": lf})
    painter._fig.canvas.draw()
    return painter


def test_frames_of_a_wide_layer_stack_their_panels_and_show_the_cold_powder() -> None:
    """A layer wider than STACK_ASPECT: the temperature panel above the deformation one, each
    as wide as most of the frame, at the domain's aspect ratio and over a hundred pixels high;
    the powder at the bed temperature (the scale's foot) drawn clearly lighter than black."""
    x = layer_points()
    T = BED_C + 120.0 * np.exp(-(((x[:, 0] - 20.0) / 30.0) ** 2))  # the beam at the left end
    p = _draw(BED_DOMAIN, True, x, T)
    assert p.stacked
    fig = p._fig
    W, H = fig.bbox.width, fig.bbox.height  # drawn at the figure's dpi
    saved = 80.0 / fig.dpi  # pixels of the saved frame per drawn pixel
    top, bottom = (ax.get_window_extent() for ax in p._axes)
    assert top.y0 > bottom.y1 and abs(top.x0 - bottom.x0) < 1.0  # stacked, aligned
    aspect = (BED_DOMAIN[1] - BED_DOMAIN[0]) / (BED_DOMAIN[3] - BED_DOMAIN[2])
    for box in (top, bottom):
        assert box.width > 0.7 * W
        assert box.width / box.height == pytest.approx(aspect, rel=0.02)
        assert box.height * saved > 100.0
    assert H < W  # a frame, not a tall strip
    rgba = np.asarray(fig.canvas.buffer_rgba())[..., :3] / 255.0
    px, py = p._axes[0].transData.transform((340.0, 20.0))  # a cold disc, far from the beam
    cold = rgba[int(round(H - py)), int(round(px))]
    assert cold.max() > 0.3, cold  # inferno's foot is (0, 0, 0.02)


def test_a_pair_frame_keeps_its_side_by_side_panels_and_scale() -> None:
    """Two discs (aspect below STACK_ASPECT): the panels side by side, inferno from black."""
    assert (PAIR_DOMAIN[1] - PAIR_DOMAIN[0]) < STACK_ASPECT * (PAIR_DOMAIN[3] - PAIR_DOMAIN[2])
    x = layer_points()[:400] * 0.2
    p = _draw(PAIR_DOMAIN, False, x, np.full(len(x), BED_C))
    assert not p.stacked
    left, right = (ax.get_window_extent() for ax in p._axes)
    assert right.x0 > left.x1 and abs(left.y0 - right.y0) < 1.0
    assert p._images[0].get_cmap().name == "inferno"
    assert tuple(p._fig.get_size_inches()) == (2 * 4.2 + 1.4, 4.2 * 48 / 80 + 1.0)


def test_the_bed_outcome_draws_the_contacts_map_and_the_necks() -> None:
    """The map marks every contact where it is, by outcome; the histogram holds the three neck
    columns; the growth panel each contact's final over initial neck; no pair neck zoom."""
    rows, x = bed_rows(), layer_points()
    molten = np.where(x[:, 0] < 150.0, 1e-4, 0.0)
    fig = bed_outcome_figure(rows, x, time_molten=molten, density=(0.8, 0.85), neck_growth=0.05)
    ax_map, ax_hist, ax_growth = fig.axes
    assert "9 contacts, 3 fused" in ax_map.get_title() and "0.800 -> 0.850" in ax_map.get_title()
    assert "the neck" not in [ax.get_title() for ax in fig.axes]  # the pair's zoom
    marked = {
        line.get_label().split(" (")[0]: np.column_stack([line.get_xdata(), line.get_ydata()])
        for line in ax_map.get_lines()
    }
    assert set(marked) == {"fused", "melted through, not fused", "not melted through"}
    np.testing.assert_allclose(marked["fused"], [[r["x_um"], r["y_um"]] for r in rows[:3]])
    # the melted powder tinted: the map's image holds both colours
    image = ax_map.get_images()[0]
    shown = image.get_array()
    assert shown.min() == 0.0 and shown.max() == 1.0
    assert np.allclose(image.get_cmap()(1.0)[:3], to_rgb(MELTED_COLOUR))
    hist_labels = [t.get_text().split(" (")[0] for t in ax_hist.get_legend().get_texts()]
    assert hist_labels == [label for _, label, _ in NECK_HISTS]
    counts = [int(t.get_text().split("(")[1].rstrip(")")) for t in ax_hist.get_legend().get_texts()]
    assert counts == [9, 6, 9]  # the neck as melting ended: only the six that melted
    growth = np.concatenate([line.get_ydata() for line in ax_growth.get_lines()[:3]])
    expected = [100.0 * (r["neck_final_um"] / r["neck_initial_um"] - 1.0) for r in rows]
    np.testing.assert_allclose(np.sort(growth), np.sort(expected))


def test_the_growth_panel_leaves_out_a_contact_with_no_initial_neck() -> None:
    """A 3D contact whose initial section held no point (neck 0) has no growth: it is left off
    the growth panel (drawn as NaN, no division warning), the others drawn as before."""
    rows, x = bed_rows(), layer_points()
    rows[0] = {**rows[0], "neck_initial_um": 0.0}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = bed_outcome_figure(rows, x, neck_growth=0.05)
    ax_growth = fig.axes[2]
    growth = np.concatenate([line.get_ydata() for line in ax_growth.get_lines()[:3]])
    expected = [100.0 * (r["neck_final_um"] / r["neck_initial_um"] - 1.0) for r in rows[1:]]
    np.testing.assert_allclose(np.sort(growth[np.isfinite(growth)]), np.sort(expected))
    assert np.isnan(growth).sum() == 1
