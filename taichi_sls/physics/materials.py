"""Material properties as functions of temperature and solid fraction (paper section 2.4, Table 3).

Each material's parameters live in one element of a struct field whose members carry the case
file's key names, in SI: a key in C (``melt_C``) becomes the same name in kelvin (``melt_K``),
every other key keeps its name and unit (``youngs_solid_Pa``). Derived members:
``enthalpy_reference_K`` (``thermal.enthalpy_reference_C``), the enthalpies at T_c and T_m, and
the hysteresis flag with its range in K (``crystallization_range_C``).

Enthalpy per unit mass (docs/model.md: an enthalpy update per point, T recovered from H):
    H(T) = int_{T_ref}^T c(T') dT' + l_s (1 - xi_s(T)),
with c = xi_s c_c + (1 - xi_s) c_m and xi_s of eq. 33 clamped to [0, 1]. Between T_c and T_m the
sensible part is quadratic in T (c varies linearly), so the inverse T(H) is closed form.

Thermal hysteresis (``hysteresis`` = 1, docs/model.md): xi_s is a history variable. Melting
follows eq. 33 on [T_c, T_m] (xi_m(T)); crystallisation the same linear law on [T_l, T_h]
(xi_k(T)), with T_h <= T_c so that xi_k <= xi_m everywhere. Each update is
    xi_s <- min(xi_m(T), max(xi_k(T), xi_s)):
heating only melts (xi_s never above xi_m), cooling only crystallises (never below xi_k), and
between the branches the fraction holds (a supercooled melt). The enthalpy of a state is
    H(T, xi_s) = S(T) + l_s (1 - xi_s),
S(T) = H(T) - l_s (1 - xi_m(T)) the sensible part of the melting branch, so the melting branch
keeps the enthalpy above, bit for bit. (S's capacity follows the melting branch, c_c below T_c:
a supercooled melt takes the solid's c; exact for Table 3's c_c = c_m.) For a given previous
xi_s, H(T, update(T, xi_s)) rises monotonically in T (crystallisation branch, fraction held,
melting branch), so the inverse T(H; xi_s) is again closed form and unique.

Crystallisation kinetics (``kinetics`` = 1, docs/model.md eqs. K1-K3): the history above with
no crystallisation branch (its range set below 0 K, :data:`KINETICS_RANGE_K`); a melt instead
crystallises by Nakamura's law at its carried enthalpy, the latent heat raising T
(:func:`crystallize_at_enthalpy`).
"""

from taichi_sls.backend import ti

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
    "viscosity_ref_Pas",
    "viscosity_ref_K",
    "viscosity_activation_J_mol",
    "surface_tension_N_m",
    "solvent_viscosity_Pa_s",
    "enthalpy_reference_K",
    "enthalpy_crystallization_J_kg",  # H(T_c)
    "enthalpy_melt_J_kg",  # H(T_m)
    # thermal hysteresis (materials.NAME.crystallization_range_C): 1 when set; the range in K
    # (without it, the melting range, unused)
    "hysteresis",
    "crystallization_low_K",
    "crystallization_high_K",
    # crystallisation kinetics (materials.NAME.crystallization_kinetics): 1 when set (hysteresis
    # is then 1 too, its range KINETICS_RANGE_K); Nakamura's rate law, temperatures in K
    "kinetics",
    "kinetics_n",
    "kinetics_inv_t_half_0_1_s",
    "kinetics_U_J_mol",
    "kinetics_T_inf_K",
    "kinetics_T_m0_K",
    "kinetics_K_g_K2",
)
INT_MEMBERS = ("viscosity_model", "hysteresis", "kinetics")

# The crystallisation range (K) of a material with kinetics: below 0 K, so that the range's
# branch xi_k(T) is 0 at every temperature and the hysteresis functions keep only melting and
# the held fraction; the kinetics crystallise (:func:`crystallize_at_enthalpy`).
KINETICS_RANGE_K = (-1.0, 0.0)
GAS_CONSTANT = 8.314462618  # J/(mol K)
# With kinetics a point counts as molten (time_molten) while under 1 % crystallised: its
# fraction leaves 0 as soon as it cools below T_m0 (docs/record/pa12_process.md: "essentially
# amorphous", avrami_time_to(0.01))
KINETICS_MOLTEN = 0.01


def material_struct():
    """The struct type of one material (built after ti.init: ``float`` is the default precision)."""
    return ti.types.struct(**{k: ti.i32 if k in INT_MEMBERS else float for k in MATERIAL_MEMBERS})


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
    return _branch_temperature(mp, H, mp.latent_heat_J_kg)


@ti.func
def _branch_temperature(mp: ti.template(), E, latent):
    """The inverse of E(T) = the sensible enthalpy plus ``latent`` spread over [T_c, T_m]: H(T)
    with the full latent heat, the melting branch's sensible part S(T) with none."""
    T_c, T_m, c_c, c_m = _phase_range(mp)
    Ec = mp.enthalpy_crystallization_J_kg
    Em = mp.enthalpy_melt_J_kg - (mp.latent_heat_J_kg - latent)
    T = 0.0 * E
    if E <= Ec:
        T = mp.enthalpy_reference_K + E / c_c
    elif E >= Em:
        T = T_m + (E - Em) / c_m
    else:
        dT = T_m - T_c
        a = (c_m - c_c) / (2.0 * dT)
        b = c_c + latent / dT
        q = E - Ec
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
    """The Perzyna viscosity eta of eq. 41. Table 3: eta = A exp(-b T[C]) (T in C as printed),
    or a constant; or Arrhenius's zero-shear law eta_0 = eta_ref exp(E/R (1/T - 1/T_ref)) taken
    as the melt's Newtonian viscosity: the zero-yield Perzyna melt is Newtonian with eta / 2
    (docs/record/verification.md), so eta = 2 eta_0."""
    eta = mp.viscosity_Pas
    if mp.viscosity_model == ViscosityModel.EXPONENTIAL:
        eta = mp.viscosity_A_Pas * ti.exp(-mp.viscosity_b_1_C * (T - KELVIN))
    elif mp.viscosity_model == ViscosityModel.ARRHENIUS:
        arg = mp.viscosity_activation_J_mol / GAS_CONSTANT * (1.0 / T - 1.0 / mp.viscosity_ref_K)
        eta = 2.0 * mp.viscosity_ref_Pas * ti.exp(arg)
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


# ----------------------------------------------------------------------------- hysteresis
# A point counts as on a branch (its latent heat in the apparent capacity) within this much of
# the branch's fraction; it picks the capacity of the grid's heat step only, never the energy
# (which the enthalpy carries exactly), so a loose tolerance is harmless.
BRANCH_TOL = 1e-6


@ti.func
def crystallization_fraction(mp: ti.template(), T):
    """xi_k(T): the solid fraction of the crystallisation branch, eq. 33's linear law on
    [T_l, T_h], clamped to [0, 1]."""
    T_l = mp.crystallization_low_K
    T_h = mp.crystallization_high_K
    return ti.min(1.0, ti.max(0.0, 1.0 - (T - T_l) / (T_h - T_l)))


@ti.func
def solid_fraction_history(mp: ti.template(), T, xi0):
    """The solid fraction at T of a point whose fraction was xi0 (module docstring); eq. 33
    without hysteresis."""
    xi = solid_fraction(mp, T)
    if mp.hysteresis:
        xi = ti.min(xi, ti.max(crystallization_fraction(mp, T), xi0))
    return xi


@ti.func
def enthalpy_history(mp: ti.template(), T, xi):
    """H(T, xi_s) = S(T) + l_s (1 - xi_s) of the module docstring; H(T) without hysteresis."""
    H = enthalpy(mp, T)
    if mp.hysteresis:
        H += mp.latent_heat_J_kg * (solid_fraction(mp, T) - xi)
    return H


@ti.func
def _sensible_temperature(mp: ti.template(), S):
    """The inverse of the melting branch's sensible enthalpy S(T)."""
    return _branch_temperature(mp, S, 0.0)


@ti.func
def temperature_from_enthalpy_history(mp: ti.template(), H, xi0):
    """The T at which a point whose fraction was xi0 holds enthalpy H, its fraction updated
    (module docstring); exact inverse of H(T, solid_fraction_history(T, xi0))."""
    T = temperature_from_enthalpy(mp, H)  # the melting branch
    if mp.hysteresis:
        T_c, T_m, c_c, c_m = _phase_range(mp)
        l_s = mp.latent_heat_J_kg
        if H < enthalpy(mp, T_c + (1.0 - xi0) * (T_m - T_c)):  # below where melting resumes
            T = _sensible_temperature(mp, H - l_s * (1.0 - xi0))  # the fraction held
            T_l = mp.crystallization_low_K
            T_h = mp.crystallization_high_K
            if T < T_l + (1.0 - xi0) * (T_h - T_l):
                # crystallising: H = c_c (T - T_ref) + l_s (1 - xi_k(T)), with T <= T_h <= T_c
                H_l = c_c * (T_l - mp.enthalpy_reference_K)
                if H <= H_l:
                    T = mp.enthalpy_reference_K + H / c_c
                else:
                    T = T_l + (H - H_l) / (c_c + l_s / (T_h - T_l))
    return T


@ti.func
def heat_capacity_history(mp: ti.template(), T, xi):
    """The apparent capacity of a point at (T, xi_s): the sensible capacity of the melting
    branch, plus the latent heat per kelvin of the branch it lies on (melting: xi_s at xi_m
    inside [T_c, T_m]; crystallising: xi_s at xi_k inside [T_l, T_h]); a point whose fraction
    holds between the branches has none. Without hysteresis dH/dT as before."""
    c = apparent_heat_capacity(mp, T)
    if mp.hysteresis:
        T_c, T_m, c_c, c_m = _phase_range(mp)
        T_l = mp.crystallization_low_K
        T_h = mp.crystallization_high_K
        xi_m = solid_fraction(mp, T)
        c = lerp_phase(xi_m, c_c, c_m)
        if T > T_c and T < T_m and xi >= xi_m - BRANCH_TOL:
            c += mp.latent_heat_J_kg / (T_m - T_c)
        if T > T_l and T < T_h and xi <= crystallization_fraction(mp, T) + BRANCH_TOL:
            c += mp.latent_heat_J_kg / (T_h - T_l)
    return c


# ----------------------------------------------------------------------------- kinetics
# Nakamura's integral form (docs/model.md, eqs. K1-K3): X = 1 - exp(-theta^n), theta = int K_N dt.
# The state is the solid fraction itself: theta = (-ln(1 - xi_s))^(1/n) is recovered from it
# each heat step, advanced by K_N(T) dt, and mapped back. At constant T this is the Avrami
# closed form for any step (theta is linear in t); melting lowers xi_s and with it theta.


@ti.func
def nakamura_rate_constant(mp: ti.template(), T):
    """K_N(T) = (ln 2)^(1/n) / t_1/2(T) (1/s), eq. K3: the Hoffman-Lauritzen half time
    1/t_1/2 = (1/t_1/2)_0 exp(-U / (R (T - T_inf))) exp(-K_g / (T dT f)), dT = T_m0 - T,
    f = 2 T / (T + T_m0); 0 outside (T_inf, T_m0)."""
    T_inf = mp.kinetics_T_inf_K
    T_m0 = mp.kinetics_T_m0_K
    K = 0.0
    if T > T_inf and T < T_m0:
        f = 2.0 * T / (T + T_m0)
        log_rate = ti.log(mp.kinetics_inv_t_half_0_1_s) - mp.kinetics_U_J_mol / (
            GAS_CONSTANT * (T - T_inf)
        )
        log_rate -= mp.kinetics_K_g_K2 / (T * (T_m0 - T) * f)
        K = ti.exp(ti.log(ti.log(2.0)) / mp.kinetics_n + log_rate)
    return K


# below this, 1 - exp(-u) and -ln(1 - x) by their series: the incubation's X of 1e-30 must
# survive the round trip X -> theta -> X every step (1 - exp(-u) would round it to 0)
SERIES_BELOW = 1e-2


@ti.func
def _one_minus_exp_neg(u):
    """1 - exp(-u) for u >= 0 without cancellation (Taylor to u^8 below 1e-2: 1e-19 relative)."""
    r = 0.0
    if u < SERIES_BELOW:
        term = u
        for k in ti.static(range(2, 9)):
            r += term
            term *= -u / k
        r += term
    else:
        r = 1.0 - ti.exp(-u)
    return r


@ti.func
def _minus_log_one_minus(x):
    """-ln(1 - x) for 0 <= x < 1 without cancellation (series to x^10 below 1e-2: 1e-21)."""
    r = 0.0
    if x < SERIES_BELOW:
        xk = x
        for k in ti.static(range(1, 11)):
            r += xk / k
            xk *= x
    else:
        r = -ti.log(1.0 - x)
    return r


@ti.func
def nakamura_step(mp: ti.template(), T, xi, dt):
    """The crystalline fraction after dt at T from xi (eqs. K1-K2): theta = (-ln(1 - xi))^(1/n)
    + K_N(T) dt, X = 1 - exp(-theta^n); never below xi."""
    X = xi
    if xi < 1.0:
        K = nakamura_rate_constant(mp, T)
        if K > 0.0:
            n = mp.kinetics_n
            theta = ti.pow(_minus_log_one_minus(xi), 1.0 / n) + K * dt
            X = ti.max(xi, ti.min(1.0, _one_minus_exp_neg(ti.pow(theta, n))))
    return X


@ti.func
def crystallize_at_enthalpy(mp: ti.template(), H, T, xi, dt):
    """A kinetics point's (T, xi_s) after its heat step left it at (T, xi) with enthalpy H: the
    fraction crystallises by :func:`nakamura_step` at T over dt and the latent heat it releases
    raises T at the same H, T = S^-1(H - l_s (1 - xi_s)) (energy exact: H(T, xi_s) = H). A
    point that would crystallise past its melting branch (recalescence into [T_c, T_m]) stops
    on the branch: T = T(H), xi_s = xi_m(T)."""
    T1 = T
    xi1 = nakamura_step(mp, T, xi, dt)
    if xi1 > xi:
        T1 = _sensible_temperature(mp, H - mp.latent_heat_J_kg * (1.0 - xi1))
        if xi1 > solid_fraction(mp, T1):
            T1 = temperature_from_enthalpy(mp, H)
            xi1 = solid_fraction(mp, T1)
    else:
        xi1 = xi
    return T1, xi1
