"""Verification: each case of ``cases/verification/`` against its analytic reference.

A runner takes a :class:`~.spec.VerificationCase` (usually from :func:`load`, which sets the
resolution), runs it and returns a :class:`~.common.Result` with named error measures. The
default tests and the accuracy study (``taichi-sls bench accuracy``) call the same runners."""

from __future__ import annotations

from collections.abc import Callable

from ...config import CaseError
from .capillarity import (
    mode_amplitude,
    run_curvature,
    run_inviscid,
    run_laplace,
    run_square,
    run_viscous_decay,
)
from .common import Result
from .heat import run_energy, run_erf, run_gaussian, run_spot3d, run_stefan
from .hopper import run_hopper
from .mechanics import perzyna_history, run_bar, run_finite_strain, run_perzyna, run_steffen
from .spec import VerificationCase, case_names, case_path, load, load_file

RUNNERS: dict[str, Callable[[VerificationCase], Result]] = {
    "bar": run_bar,
    "steffen": run_steffen,
    "perzyna": run_perzyna,
    "finite_strain": run_finite_strain,
    "erf": run_erf,
    "gaussian": run_gaussian,
    "spot3d": run_spot3d,
    "stefan": run_stefan,
    "energy": run_energy,
    "curvature": run_curvature,
    "laplace": run_laplace,
    "square": run_square,
    "viscous_decay": run_viscous_decay,
    "inviscid": run_inviscid,
    "hopper": run_hopper,
}

__all__ = [
    "RUNNERS",
    "Result",
    "VerificationCase",
    "case_names",
    "case_path",
    "load",
    "load_file",
    "mode_amplitude",
    "perzyna_history",
    "run",
]


def run(vc: VerificationCase) -> Result:
    """Run the verification comparison that the case's ``[verification]`` kind names."""
    kind = vc.spec.kind
    if kind not in RUNNERS:
        raise CaseError(
            f"verification.kind = {kind!r}: no comparison to run; one of {', '.join(RUNNERS)}"
        )
    return RUNNERS[kind](vc)
