"""Pytest set-up. Shared helpers live in helpers.py (importable from every test folder: pytest puts
this folder on sys.path for its conftest)."""

import copy

import pytest
from helpers import PAPER_SCENE


@pytest.fixture
def paper_scene() -> dict:
    return copy.deepcopy(PAPER_SCENE)
