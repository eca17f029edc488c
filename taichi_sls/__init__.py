"""taichi_sls: particle-scale MPM simulation of selective laser sintering (Maeshima, Kim, Zohdi
2020, read as ../shared/MODEL.md fixes it). Entry points: ``python -m taichi_sls.run CASE.toml``."""

__version__ = "0.1.0"
