"""Patches to Taichi's private Python front end (front_end.py: memoized sources and source
excerpts, a faster class check): compile time only, every kernel and message the same. Nothing
is patched on import: :func:`install` patches, and ``init_taichi`` (solver/simulation.py) calls
it before each ``ti.init``."""

from .front_end import install

__all__ = ["install"]
