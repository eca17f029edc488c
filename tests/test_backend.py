"""The backend shim: TAICHI_SLS_BACKEND picks the Taichi the solver compiles with."""

import pytest

from taichi_sls import backend


def test_the_default_backend_is_upstream_taichi():
    assert backend.DEFAULT == "taichi" and backend.load("taichi").__name__ == "taichi"


def test_an_unknown_backend_is_a_one_line_error_naming_the_choices(monkeypatch):
    monkeypatch.setenv(backend.ENV, "taichy")
    with pytest.raises(backend.BackendError) as e:
        backend.load()
    msg = str(e.value)
    assert "\n" not in msg and "TAICHI_SLS_BACKEND='taichy'" in msg
    assert all(name in msg for name in backend.BACKENDS)


def test_an_uninstalled_backend_is_a_one_line_error(monkeypatch):
    monkeypatch.setitem(backend.BACKENDS, "missing", "no_such_module_for_taichi_sls")
    with pytest.raises(backend.BackendError) as e:
        backend.load("missing")
    msg = str(e.value)
    assert "\n" not in msg and "'missing'" in msg and "does not import" in msg
