"""Named codes for the compile-time switches and the flags kept in fields."""

from enum import IntEnum, IntFlag


class Transfer(IntEnum):
    """Grid-to-point velocity transfer (``solver.transfer``)."""

    FLIP = 0  # eq. 14 as printed
    PIC_FLIP = 1  # flip_ratio * FLIP + (1 - flip_ratio) * PIC
    APIC = 2  # affine PIC


class Update(IntEnum):
    """When the stress is updated (``solver.update``)."""

    USL = 0  # with the grid velocity v^{n+1} (eqs. 14-17)
    MUSL = 1  # with the velocity remapped from the updated points


class WallMechanical(IntEnum):
    """Mechanical condition of a wall (``boundary.*.mechanical``)."""

    SLIP = 0  # zero normal velocity
    STICK = 1  # zero velocity
    OPEN = 2  # no condition
    MIRROR = 3  # a plane of symmetry: zero normal velocity, ghosts mirrored (physics/mirror.py)


class ViscosityModel(IntEnum):
    """``materials.*.viscosity_model``."""

    EXPONENTIAL = 0  # eta = A exp(-b T[C]) (Table 3)
    CONSTANT = 1
    ARRHENIUS = 2  # eta = 2 eta_0(T), eta_0 = eta_ref exp(E/R (1/T - 1/T_ref)) the zero-shear law


class NodeFlag(IntFlag):
    """Bits of the grid's ``flags`` field (the CSF method)."""

    CURVATURE = 1  # the node's 9-point fit is a valid curvature
    INTERFACE = 2  # the node carries a CSF force (mass and a mass gradient)


class StressReading(IntEnum):
    """``solver.stress_reading``."""

    MODEL = 0  # s = 2 mu dev(eps_e), p = K tr(eps_e) (docs/model.md)
    PAPER = 1  # eq. 39 and p = lambda tr(eps) as printed


class SurfaceMethod(IntEnum):
    """``surface_tension.method``."""

    CSF = 0  # the paper's level set, curvature and CSF force (eqs. 19-24)
    SURFACE_ENERGY = 1  # the gradient of gamma times the outline's length


class StressForm(IntEnum):
    """``solver.stress_form``."""

    TOTAL = 0  # stress from the accumulated elastic strain at the current moduli (eqs. 38-39)
    INCREMENTAL = 1  # the last stress plus the current moduli times the strain increment


class Strain(IntEnum):
    """``solver.strain``."""

    SMALL = 0  # accumulated eps += sym(L) dt (eqs. 16-17), total or incremental stress form
    FINITE = 1  # F = Fe Fp, Hencky elastic strain, the Perzyna map on the Kirchhoff stress


class HeatNode(IntEnum):
    """A node of the backward-Euler heat step (solver/implicit_heat.py)."""

    EMPTY = 0  # no heat capacity: no point reaches it
    FREE = 1  # an unknown temperature
    FIXED = 2  # a fixed-temperature wall's node: its temperature is given
