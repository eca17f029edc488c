"""Case files: the validated schema, its resolution (resolve.py), TOML loading with a ``base``
and ``--set`` overrides, and the generated key reference. The lowest layer: it imports nothing
else of the package."""

from .bed import Bed
from .bodies import Body, Cylinder, Disc, Polygon, Prism, Rect
from .errors import CaseError
from .loading import (
    apply_override,
    bundled_case,
    bundled_cases,
    case_from_dict,
    case_to_dict,
    case_to_toml,
    deep_update,
    load_case,
    read_toml,
    validate_case,
)
from .materials import Material
from .resolve import ResolvedCase, resolve
from .schema import Case

__all__ = [
    "Bed",
    "Body",
    "Case",
    "CaseError",
    "Cylinder",
    "Disc",
    "Material",
    "Polygon",
    "Prism",
    "Rect",
    "ResolvedCase",
    "apply_override",
    "bundled_case",
    "bundled_cases",
    "case_from_dict",
    "case_to_dict",
    "case_to_toml",
    "deep_update",
    "load_case",
    "read_toml",
    "resolve",
    "validate_case",
]
