"""Zero-shear viscosity of a polymer melt against temperature: the Arrhenius law."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ._util import out

GAS_CONSTANT = 8.314462618  # J/(mol K)


def arrhenius_viscosity(
    T_K: ArrayLike, eta_ref: float, T_ref_K: float, E_J_mol: float
) -> float | np.ndarray:
    """eta_0(T) = eta_ref exp(E / R (1/T - 1/T_ref)) (Pa s), T in K: the Arrhenius shift of a
    melt's zero-shear viscosity far above its glass transition (Ferry 1980, ch. 11; the form of
    MercuryDPM's melt, docs/record/pa12_process.md)."""
    T = np.asarray(T_K, dtype=float)
    return out(eta_ref * np.exp(E_J_mol / GAS_CONSTANT * (1.0 / T - 1.0 / T_ref_K)))
