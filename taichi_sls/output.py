"""Run outputs: case copy, frame images, VTU points, time series CSV/plot, summary, GIF.

Every file is written atomically (temp file in the same folder + ``os.replace``) so a run that is
interrupted -- Ctrl-C, wall-clock limit, crash -- leaves each output either old or complete,
never truncated. Plotting is headless (Agg) and reuses one figure across frames so memory stays
flat over hundreds of frames.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import secrets
from collections.abc import Iterator
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import matplotlib

matplotlib.use("Agg")  # headless: the solver runs on machines without a display

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

GIF_MAX_BYTES = 2_000_000
GIF_FRAME_S = 0.15
_GIF_BUDGET = int(0.9 * GIF_MAX_BYTES)  # encoder output varies a little with the frame subset
_GIF_MIN_FRAMES = 20  # below this, downscale instead of dropping more frames
_MELT_LEVEL = 0.5  # liquid fraction drawn as the melt outline
_MAX_CONTOUR_CELLS = 400  # per axis; bounds the melt-outline grid if points fly far apart

_DEFORM_LABELS = {
    "displacement": ("|u| [um]", "displacement"),
    "plastic_strain": ("equivalent plastic strain", "plastic strain"),
}
_SERIES_LABELS = {
    "contact_line_um": "contact line [um]",
    "T_max_C": "peak temperature [C]",
}
_MONITORED = ("contact_line_um", "T_max_C")


# --------------------------------------------------------------------------- atomic writes


@contextlib.contextmanager
def _atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temp path next to ``path``; on success move it over ``path``, else delete it."""
    final = Path(path)
    final.parent.mkdir(parents=True, exist_ok=True)
    # Same folder so os.replace is a rename on one filesystem (atomic); dot-prefixed so globs
    # for outputs never pick it up; pid + random token so concurrent writers never collide.
    tmp = final.parent / f".{final.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp"
    try:
        yield tmp
        os.replace(tmp, final)
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` so readers see either the old file or the complete new one."""
    with _atomic_path(path) as tmp:
        # os.open with mode 0o666 honours the umask (tempfile would force 0600 on outputs).
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        with os.fdopen(fd, "wb") as f:
            f.write(data)


def atomic_write_text(path: str | os.PathLike[str], text: str) -> None:
    """UTF-8 text version of :func:`atomic_write_bytes`."""
    atomic_write_bytes(path, text.encode("utf-8"))


# --------------------------------------------------------------------------- helpers


def _fmt_cell(v: Any) -> str:
    """CSV cell: ints exact, floats round-trip exact (repr), NaN/inf as nan/inf, None empty."""
    if v is None:
        return ""
    if isinstance(v, (bool, np.bool_)):
        return str(int(v))
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    return str(v)


def _jsonable(obj: Any) -> Any:
    """Convert numpy types, paths and non-finite floats into strict-JSON-friendly values."""
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, set, frozenset)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return _jsonable(obj.item())
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if obj is None or isinstance(obj, (str, int, bool)):
        return obj
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    return str(obj)


def _point_spacing(x: np.ndarray, fallback: float) -> float:
    """Typical particle spacing sqrt(area per point), from a sample of local point densities.

    Counting neighbours within a few nearest-neighbour distances (rather than using the
    nearest-neighbour distance itself) also covers anisotropic or jittered arrangements.
    """
    n = len(x)
    if n < 2:
        return fallback
    rng = np.random.default_rng(0)  # fixed seed: marker size must not flicker between frames
    sample = x if n <= 64 else x[rng.choice(n, 64, replace=False)]

    def dist2() -> Iterator[np.ndarray]:  # in chunks so memory stays O(16 N), not O(64 N)
        for i in range(0, len(sample), 16):
            yield ((sample[i : i + 16, None, :] - x[None]) ** 2).sum(axis=-1)

    # zero distance = self or an exact duplicate
    nn2 = np.concatenate([np.where(d2 > 0.0, d2, np.inf).min(axis=1) for d2 in dist2()])
    nn2 = nn2[np.isfinite(nn2)]
    if nn2.size == 0:
        return fallback
    r2 = 9.0 * float(np.median(nn2))
    counts = np.concatenate([(d2 <= r2).sum(axis=1) for d2 in dist2()])
    # Upper quantile of counts: points near a free surface see only half a neighbourhood.
    count = float(np.quantile(counts, 0.75))
    h = math.sqrt(math.pi * r2 / count)
    return h if h > 0.0 else fallback


def _finite_range(
    v: np.ndarray, lo: float | None = None, hi: float | None = None
) -> tuple[float, float]:
    """Colour limits spanning the finite values and the anchors; never degenerate."""
    f = v[np.isfinite(v)]
    vals = [float(f.min()), float(f.max())] if f.size else []
    vals += [a for a in (lo, hi) if a is not None]
    if not vals:
        return 0.0, 1.0
    vmin, vmax = min(vals), max(vals)
    if not vmax > vmin:  # uniform field: Normalize would divide by zero
        vmin, vmax = vmin - (0.0 if lo is not None else 1.0), vmax + 1.0
    return vmin, vmax


def _melt_grid(
    x: np.ndarray, lf: np.ndarray, h: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Bin liquid fraction on a grid of cell ``h``; empty cells count as solid (0).

    Contouring this grid at 0.5 is robust for any point set (no triangulation that could fail
    on collinear/duplicate points or bridge gaps between particles), and cheap (bincount).
    Returns (xc, yc, values) or None when there is no liquid/solid boundary to draw.
    """
    ok = np.isfinite(x).all(axis=1)
    x, lf = x[ok], np.nan_to_num(lf[ok], nan=0.0)
    if len(x) == 0 or not (lf > _MELT_LEVEL).any():
        return None
    lo, hi = x.min(axis=0), x.max(axis=0)
    h = max(h, float((hi - lo).max()) / _MAX_CONTOUR_CELLS, 1e-12)
    lo = lo - 1.5 * h  # one empty ring all round closes the outline at free surfaces
    nx, ny = (np.floor((hi - lo) / h).astype(int) + 3).tolist()
    ij = np.floor((x - lo) / h).astype(int)
    flat = ij[:, 1] * nx + ij[:, 0]
    s = np.bincount(flat, weights=lf, minlength=nx * ny)
    c = np.bincount(flat, minlength=nx * ny)
    vals = np.divide(s, c, out=np.zeros_like(s), where=c > 0).reshape(ny, nx)
    if not (vals < _MELT_LEVEL).any():
        return None
    xc = lo[0] + (np.arange(nx) + 0.5) * h
    yc = lo[1] + (np.arange(ny) + 0.5) * h
    return xc, yc, vals


def _save_png(fig: Figure, path: Path, dpi: int) -> None:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    atomic_write_bytes(path, buf.getvalue())


# --------------------------------------------------------------------------- series plot


def plot_series(csv_path: Path, png_path: Path, columns: list[str]) -> bool:
    """Plot each of ``columns`` (those present) against ``t_s`` in microseconds, one panel each.

    Returns False (and writes nothing) when there is nothing to plot: fewer than two rows, no
    ``t_s`` column or none of ``columns`` present. Unparseable cells plot as gaps.
    """
    csv_path, png_path = Path(csv_path), Path(png_path)
    if not csv_path.is_file():
        return False
    with csv_path.open(newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    present = [c for c in columns if rows and c in rows[0]]
    if len(rows) < 2 or "t_s" not in rows[0] or not present:
        return False

    def col(name: str) -> np.ndarray:
        out = np.full(len(rows), np.nan)
        for i, r in enumerate(rows):
            with contextlib.suppress(TypeError, ValueError):
                out[i] = float(r[name])
        return out

    t_us = col("t_s") * 1e6
    fig = Figure(figsize=(4.2 * len(present), 3.2), layout="constrained")
    FigureCanvasAgg(fig)
    for ax, name in zip(fig.subplots(1, len(present), squeeze=False)[0], present, strict=True):
        ax.plot(t_us, col(name), lw=1.2)
        ax.set_xlabel("t [us]")
        ax.set_ylabel(_SERIES_LABELS.get(name, name))
        ax.grid(True, alpha=0.3)
    _save_png(fig, png_path, dpi=100)
    return True


# --------------------------------------------------------------------------- writer


class OutputWriter:
    """Writes everything a run produces into ``out_dir``; see module docstring."""

    def __init__(
        self,
        out_dir: Path,
        *,
        domain_um: tuple[float, float, float, float],
        melt_C: float,
        png: bool = True,
        gif: bool = True,
        vtu: bool = False,
        dpi: int = 80,
        deformation: str = "displacement",
    ) -> None:
        if deformation not in _DEFORM_LABELS:
            raise ValueError(
                f"deformation={deformation!r}; allowed: {', '.join(sorted(_DEFORM_LABELS))}"
            )
        xmin, xmax, ymin, ymax = (float(v) for v in domain_um)
        if not (xmax > xmin and ymax > ymin):
            raise ValueError(f"domain_um={domain_um!r} must be (xmin, xmax, ymin, ymax), min<max")
        self.out_dir = Path(out_dir)
        self.domain_um = (xmin, xmax, ymin, ymax)
        self.melt_C = float(melt_C)
        self.png, self.gif, self.vtu = png, gif, vtu
        self.dpi = int(dpi)
        self.deformation = deformation
        self.frames_written = 0
        self.out_dir.mkdir(parents=True, exist_ok=True)
        (self.out_dir / "frames").mkdir(exist_ok=True)
        self._png_paths: dict[int, Path] = {}
        self._pvd: dict[int, tuple[float, str]] = {}
        self._header: list[str] = []
        self._lines: list[list[str]] = []  # formatted cells; padded when the header grows
        self._fig: Figure | None = None

    # ----------------------------------------------------------------- simple files

    def write_case(self, toml_text: str) -> None:
        atomic_write_text(self.out_dir / "case.toml", toml_text)

    def summary(self, data: dict) -> None:
        text = json.dumps(_jsonable(data), indent=2, allow_nan=False)
        atomic_write_text(self.out_dir / "summary.json", text + "\n")

    def row(self, values: dict[str, float]) -> None:
        """Append a row to timeseries.csv (whole file rewritten atomically, so always valid).

        The first row fixes the column order; keys first seen later become new columns at the
        end (earlier rows left empty there) rather than being dropped.
        """
        for k in values:
            if k not in self._header:
                self._header.append(k)
        self._lines.append([_fmt_cell(values.get(k)) for k in self._header])
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(self._header)
        n = len(self._header)
        for cells in self._lines:
            w.writerow(cells + [""] * (n - len(cells)))
        atomic_write_text(self.out_dir / "timeseries.csv", buf.getvalue())

    @property
    def next_index(self) -> int:
        """The frame index after the last one written (or found when resuming)."""
        return max(self._png_paths, default=self.frames_written - 1) + 1

    def resume(self) -> None:
        """Continue an existing output folder: keep its time series rows and frames."""
        path = self.out_dir / "timeseries.csv"
        if path.is_file():
            rows = list(csv.reader(path.open()))
            if rows:
                self._header = rows[0]
                self._lines = rows[1:]
        for p in sorted((self.out_dir / "frames").glob("frame_*.png")):
            self._png_paths[int(p.stem.split("_")[1])] = p

    # ----------------------------------------------------------------- frames

    def frame(
        self,
        index: int,
        t_s: float,
        x_um: np.ndarray,
        T_C: np.ndarray,
        deform: np.ndarray,
        liquid_fraction: np.ndarray,
    ) -> None:
        """Write frame ``index`` (PNG and/or VTU as configured) for time ``t_s`` seconds."""
        x = np.asarray(x_um, dtype=float).reshape(-1, 2)
        fields = {
            "T_C": np.asarray(T_C, dtype=float).ravel(),
            "deform": np.asarray(deform, dtype=float).ravel(),
            "liquid_fraction": np.asarray(liquid_fraction, dtype=float).ravel(),
        }
        for name, v in fields.items():
            if v.shape != (len(x),):
                raise ValueError(f"frame {index}: {name} has {v.size} values for {len(x)} points")
        index = int(index)
        if self.png:
            self._draw(t_s, x, fields)
            path = self.out_dir / "frames" / f"frame_{index:04d}.png"
            _save_png(self._fig, path, self.dpi)
            self._png_paths[index] = path
        if self.vtu:
            self._write_vtu(index, float(t_s), x, fields)
        self.frames_written += 1

    def _setup_figure(self) -> None:
        xmin, xmax, ymin, ymax = self.domain_um
        panel_w = 4.2  # inches; 2 panels + colour bars stay ~800 px wide at dpi 80
        panel_h = min(max(panel_w * (ymax - ymin) / (xmax - xmin), 1.5), 6.0)
        fig = Figure(figsize=(2 * panel_w + 1.4, panel_h + 1.0))
        FigureCanvasAgg(fig)
        # Fixed layout (not constrained) so the axes box -- and so the marker scale -- is known
        # before drawing and identical across frames.
        fig.subplots_adjust(left=0.06, right=0.93, bottom=0.14, top=0.86, wspace=0.38)
        axes = fig.subplots(1, 2)
        cb_label, name = _DEFORM_LABELS[self.deformation]
        self._scatters, self._cbars = [], []
        for ax, cmap, label, title in zip(
            axes,
            ("inferno", "viridis"),
            ("T [C]", cb_label),
            ("temperature (cyan: melt)", name),
            strict=True,
        ):
            sc = ax.scatter(
                np.zeros(0), np.zeros(0), c=np.zeros(0), cmap=cmap, marker="s", linewidths=0
            )
            self._cbars.append(fig.colorbar(sc, ax=ax, label=label, fraction=0.046, pad=0.03))
            self._scatters.append(sc)
            ax.set_xlim(xmin, xmax)
            ax.set_ylim(ymin, ymax)
            ax.set_aspect("equal", adjustable="box")
            ax.set_xlabel("x [um]")
            ax.set_ylabel("y [um]")
            ax.set_title(title, fontsize=10)
        # Points per micrometre under equal aspect: the tighter of the two directions.
        pos = axes[0].get_position()
        w_pt, h_pt = fig.get_figwidth() * pos.width * 72, fig.get_figheight() * pos.height * 72
        self._pt_per_um = min(w_pt / (xmax - xmin), h_pt / (ymax - ymin))
        self._axes, self._contour, self._fig = axes, None, fig

    def _draw(self, t_s: float, x: np.ndarray, fields: dict[str, np.ndarray]) -> None:
        if self._fig is None:
            self._setup_figure()
        fallback = (
            self.domain_um[1] - self.domain_um[0]
        ) / 100  # lone or coincident points: a small visible square
        h = _point_spacing(x[np.isfinite(x).all(axis=1)], fallback)
        # Square side 1.5 h so neighbouring markers overlap: reads as a continuous body.
        size = max((1.5 * h * self._pt_per_um) ** 2, 0.5)
        T, d = fields["T_C"], fields["deform"]
        # T range always includes melt_C and |u| starts at 0, so colours keep their meaning.
        limits = (_finite_range(T, hi=self.melt_C), _finite_range(d, lo=0.0))
        for sc, v, clim in zip(self._scatters, (T, d), limits, strict=True):
            sc.set_offsets(x)
            sc.set_array(v)
            sc.set_sizes(np.array([size]))
            sc.set_clim(*clim)
        if self._contour is not None:
            with contextlib.suppress(Exception):
                self._contour.remove()
            self._contour = None
        try:
            grid = _melt_grid(x, fields["liquid_fraction"], 2.0 * h)
            if grid is not None:
                self._contour = self._axes[0].contour(
                    *grid, levels=[_MELT_LEVEL], colors="cyan", linewidths=1.0
                )
        except Exception:  # noqa: BLE001 -- the outline is decoration; never lose a frame to it
            self._contour = None
        self._fig.suptitle(f"t = {t_s * 1e6:.1f} us")

    def _write_vtu(self, index: int, t_s: float, x: np.ndarray, fields: dict) -> None:
        import meshio  # only needed for vtu=True

        rel = f"vtu/points_{index:04d}.vtu"
        pts = np.column_stack([x, np.zeros(len(x))])
        cells = [("vertex", np.arange(len(x)).reshape(-1, 1))] if len(x) else []
        mesh = meshio.Mesh(pts, cells, point_data=fields)
        with _atomic_path(self.out_dir / rel) as tmp:
            meshio.write(tmp, mesh, file_format="vtu")
        self._pvd[index] = (t_s, rel)
        entries = "".join(
            f'    <DataSet timestep="{t!r}" group="" part="0" file={quoteattr(f)}/>\n'
            for _, (t, f) in sorted(self._pvd.items())
        )
        atomic_write_text(
            self.out_dir / "points.pvd",
            '<?xml version="1.0"?>\n'
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            f"  <Collection>\n{entries}  </Collection>\n</VTKFile>\n",
        )

    # ----------------------------------------------------------------- end of run

    def finish(self) -> None:
        """Write animation.gif (if enabled) and timeseries.png; release the figure."""
        self._fig = None  # drop the frame figure; a later frame() rebuilds it
        if self.gif:
            paths = [p for _, p in sorted(self._png_paths.items())]
            if not paths:  # e.g. a fresh writer finishing an earlier run's folder
                paths = sorted((self.out_dir / "frames").glob("frame_*.png"))
            if paths:
                _write_gif(paths, self.out_dir / "animation.gif")
        columns = [c for c in _MONITORED if c in self._header]
        plot_series(self.out_dir / "timeseries.csv", self.out_dir / "timeseries.png", columns)


def _write_gif(paths: list[Path], gif_path: Path) -> None:
    """Encode PNG frames into a looping GIF under GIF_MAX_BYTES (drop frames, then downscale)."""
    import imageio.v3 as iio

    def rgb(p: Path) -> np.ndarray:
        im = np.asarray(iio.imread(p))
        return np.stack([im] * 3, axis=-1) if im.ndim == 2 else im[..., :3]

    def encode(sel: list[Path], scale: int, step: int) -> bytes:
        first = rgb(sel[0])[::scale, ::scale]
        data = np.full((len(sel), *first.shape), 255, dtype=np.uint8)  # one copy, no stacking
        for k, p in enumerate(sel):
            im = rgb(p)[::scale, ::scale]
            h, w = min(im.shape[0], first.shape[0]), min(im.shape[1], first.shape[1])
            data[k, :h, :w] = im[:h, :w]  # pad/crop should a frame differ in size
        # Dropping frames keeps the animation's pace: each kept frame shows `step` times longer.
        ms = round(1000 * GIF_FRAME_S * step)
        return iio.imwrite(
            "<bytes>", data, extension=".gif", plugin="pillow", is_batch=True, duration=ms, loop=0
        )

    n, step, scale = len(paths), 1, 1
    probe = paths[:: max(1, n // 8)][:8]  # estimate bytes per frame from a few frames
    per_frame = len(encode(probe, 1, 1)) / len(probe)
    step = max(1, math.ceil(n * per_frame / _GIF_BUDGET))
    if n / step < _GIF_MIN_FRAMES and n >= _GIF_MIN_FRAMES:
        step = max(1, n // _GIF_MIN_FRAMES)
    while True:
        data = encode(paths[::step], scale, step)
        if len(data) <= GIF_MAX_BYTES or scale >= 16:
            break
        if len(paths[::step]) > _GIF_MIN_FRAMES:
            step *= 2
        else:
            scale *= 2
    atomic_write_bytes(gif_path, data)
