"""Validation against measured PA12: the measured data (:mod:`.measured`) and the comparisons
of computed necks with them (docs/validation.md)."""
