"""Case tables -> the parameter structs of the kernels, and the stability limits (eqs. 46-48).

Material members keep the case's key names; a key in C becomes the same name in K
(physics/materials.py). Laser members are in SI, ``_um`` keys becoming ``_m``."""

from __future__ import annotations

import math

import numpy as np

from ..config import Case, Material
from ..config.materials import CrystallizationKinetics
from ..config.temperature_table import read_temperature_table
from ..physics.codes import ViscosityModel
from ..physics.laser import LASER_MEMBERS
from ..physics.materials import INT_MEMBERS, KELVIN, KINETICS_RANGE_K, MATERIAL_MEMBERS

# the material keys that are temperatures (C), kept in kelvin under the same name with _K
TEMPERATURES_C = ("melt_C", "crystallization_C", "viscosity_ref_C")


def material_values(m: Material, enthalpy_reference_C: float) -> dict[str, float]:
    """The kernel's parameters of one material (SI, temperatures in K)."""
    vals: dict[str, float] = {}
    for key, v in m.model_dump().items():
        if key in TEMPERATURES_C:
            vals[key[:-2] + "_K"] = v + KELVIN
        elif key == "viscosity_model":
            vals[key] = int(ViscosityModel[v.upper()])
        elif key == "crystallization_range_C":
            # hysteresis: the crystallisation range in K and the flag the kernels branch on; a
            # material without it keeps its melting range both ways (physics/materials.py).
            # Kinetics keep the history (hysteresis 1) without a crystallisation branch: its
            # range lies below 0 K, where xi_k(T) = 0 at every temperature (KINETICS_RANGE_K)
            lo, hi = v if v is not None else (m.crystallization_C, m.melt_C)
            kinetic = m.crystallization_kinetics is not None
            vals["hysteresis"] = int(v is not None or kinetic)
            vals["crystallization_low_K"] = KINETICS_RANGE_K[0] if kinetic else lo + KELVIN
            vals["crystallization_high_K"] = KINETICS_RANGE_K[1] if kinetic else hi + KELVIN
        elif key == "crystallization_kinetics":
            # Nakamura's rate law in SI (a material without kinetics carries the PA12 defaults,
            # never read: kinetics = 0)
            kin = v if v is not None else CrystallizationKinetics().model_dump()
            vals["kinetics"] = int(v is not None)
            vals["kinetics_n"] = kin["n"]
            vals["kinetics_inv_t_half_0_1_s"] = kin["inv_t_half_0_1_s"]
            vals["kinetics_U_J_mol"] = kin["U_J_mol"]
            vals["kinetics_T_inf_K"] = kin["T_inf_C"] + KELVIN
            vals["kinetics_T_m0_K"] = kin["T_m0_C"] + KELVIN
            vals["kinetics_K_g_K2"] = kin["K_g_K2"]
        else:
            vals[key] = v
    T_c, T_m = vals["crystallization_K"], vals["melt_K"]
    T_ref = enthalpy_reference_C + KELVIN
    H_c = m.heat_capacity_solid_J_kgK * (T_c - T_ref)
    # mushy sensible heat with c linear in T from c_c to c_m, plus the whole latent heat
    H_m = H_c + 0.5 * (m.heat_capacity_solid_J_kgK + m.heat_capacity_liquid_J_kgK) * (T_m - T_c)
    H_m += m.latent_heat_J_kg
    vals.update(
        enthalpy_reference_K=T_ref, enthalpy_crystallization_J_kg=H_c, enthalpy_melt_J_kg=H_m
    )
    return {k: vals[k] for k in MATERIAL_MEMBERS}


def material_arrays(case: Case, names: list[str]) -> dict[str, np.ndarray]:
    """Every material's parameters, one array per struct member (for ``from_numpy``)."""
    rows = [material_values(case.materials[n], case.thermal.enthalpy_reference_C) for n in names]
    return {
        k: np.array([r[k] for r in rows], dtype=np.int32 if k in INT_MEMBERS else float)
        for k in MATERIAL_MEMBERS
    }


def laser_arrays(case: Case) -> dict[str, np.ndarray]:
    """Every beam's parameters in SI, one array per struct member."""
    top = case.top_um()
    rows = []
    for las in case.lasers:
        r0 = las.spot_radius_um * 1e-6
        eta = las.penetration_depth_um * 1e-6
        # eq. 31 read as power per unit volume (W/m^3), docs/model.md
        amp = 2 * las.absorptivity * las.power_W / (math.pi * r0 * r0 * eta) * las.depth_factor
        if las.source_units == "W_per_kg":  # eq. 3 as printed: rho * s_laser
            amp *= case.materials[case.bodies[0].material].density_kg_m3
        x_end = las.x_end_um if las.x_end_um is not None else 1e9
        y_top = las.top_um if las.top_um is not None else top
        rows.append(
            dict(
                on_s=las.on_s,
                off_s=las.off_s,
                x_start_m=las.x_start_um * 1e-6,
                speed_m_s=las.speed_m_s,
                x_end_m=x_end * 1e-6,
                top_m=y_top * 1e-6,
                amplitude_W_m3=amp,
                spot_radius_m=r0,
                penetration_depth_m=eta,
                across=1.0 if las.scan == "across" else 0.0,
                tracks=float(las.tracks),
                hatch_m=las.hatch_um * 1e-6,
                return_s=las.return_s or 0.0,
                pass_half_s=las.pass_half_s() if las.scan == "across" else 0.0,
                z_start_m=(las.z_start_um or 0.0) * 1e-6,
                z_end_m=(las.z_end_um if las.z_end_um is not None else 1e9) * 1e-6,
                along_z=1.0 if las.direction == "z" else 0.0,
                local_surface=1.0 if las.surface == "local" else 0.0,
            )
        )
    return {k: np.array([r[k] for r in rows], dtype=float) for k in LASER_MEMBERS}


# ----------------------------------------------------------------------------- stability


# c of the solvent viscosity's explicit limit dt <= rho h^2 / (c eta_s) in d dimensions. The
# stress 2 eta_s dev(D) (3D deviator) gives the momentum equation eta_s (lap v + grad div v / 3);
# on a lumped-mass grid of spacing h the discrete Laplacian's largest eigenvalue is 4 d / h^2
# (the uGIMP weights only smooth it) and the grad-div part adds at most a third, so
# nu lambda_max <= (4/3) 4 d nu / h^2, nu = eta_s / rho; forward Euler in the velocity is stable
# for dt lambda_max <= 2: c = 8 d / 3. It is taken beside the elastic limit, not combined with
# it: time.safety (0.4) covers the two acting together. The same eigenvalue 4 d / h^2 sets the
# thermal limit h^2 rho c / (2 d k) (eq. 48's h^2 / 4 alpha in 2D) and scales the elastic one,
# written h / c_p in 2D, by sqrt(2 / d).
def imposed_table(case: Case) -> tuple[np.ndarray, np.ndarray]:
    """The held temperature history of ``thermal.imposed_temperature_csv``: times (s) and
    temperatures (K), as the kernels read them (State.imposed); empty arrays without one."""
    path = case.thermal.imposed_temperature_csv
    if path is None:
        return np.zeros(0), np.zeros(0)
    t_s, T_C = read_temperature_table(path)
    return t_s, T_C + KELVIN


def viscous_stencil(dim: int = 2) -> float:
    """c = 8 d / 3 of the viscous limit rho h^2 / (c eta_s) in ``dim`` dimensions."""
    return 8.0 * dim / 3.0


VISCOUS_STENCIL = viscous_stencil(2)


def p_wave_modulus(E: float, nu: float) -> float:
    """M = E (1 - nu) / ((1 + nu)(1 - 2 nu)): the modulus of the fastest (dilatational) wave."""
    return E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))


def stability_limits(m: Material, h: float, dim: int = 2) -> dict[str, float]:
    """Time-step limits (s) of one material on grid spacing h (m), docs/model.md / eqs. 46-48.

    The elastic limit uses the larger P-wave modulus of the two phases, each with its own nu;
    the thermal limit the smallest heat capacity and largest conductivity; a solvent
    viscosity adds its own ("viscous", :func:`viscous_stencil`). ``dim``: 2 or 3 (the grid
    stencil's largest eigenvalue grows with it).
    """
    M = max(
        p_wave_modulus(m.youngs_solid_Pa, m.poisson),
        p_wave_modulus(m.youngs_liquid_Pa, m.poisson_liquid),
    )
    c_wave = math.sqrt(M / m.density_kg_m3)
    k = max(m.conductivity_solid_W_mK, m.conductivity_liquid_W_mK)
    c = min(m.heat_capacity_solid_J_kgK, m.heat_capacity_liquid_J_kgK)
    # sqrt(2 / 2) and 2 * 2 are exact: the 2D limits keep their bits
    elastic = h / c_wave * math.sqrt(2 / dim)
    out = {"elastic": elastic, "thermal": h * h * m.density_kg_m3 * c / (2 * dim * k)}
    if m.solvent_viscosity_Pa_s > 0:
        out["viscous"] = h * h * m.density_kg_m3 / (viscous_stencil(dim) * m.solvent_viscosity_Pa_s)
    if m.surface_tension_N_m > 0:
        out["surface_tension"] = math.sqrt(m.density_kg_m3 * h**3 / m.surface_tension_N_m)
    return out
