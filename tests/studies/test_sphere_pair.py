"""studies/sphere_pair.py: two liquid spheres coalescing in 3D (no heat). A short look at
R/h = 4 (25 s: slow): the neck grows from the seeded contact and the volume is kept.
The study's figures to tau = 3.8 are in docs/verification.md."""

import pytest

from taichi_sls.studies.sphere_pair import coalesce, sphere_pair_case


@pytest.mark.slow
def test_the_spheres_neck_grows_and_the_volume_is_kept():
    """To tau = 0.2 at R/h = 4: x/R rises every frame (measured 0.50, 0.56, 0.61) and the
    volume sum V0 J moves by less than 0.5 % (measured -0.11 %: the Maxwell liquid's elastic
    volume change under its Laplace pressure, K = 2.9 MPa against 2 gamma / R = 3.6 kPa, and
    the grid's; bound 0.5 %)."""
    rows = coalesce(sphere_pair_case(4.0, 0.2), frames=2, progress=False)
    x = [r["x_over_R"] for r in rows]
    assert x[0] > 0.0 and all(b > a for a, b in zip(x, x[1:], strict=False))
    assert rows[-1]["tau"] == pytest.approx(0.2, rel=0.05)
    assert all(abs(r["volume_change"]) < 5e-3 for r in rows)
