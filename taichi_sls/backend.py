"""The Taichi that the solver compiles with: upstream ``taichi`` or a maintained fork.

Every module imports ``ti`` from here (``from taichi_sls.backend import ti``), so one environment
variable, ``TAICHI_SLS_BACKEND``, swaps the compiler for the whole solver. The forks measured in
docs/record/compile.md are drop-in for Taichi 1.7's public API (taichi-forge) or not (Quadrants
renamed and removed names the solver uses); upstream ``taichi`` is the default
(docs/record/compile.md says why).
"""

from __future__ import annotations

import importlib
import os
from types import ModuleType

ENV = "TAICHI_SLS_BACKEND"
DEFAULT = "taichi"
# backend name -> the module it imports (the pip distribution in brackets)
BACKENDS = {
    "taichi": "taichi",  # upstream Taichi 1.7 (pip: taichi)
    "taichi_forge": "taichi_forge",  # community fork (pip: taichi-forge)
    "quadrants": "quadrants",  # Genesis' fork (pip: quadrants)
}


class BackendError(ImportError):
    """An unknown or uninstalled ``TAICHI_SLS_BACKEND``."""


def load(name: str | None = None) -> ModuleType:
    """The Taichi module ``name`` names (default: ``$TAICHI_SLS_BACKEND``, else upstream)."""
    name = (os.environ.get(ENV) or DEFAULT) if name is None else name
    if name not in BACKENDS:
        raise BackendError(f"{ENV}={name!r} is not a backend: use one of {', '.join(BACKENDS)}")
    try:
        return importlib.import_module(BACKENDS[name])
    except ImportError as e:
        why = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise BackendError(
            f"{ENV}={name!r}: module {BACKENDS[name]!r} does not import: {why}"
        ) from None


ti = load()
NAME: str = next(k for k, v in BACKENDS.items() if v == ti.__name__)
