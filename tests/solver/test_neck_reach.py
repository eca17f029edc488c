"""The per-contact neck (neck_width with pair_reach) read on the exact Hopper outline, no
simulation: it follows the coalescence past the initial diameter (issue #40 item 6)."""

import numpy as np
import pytest

from taichi_sls.solver.contacts import neck_width, pair_reach
from taichi_sls.studies.references.hopper import hopper_neck_at, hopper_nu, hopper_scale

R0_OVER_H = 20


def _hopper_field(z: np.ndarray, nu: float, R0: float) -> np.ndarray:
    """1 - |zeta| at the points z (complex) of Hopper's plane: >= 0 inside the outline, 0 on
    it, smooth across it (the inverse of the conformal map z = -i c zeta / (1 + nu zeta^2)
    of references/hopper.py, the root of nu z zeta^2 + i c zeta + z = 0 within the disc)."""
    c = hopper_scale(nu, R0)
    root = np.sqrt(-(c**2) - 4.0 * nu * z * z + 0j)
    den = np.where(np.abs(-1j * c - root) >= np.abs(-1j * c + root), -1j * c - root, -1j * c + root)
    return 1.0 - np.abs(2.0 * z / den)


def _read(tau: float, turn_deg: float) -> float:
    """r_n / R0 read by neck_width (reach pair_reach) on the exact outline's field sampled on
    the nodes at R0/h = 20, the outline turned by ``turn_deg`` about the neck."""
    h, R0, nu = 1.0 / R0_OVER_H, 1.0, hopper_nu(tau)
    off = 3 * R0_OVER_H
    g = (np.arange(2 * off + 1) - off) * h
    X, Y = np.meshgrid(g, g, indexing="ij")
    turn = np.exp(1j * np.deg2rad(turn_deg))
    field = _hopper_field((X + 1j * Y) / turn, nu, R0)  # turn the outline, not the grid
    # the lobes' centres: each half's area centroid, on a fine lattice (the bodies' mass centres)
    f = np.linspace(-2.0, 2.0, 801) * R0
    FX, FY = np.meshgrid(f, f, indexing="ij")
    zf = (FX + 1j * FY)[_hopper_field(FX + 1j * FY, nu, R0) >= 0.0]
    za, zb = zf[zf.real < 0].mean() * turn, zf[zf.real > 0].mean() * turn
    ca, cb = np.array([za.real, za.imag]), np.array([zb.real, zb.imag])
    w, _ = neck_width(field, h, off, ca, cb, pair_reach(R0, R0))
    return 0.5 * w / R0


@pytest.mark.parametrize("tau", [0.5, 1.0, 2.0, 3.0])
def test_neck_follows_hopper(tau: float) -> None:
    # 3 % (the bar): at tau = 0.5 the neck's radius of curvature is about a cell and the
    # bilinear field cuts it (-2.4 % measured); from tau = 1 on the reading is within 0.3 %.
    # Before pair_reach the width stopped at 2 R0 (1.000 at tau 2 and 3), and before the convex
    # rule the pair at tau 3 read a section at the range's end (-2 %).
    assert _read(tau, 0.0) == pytest.approx(float(hopper_neck_at(tau)), rel=0.03)


@pytest.mark.parametrize("tau", [1.0, 2.0, 3.0])
def test_turned_outline_reads_as_aligned(tau: float) -> None:
    # 1 % (the bar); measured <= 0.1 %. Not at tau = 0.5: the one-cell neck curvature
    # puts the turned reading 2.3 % from the aligned one (a resolution limit, reported).
    assert _read(tau, 45.0) == pytest.approx(_read(tau, 0.0), rel=0.01)
