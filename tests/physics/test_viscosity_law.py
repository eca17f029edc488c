"""materials.*.viscosity_model = "arrhenius" (physics/materials.py, viscosity): the melt's
zero-shear viscosity follows eta_0 = eta_ref exp(E/R (1/T - 1/T_ref)) and is the Newtonian
viscosity of the zero-yield Perzyna melt (its Perzyna eta = 2 eta_0)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import material_field

from taichi_sls.backend import ti
from taichi_sls.config import Material
from taichi_sls.physics.materials import KELVIN, viscosity
from taichi_sls.solver.simulation import init_taichi
from taichi_sls.studies.references import arrhenius_viscosity, maxwell_shear_stress
from taichi_sls.studies.sinter_hold import newtonian_viscosity
from taichi_sls.studies.verification.mechanics import constitutive_history, shear_increment

# the process melt's law (taichi_sls/materials/pa12_process.toml), zero yield
MELT = Material(
    viscosity_model="arrhenius",
    viscosity_ref_Pas=4175.0,
    viscosity_ref_C=172.0,
    viscosity_activation_J_mol=32.5e3,
    youngs_solid_Pa=2.9e5,
    youngs_liquid_Pa=2.9e5,
    poisson=0.45,
    poisson_liquid=0.45,
    yield_solid_Pa=0.0,
    hardening_solid_Pa=0.0,
)
T_C = np.array([150.0, 172.0, 185.0, 200.0, 250.0])


def _closed_form(T_C: np.ndarray) -> np.ndarray:
    m = MELT
    T_ref = m.viscosity_ref_C + KELVIN
    return arrhenius_viscosity(
        T_C + KELVIN, m.viscosity_ref_Pas, T_ref, m.viscosity_activation_J_mol
    )


def test_the_kernel_law_is_twice_the_arrhenius_closed_form():
    """The kernel's Perzyna eta is 2 eta_0(T) to round-off (1e-12 relative) at 150-250 C, and
    eta_0 at T_ref is eta_ref; the Hopper clock of studies/sinter_hold reads eta_0 itself."""
    init_taichi(optimize=False)
    f = material_field(MELT)
    n = len(T_C)
    T, eta = ti.field(float, n), ti.field(float, n)
    T.from_numpy(T_C + KELVIN)

    @ti.kernel
    def run():
        for i in range(n):
            eta[i] = viscosity(f[0], T[i])

    run()
    expect = _closed_form(T_C)
    np.testing.assert_allclose(eta.to_numpy(), 2.0 * expect, rtol=1e-12)
    assert expect[1] == pytest.approx(4175.0, rel=1e-15)
    assert expect[0] > expect[1] > expect[2] > expect[3] > expect[4]
    np.testing.assert_allclose(newtonian_viscosity(MELT, T_C), expect, rtol=1e-15)


@pytest.mark.parametrize("T_C", [172.0, 200.0])
def test_simple_shear_of_the_melt_has_the_zero_shear_viscosity(T_C):
    """Simple shear at a constant rate from rest (rate tau = 1e-3, small strain): the shear
    stress follows the Maxwell closed form with the Newtonian viscosity eta_0(T) of the law,
    eta_0 rate (1 - exp(-t / tau)), tau = eta_0 / mu, within 1 % of its steady value over five
    tau at dt = tau / 1000 (the backward-Euler error is some 2e-4 there)."""
    eta0 = float(_closed_form(np.array([T_C]))[0])
    mu = 2.9e5 / (2 * 1.45)
    tau = eta0 / mu
    rate, dt, n = 1e-3 / tau, tau / 1000, 5000
    incs = np.tile(shear_increment(rate, dt), (n, 1, 1))
    sig = constitutive_history(MELT, incs, dt, T_K=T_C + KELVIN)
    t = dt * np.arange(1, n + 1)
    steady = eta0 * rate
    err = np.abs(sig[:, 0, 1] - maxwell_shear_stress(t, rate, mu, tau)).max() / steady
    print(f"{T_C} C: eta_0 = {eta0:.0f} Pa s, max error {err:.2e} of the steady stress")
    assert err < 0.01
