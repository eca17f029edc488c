"""The material table of a case (``[materials.NAME]``)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import AfterValidator, Field

from .model import Model, Pair


def _poisson(v: float) -> float:
    if not -1.0 < v < 0.5:
        raise ValueError("must lie in (-1, 0.5)")
    return v


Poisson = Annotated[float, AfterValidator(_poisson)]


class CrystallizationKinetics(Model):
    """Quiescent crystallisation kinetics (docs/model.md): Nakamura's non-isothermal form of the
    isothermal Avrami law with a Hoffman-Lauritzen half time. Defaults: the PA12 values of
    docs/record/pa12_process.md (``studies.references.crystallization.PA12_CRYSTALLIZATION``), of
    which n, T_m0_C and K_g_K2 are modelling choices and inv_t_half_0_1_s is calibrated to a 146 C
    DSC peak at 10 K/min."""

    n: float = Field(3.0, ge=1.0, le=4.0, description="Avrami exponent n, in [1, 4]")
    inv_t_half_0_1_s: float = Field(
        9.072e4, gt=0, description="(1/t_1/2)_0, the pre-factor of the half-time law (1/s)"
    )
    U_J_mol: float = Field(
        6270.0, gt=0, description="U, activation energy of segmental transport (J/mol)"
    )
    T_inf_C: float = Field(13.0, description="T_inf, where transport stops: T_g - 30 K (C)")
    T_m0_C: float = Field(
        200.0, description="T_m0 (> T_inf_C), the equilibrium melting temperature (C)"
    )
    K_g_K2: float = Field(2.0e5, gt=0, description="K_g, the nucleation constant (K^2)")


class Material(Model):
    """Every parameter of the paper's Table 3. `_solid` holds for T <= T_c, `_liquid` for
    T >= T_m; in between they are interpolated linearly in the solid fraction (eq. 33)."""

    preset: str | None = Field(
        None,
        description="a bundled material whose values fill this table, the keys written beside "
        "it overriding them (config/presets.py): pa12_process, PA12 as a machine runs it "
        "(docs/record/pa12_process.md). Unset: the paper's Table 3, the defaults below",
    )
    density_kg_m3: float = Field(1020.0, gt=0, description="rho")
    conductivity_solid_W_mK: float = Field(0.28, gt=0, description="k_c")
    conductivity_liquid_W_mK: float = Field(0.24, gt=0, description="k_m")
    heat_capacity_solid_J_kgK: float = Field(2700.0, gt=0, description="c_c")
    heat_capacity_liquid_J_kgK: float = Field(2700.0, gt=0, description="c_m")
    latent_heat_J_kg: float = Field(50e3, ge=0, description="l_s")
    melt_C: float = Field(175.0, description="T_m")
    crystallization_C: float = Field(
        146.0,
        description="T_c (< T_m): the melting range is [T_c, T_m], on heating and cooling alike "
        "(eq. 33); with crystallization_range_C or crystallization_kinetics set, on heating only",
    )
    crystallization_range_C: Pair | None = Field(
        None,
        description="[T_low, T_high] with T_low < T_high <= crystallization_C: thermal "
        "hysteresis, a melt that supercools. Each point's solid fraction becomes history: it "
        "melts over [T_c, T_m] on heating, stays as it is while the temperature lies between "
        "the two ranges, and crystallises over [T_low, T_high] on cooling; the latent heat is "
        "absorbed on melting and released on crystallisation (docs/model.md). PA12 melts at "
        "about 175-185 C and crystallises near 145-150 C. Unset: the paper's one range [T_c, "
        "T_m] both ways",
    )
    crystallization_kinetics: CrystallizationKinetics | None = Field(
        None,
        description="crystallisation from kinetics instead of a range (docs/model.md), e.g. "
        "[materials.PA12.crystallization_kinetics] with no keys for the PA12 defaults; not with "
        "crystallization_range_C. Each point's solid fraction is history as with the range: it "
        "melts over [T_c, T_m] on heating, and a melt crystallises by Nakamura's law, "
        "X = 1 - exp(-(int K_N(T) dt)^n), K_N = (ln 2)^(1/n) / t_1/2(T), at any temperature in "
        "(T_inf, T_m0) where its melting branch allows it; the latent heat is released as it "
        "does. How long a melt lives at a bed temperature then follows from the material "
        "(PA12 defaults at 170 C: 1 % crystallised after 31 min). Unset: the paper's one range, "
        "or crystallization_range_C",
    )
    expansion_solid_1_K: float = Field(15e-5, description="alpha for T <= T_c")
    expansion_liquid_1_K: float = Field(5e-5, description="alpha for T >= T_m")
    solidification_dilatation: float = Field(
        0.015, description="beta: d(eps_m) = beta d(xi_s) 1 (eq. 37); 0.015 = the paper's 1.5 %"
    )
    poisson: Poisson = Field(0.42, description="nu for T <= T_c, in (-1, 0.5) (Table 3)")
    poisson_liquid: Poisson = Field(
        0.49,
        description="nu for T >= T_m, in (-1, 0.5); interpolated in xi_s like E. Default 0.49: a "
        "melt is nearly incompressible; the paper's one nu (set 0.42 for its reading) makes the "
        "10 kPa melt's bulk modulus 21 kPa, which its own Laplace pressure compresses by 8 % in "
        "area and so opens the neck (docs/model.md). 0.49 keeps the melt's P-wave modulus below "
        "the solid's: the same time step",
    )
    youngs_solid_Pa: float = Field(1e5, gt=0, description="E for T <= T_c")
    youngs_liquid_Pa: float = Field(1e4, gt=0, description="E for T >= T_m")
    yield_solid_Pa: float = Field(1e5, ge=0, description="sigma_Y for T <= T_c")
    yield_liquid_Pa: float = Field(1e4, ge=0, description="sigma_Y for T >= T_m")
    hardening_solid_Pa: float = Field(1e5, ge=0, description="H for T <= T_c")
    hardening_liquid_Pa: float = Field(0.0, ge=0, description="H for T >= T_m")
    viscosity_model: Literal["exponential", "constant", "arrhenius"] = Field(
        "exponential",
        description="the Perzyna viscosity eta (eq. 41). exponential: eta = A exp(-b T[C]) "
        "(Table 3); constant: eta = viscosity_Pas; arrhenius: a zero-shear law, the melt's "
        "Newtonian viscosity eta_0 = viscosity_ref_Pas exp(E/R (1/T - 1/T_ref)) (T in K), "
        "entered as eta = 2 eta_0 because the zero-yield Perzyna melt is Newtonian with "
        "eta / 2 (docs/record/verification.md)",
    )
    viscosity_A_Pas: float = Field(130219.0, gt=0, description="A of the exponential law (Pa s)")
    viscosity_b_1_C: float = Field(0.02, ge=0, description="b of the exponential law (1/C)")
    viscosity_Pas: float = Field(1e3, gt=0, description="constant viscosity (Pa s)")
    viscosity_ref_Pas: float = Field(
        4175.0, gt=0, description="eta_ref of the arrhenius law: eta_0 at viscosity_ref_C (Pa s)"
    )
    viscosity_ref_C: float = Field(172.0, description="T_ref of the arrhenius law (C)")
    viscosity_activation_J_mol: float = Field(
        32.5e3, ge=0, description="E, the flow activation energy of the arrhenius law (J/mol)"
    )
    surface_tension_N_m: float = Field(36.3e-3, ge=0, description="gamma (N/m)")
    solvent_viscosity_Pa_s: float = Field(
        0.0,
        ge=0,
        description="eta_s of a Kelvin-Voigt 'solvent' viscosity of the melt, a physical "
        "damping beside the paper's model (0: off, the paper's): the stress 2 eta_s dev(D), D = "
        "sym(L), weighted by the molten share (1 - xi_s), is added to the internal force only "
        "(it never enters the stored elastic state). It damps the melt's elastic ringing; size "
        "it to eta_s ~ rho c_s R, c_s = sqrt(mu_melt / rho) the melt's shear wave speed and R "
        "the particle radius (the critical damping of the particle's lowest modes): some "
        "0.01 Pa s for the paper's PA12, five orders below the melt viscosity. Its explicit "
        "limit dt <= rho h^2 / (c eta_s) joins the automatic time step (solver/params.py)",
    )

    def solid_below_C(self) -> float:
        """The temperature below which the material is solid whatever its history (C): the
        bottom of the crystallisation range, or T_c without hysteresis. With kinetics no
        temperature is (a melt may live for ever above T_inf): T_c, a progress estimate only."""
        r = self.crystallization_range_C
        return self.crystallization_C if r is None else r[0]
