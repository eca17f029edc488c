"""Material properties as functions of temperature and solid fraction (paper section 2.4, Table 3).

Parameters live in a small Taichi field ``mat[m, P_*]`` filled from the case's
:class:`~taichi_sls.case.Material` tables (SI units, temperatures in kelvin), so no material
constant is written inside a kernel.

Enthalpy per unit mass (MODEL.md: an enthalpy update per point, T recovered from H):
    H(T) = int_{T_ref}^T c(T') dT' + l_s (1 - xi_s(T)),
with c = xi_s c_c + (1 - xi_s) c_m and xi_s of eq. 33 clamped to [0, 1]. Between T_c and T_m the
sensible part is quadratic in T (c varies linearly), so the inverse T(H) is closed form.
"""

import math

import numpy as np
import taichi as ti

from .case import Material

KELVIN = 273.15

P_NAMES = (
    "rho",
    "k_c",
    "k_m",
    "c_c",
    "c_m",
    "l_s",
    "T_m",
    "T_c",
    "alpha_c",
    "alpha_m",
    "beta",
    "nu",
    "nu_m",
    "E_c",
    "E_m",
    "sy_c",
    "sy_m",
    "H_c",
    "H_m",
    "visc_const",  # 1: constant viscosity, 0: A exp(-b T[C])
    "visc_A",
    "visc_b",
    "visc",
    "gamma",
    "T_ref",
    "H_at_Tc",  # enthalpy at T_c (J/kg), derived
    "H_at_Tm",  # enthalpy at T_m (J/kg), derived
)
P = {n: i for i, n in enumerate(P_NAMES)}
N_PARAMS = len(P_NAMES)


def material_row(m: Material, T_ref_C: float) -> "np.ndarray":
    """The SI parameter row of one material (temperatures in K)."""
    T_c = m.crystallization_C + KELVIN
    T_m = m.melt_C + KELVIN
    T_ref = T_ref_C + KELVIN
    H_c = m.heat_capacity_solid_J_kgK * (T_c - T_ref)
    # mushy sensible heat with c linear in T from c_c to c_m, plus the whole latent heat
    H_m = H_c + 0.5 * (m.heat_capacity_solid_J_kgK + m.heat_capacity_liquid_J_kgK) * (T_m - T_c)
    H_m += m.latent_heat_J_kg
    vals = dict(
        rho=m.density_kg_m3,
        k_c=m.conductivity_solid_W_mK,
        k_m=m.conductivity_liquid_W_mK,
        c_c=m.heat_capacity_solid_J_kgK,
        c_m=m.heat_capacity_liquid_J_kgK,
        l_s=m.latent_heat_J_kg,
        T_m=T_m,
        T_c=T_c,
        alpha_c=m.expansion_solid_1_K,
        alpha_m=m.expansion_liquid_1_K,
        beta=m.solidification_dilatation,
        nu=m.poisson,
        nu_m=m.poisson_liquid,
        E_c=m.youngs_solid_Pa,
        E_m=m.youngs_liquid_Pa,
        sy_c=m.yield_solid_Pa,
        sy_m=m.yield_liquid_Pa,
        H_c=m.hardening_solid_Pa,
        H_m=m.hardening_liquid_Pa,
        visc_const=1.0 if m.viscosity_model == "constant" else 0.0,
        visc_A=m.viscosity_A_Pas,
        visc_b=m.viscosity_b_1_C,
        visc=m.viscosity_Pas,
        gamma=m.surface_tension_N_m,
        T_ref=T_ref,
        H_at_Tc=H_c,
        H_at_Tm=H_m,
    )
    return np.array([vals[n] for n in P_NAMES], dtype=np.float64)


# ----------------------------------------------------------------------------- host side


def p_wave_modulus(E: float, nu: float) -> float:
    """M = E (1 - nu) / ((1 + nu)(1 - 2 nu)): the modulus of the fastest (dilatational) wave."""
    return E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))


def stability_limits(m: Material, h: float) -> dict[str, float]:
    """Time-step limits (s) of one material on grid spacing h (m), MODEL.md / eqs. 46-48.

    The elastic limit uses the larger P-wave modulus of the two phases, each with its own nu;
    the thermal limit the smallest heat capacity and largest conductivity.
    """
    M = max(
        p_wave_modulus(m.youngs_solid_Pa, m.poisson),
        p_wave_modulus(m.youngs_liquid_Pa, m.poisson_liquid),
    )
    c_wave = math.sqrt(M / m.density_kg_m3)
    k = max(m.conductivity_solid_W_mK, m.conductivity_liquid_W_mK)
    c = min(m.heat_capacity_solid_J_kgK, m.heat_capacity_liquid_J_kgK)
    out = {"elastic": h / c_wave, "thermal": h * h * m.density_kg_m3 * c / (4 * k)}
    if m.surface_tension_N_m > 0:
        out["surface_tension"] = math.sqrt(m.density_kg_m3 * h**3 / m.surface_tension_N_m)
    return out


# ----------------------------------------------------------------------------- device funcs


@ti.func
def solid_fraction(mat: ti.template(), m, T):
    """Eq. 33, clamped to [0, 1]."""
    T_c = mat[m, P["T_c"]]
    T_m = mat[m, P["T_m"]]
    return ti.min(1.0, ti.max(0.0, 1.0 - (T - T_c) / (T_m - T_c)))


@ti.func
def lerp_phase(mat: ti.template(), m, xi, solid: ti.template(), liquid: ti.template()):
    """Property interpolated linearly in the solid fraction between its solid and liquid values."""
    return xi * mat[m, P[solid]] + (1.0 - xi) * mat[m, P[liquid]]


@ti.func
def temperature_from_enthalpy(mat: ti.template(), m, H):
    """Exact inverse of H(T) (module docstring)."""
    T_c = mat[m, P["T_c"]]
    T_m = mat[m, P["T_m"]]
    c_c = mat[m, P["c_c"]]
    c_m = mat[m, P["c_m"]]
    Hc = mat[m, P["H_at_Tc"]]
    Hm = mat[m, P["H_at_Tm"]]
    T = 0.0 * H
    if H <= Hc:
        T = mat[m, P["T_ref"]] + H / c_c
    elif H >= Hm:
        T = T_m + (H - Hm) / c_m
    else:
        dT = T_m - T_c
        a = (c_m - c_c) / (2.0 * dT)
        b = c_c + mat[m, P["l_s"]] / dT
        q = H - Hc
        # a s^2 + b s - q = 0, positive root, written to avoid cancellation when a -> 0
        s = 2.0 * q / (b + ti.sqrt(ti.max(b * b + 4.0 * a * q, 0.0)))
        T = T_c + s
    return T


@ti.func
def apparent_heat_capacity(mat: ti.template(), m, T):
    """dH/dT (J/kg/K): sensible plus latent heat spread over [T_c, T_m]."""
    T_c = mat[m, P["T_c"]]
    T_m = mat[m, P["T_m"]]
    xi = solid_fraction(mat, m, T)
    c = lerp_phase(mat, m, xi, "c_c", "c_m")
    if T > T_c and T < T_m:
        c += mat[m, P["l_s"]] / (T_m - T_c)
    return c


@ti.func
def viscosity(mat: ti.template(), m, T):
    """Table 3: eta = A exp(-b T[C]) (T in C as printed), or a constant."""
    eta = mat[m, P["visc"]]
    if mat[m, P["visc_const"]] < 0.5:
        eta = mat[m, P["visc_A"]] * ti.exp(-mat[m, P["visc_b"]] * (T - KELVIN))
    return eta


@ti.func
def enthalpy(mat: ti.template(), m, T):
    """H(T) of the module docstring, on the device."""
    T_c = mat[m, P["T_c"]]
    T_m = mat[m, P["T_m"]]
    c_c = mat[m, P["c_c"]]
    c_m = mat[m, P["c_m"]]
    dT = T_m - T_c
    s = ti.min(ti.max(T - T_c, 0.0), dT)
    H = c_c * (ti.min(T, T_c) - mat[m, P["T_ref"]])
    H += c_c * s + (c_m - c_c) * s * s / (2.0 * dT) + mat[m, P["l_s"]] * s / dT
    return H + c_m * ti.max(T - T_m, 0.0)
