"""The beam's first surface, read locally (``lasers.N.surface = "local"``; docs/model.md, "The
beam's first surface"): eq. 31's depth is measured from the highest point top in the grid column
that holds the point (a column of cells: x in 2D, (x, z) in 3D), found each heat step, not from
one y_l over the whole scene. A particle below a gap then absorbs from its own top.

A point's top is its centre plus its uGIMP half-width (``cfg.lp``): a point seeded at the top of
a body reaches the body's top, as the scene reading's y_l does."""

from taichi_sls.backend import ti

NO_SURFACE = -1.0e30  # a column holding no point


def column_shape(cfg) -> tuple[int, ...]:
    """The columns' array shape: the grid's nodes across x (and z): one column per cell."""
    return (cfg.nx,) if cfg.dim == 2 else (cfg.nx, cfg.nz)


@ti.func
def _cell(cfg: ti.template(), coordinate, n):
    return ti.min(ti.max(ti.cast(ti.floor(coordinate * cfg.inv_h), ti.i32) + cfg.off, 0), n - 1)


@ti.func
def column_of(cfg: ti.template(), x):
    """The index of the column of cells holding position x (clamped to the grid)."""
    if ti.static(cfg.dim == 3):
        return ti.Vector([_cell(cfg, x[0], cfg.nx), _cell(cfg, x[2], cfg.nz)])
    else:
        return ti.Vector([_cell(cfg, x[0], cfg.nx)])


@ti.func
def find_column_tops(cfg: ti.template(), pt: ti.template(), tops: ti.template()):
    """tops[column] = the highest point top in each column (NO_SURFACE where none)."""
    for I in ti.grouped(ti.ndrange(*tops.shape)):  # a range: a struct-for cannot nest
        tops[I] = NO_SURFACE
    for p in range(cfg.n_points):
        ti.atomic_max(tops[column_of(cfg, pt.x[p])], pt.x[p][1] + cfg.lp)
