"""The table of ``thermal.imposed_temperature_csv``: a temperature history T(t) that every point
of the case is held at (physics/thermal.py ``hold_temperature``), read and checked with one clear
error per bad row.

The file is a CSV with a header naming the columns ``t_s`` (time, s) and ``T_C`` (temperature,
C); other columns and lines starting with ``#`` are ignored. The times start at 0 (the run's
start) and increase strictly; between rows the temperature is linear in time, after the last
row it stays at the last one.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .bed_csv import read_columns
from .errors import CaseError

KEY = "thermal.imposed_temperature_csv"
COLUMNS = ("t_s", "T_C")
ABSOLUTE_ZERO_C = -273.15


def read_temperature_table(path: str) -> tuple[np.ndarray, np.ndarray]:
    """The table's times (s) and temperatures (C), checked: the file exists, the header names
    t_s and T_C, every row holds finite numbers, the times start at 0 and increase strictly, the
    temperatures lie above absolute zero."""
    if not Path(path).is_file():
        raise CaseError(
            f"{KEY} = {path!r}: no such file; allowed: a CSV file with columns "
            f"{', '.join(COLUMNS)}, relative to the case file"
        )
    rows, lines = read_columns(path, KEY, COLUMNS, positive_last=False)
    t, T = rows[:, 0], rows[:, 1]
    if t[0] != 0.0:
        raise CaseError(
            f"{KEY} = {path!r} line {lines[0]}: t_s = {t[0]:g}: the first time must be 0 "
            "(the run's start)"
        )
    for k in range(1, len(t)):
        if not t[k] > t[k - 1]:
            raise CaseError(
                f"{KEY} = {path!r} line {lines[k]}: t_s = {t[k]:g} after {t[k - 1]:g}: the "
                "times must increase strictly"
            )
    for k in range(len(T)):
        if not T[k] > ABSOLUTE_ZERO_C:
            raise CaseError(
                f"{KEY} = {path!r} line {lines[k]}: T_C = {T[k]:g}: must be above absolute "
                f"zero ({ABSOLUTE_ZERO_C} C)"
            )
    return t, T


def temperature_at(t_s: np.ndarray, T_C: np.ndarray, t: float | np.ndarray) -> np.ndarray:
    """The table's temperature (C) at time(s) t (s): linear between rows, the last one after."""
    return np.interp(t, t_s, T_C)
