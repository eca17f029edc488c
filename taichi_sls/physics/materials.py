"""Material properties as functions of temperature and solid fraction (paper section 2.4, Table 3).

Each material's parameters live in one element of a struct field whose members carry the case
file's key names, in SI: a key in C (``melt_C``) becomes the same name in kelvin (``melt_K``),
every other key keeps its name and unit (``youngs_solid_Pa``). Three members are derived:
``enthalpy_reference_K`` (``thermal.enthalpy_reference_C``) and the enthalpies at T_c and T_m.

Enthalpy per unit mass (docs/model.md: an enthalpy update per point, T recovered from H):
    H(T) = int_{T_ref}^T c(T') dT' + l_s (1 - xi_s(T)),
with c = xi_s c_c + (1 - xi_s) c_m and xi_s of eq. 33 clamped to [0, 1]. Between T_c and T_m the
sensible part is quadratic in T (c varies linearly), so the inverse T(H) is closed form.
"""

import taichi as ti

from .codes import ViscosityModel

KELVIN = 273.15

# members of the material struct; the solver fills them from the case (solver/params.py)
MATERIAL_MEMBERS = (
    "density_kg_m3",
    "conductivity_solid_W_mK",
    "conductivity_liquid_W_mK",
    "heat_capacity_solid_J_kgK",
    "heat_capacity_liquid_J_kgK",
    "latent_heat_J_kg",
    "melt_K",
    "crystallization_K",
    "expansion_solid_1_K",
    "expansion_liquid_1_K",
    "solidification_dilatation",
    "poisson",
    "poisson_liquid",
    "youngs_solid_Pa",
    "youngs_liquid_Pa",
    "yield_solid_Pa",
    "yield_liquid_Pa",
    "hardening_solid_Pa",
    "hardening_liquid_Pa",
    "viscosity_model",
    "viscosity_A_Pas",
    "viscosity_b_1_C",
    "viscosity_Pas",
    "surface_tension_N_m",
    "solvent_viscosity_Pa_s",
    "enthalpy_reference_K",
    "enthalpy_crystallization_J_kg",  # H(T_c)
    "enthalpy_melt_J_kg",  # H(T_m)
)


def material_struct():
    """The struct type of one material (built after ti.init: ``float`` is the default precision)."""
    return ti.types.struct(
        **{k: ti.i32 if k == "viscosity_model" else float for k in MATERIAL_MEMBERS}
    )


@ti.func
def solid_fraction(mp: ti.template(), T):
    """Eq. 33, clamped to [0, 1]. ``mp``: one material (``materials[m]``)."""
    T_c = mp.crystallization_K
    T_m = mp.melt_K
    return ti.min(1.0, ti.max(0.0, 1.0 - (T - T_c) / (T_m - T_c)))


@ti.func
def lerp_phase(xi, solid, liquid):
    """A property interpolated linearly in the solid fraction between its solid and liquid
    values."""
    return xi * solid + (1.0 - xi) * liquid


@ti.func
def _phase_range(mp: ti.template()):
    """(T_c, T_m, c_c, c_m): the mushy range and the heat capacities at its ends."""
    return (
        mp.crystallization_K,
        mp.melt_K,
        mp.heat_capacity_solid_J_kgK,
        mp.heat_capacity_liquid_J_kgK,
    )


@ti.func
def temperature_from_enthalpy(mp: ti.template(), H):
    """Exact inverse of H(T) (module docstring)."""
    T_c, T_m, c_c, c_m = _phase_range(mp)
    Hc = mp.enthalpy_crystallization_J_kg
    Hm = mp.enthalpy_melt_J_kg
    T = 0.0 * H
    if H <= Hc:
        T = mp.enthalpy_reference_K + H / c_c
    elif H >= Hm:
        T = T_m + (H - Hm) / c_m
    else:
        dT = T_m - T_c
        a = (c_m - c_c) / (2.0 * dT)
        b = c_c + mp.latent_heat_J_kg / dT
        q = H - Hc
        # a s^2 + b s - q = 0, positive root, written to avoid cancellation when a -> 0
        s = 2.0 * q / (b + ti.sqrt(ti.max(b * b + 4.0 * a * q, 0.0)))
        T = T_c + s
    return T


@ti.func
def apparent_heat_capacity(mp: ti.template(), T):
    """dH/dT (J/kg/K): sensible plus latent heat spread over [T_c, T_m]."""
    T_c = mp.crystallization_K
    T_m = mp.melt_K
    xi = solid_fraction(mp, T)
    c = lerp_phase(xi, mp.heat_capacity_solid_J_kgK, mp.heat_capacity_liquid_J_kgK)
    if T > T_c and T < T_m:
        c += mp.latent_heat_J_kg / (T_m - T_c)
    return c


@ti.func
def viscosity(mp: ti.template(), T):
    """Table 3: eta = A exp(-b T[C]) (T in C as printed), or a constant."""
    eta = mp.viscosity_Pas
    if mp.viscosity_model == ViscosityModel.EXPONENTIAL:
        eta = mp.viscosity_A_Pas * ti.exp(-mp.viscosity_b_1_C * (T - KELVIN))
    return eta


@ti.func
def enthalpy(mp: ti.template(), T):
    """H(T) of the module docstring."""
    T_c, T_m, c_c, c_m = _phase_range(mp)
    dT = T_m - T_c
    s = ti.min(ti.max(T - T_c, 0.0), dT)
    H = c_c * (ti.min(T, T_c) - mp.enthalpy_reference_K)
    H += c_c * s + (c_m - c_c) * s * s / (2.0 * dT) + mp.latent_heat_J_kg * s / dT
    return H + c_m * ti.max(T - T_m, 0.0)
