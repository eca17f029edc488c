"""The 3D frames' surface panel (io/surface_image.py): an orthographic view of a closed
triangle surface, the nearer faces over the farther ones."""

import numpy as np
from test_frames3d import _lattice_sphere

from taichi_sls.io.surface3d import colour_grid, surface
from taichi_sls.io.surface_image import OrthographicView, box_edges, draw_surface, fit_box

VIEW = OrthographicView(elev_deg=25.0, azim_deg=-60.0)
BOX = np.array([(-12.0, 12.0)] * 3)


def _sphere(centre: np.ndarray, radius: float = 10.0):
    x = _lattice_sphere(radius, 1.0) + centre
    box = tuple((c - radius - 2.0, c + radius + 2.0) for c in centre)
    s = surface(colour_grid(x, {"T_C": np.zeros(len(x))}, 1.0, box))
    return s.verts, s.tris, s.normals()


def test_a_sphere_draws_as_a_disc_of_its_radius_from_any_view():
    """An orthographic view of a sphere of radius R is a disc of radius R: the drawn area within
    3 % of pi R^2 (the mesh's facets and the pixels' edge: measured +1.0 and +1.5 %), centred on the
    sphere's projected centre within a pixel, from two cameras; and the faces turned away are
    not drawn (the image is the same with them dropped beforehand)."""
    verts, tris, normals = _sphere(np.zeros(3))
    for view in (VIEW, OrthographicView(elev_deg=-40.0, azim_deg=130.0)):
        proj = fit_box(view, BOX, 400)
        colours = np.tile([0.2, 0.4, 0.6, 1.0], (len(tris), 1))
        image = draw_surface(proj, verts, tris, normals, colours)
        alpha = image[..., 3] / 255.0
        area_px = alpha.sum()
        assert abs(area_px / (np.pi * (10.0 * proj.scale) ** 2) - 1.0) < 0.03
        rows, cols = np.indices(alpha.shape)
        centre = np.array([(cols * alpha).sum(), (rows * alpha).sum()]) / area_px
        assert np.allclose(centre + 0.5, proj.pixels(np.zeros(3)), atol=1.0)
        front = normals @ proj.toward > 0.0
        alone = draw_surface(proj, verts, tris[front], normals[front], colours[front])
        assert np.array_equal(alone, image)


def test_the_nearer_of_two_spheres_covers_the_farther():
    """Two spheres on the line of sight, the red one nearer: the image's centre is red; swapped
    along the line, it is blue. The box's edges are drawn grey beneath."""
    proj = fit_box(VIEW, np.array([(-40.0, 40.0)] * 3), 300)
    near = 15.0 * proj.toward
    red, blue = [1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]
    for offset, want in ((near, red), (-near, blue)):
        parts = [_sphere(offset), _sphere(-offset)]
        shift = len(parts[0][0])
        verts = np.concatenate([p[0] for p in parts])
        tris = np.concatenate([parts[0][1], parts[1][1] + shift])
        normals = np.concatenate([p[2] for p in parts])
        colours = np.array([red] * len(parts[0][1]) + [blue] * len(parts[1][1]))
        image = draw_surface(proj, verts, tris, normals, colours, box_edges(BOX * 3))
        col, row = np.round(proj.pixels(np.zeros(3)) - 0.5).astype(int)
        assert np.allclose(image[row, col] / 255.0, want, atol=0.01)
        corner = np.round(proj.pixels(BOX[:, 1] * 3) - 0.5).astype(int)
        assert image[corner[1], corner[0], 3] > 0  # the box's corner is drawn
