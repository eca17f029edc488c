"""The compile clock counts every kernel compiled, once; the front-end cache keeps Taichi's
error excerpts."""

import pytest

from taichi_sls import front_end
from taichi_sls.backend import ti
from taichi_sls.solver import compile_clock
from taichi_sls.solver.simulation import init_taichi


@pytest.fixture(scope="module", autouse=True)
def taichi():
    init_taichi()


def test_a_kernel_counts_on_its_first_call_only():
    assert compile_clock.available()
    x = ti.field(float, 4)

    @ti.kernel
    def fill(v: float):
        for i in x:
            x[i] = v

    start = compile_clock.reading()
    fill(1.0)
    first = compile_clock.since(start)
    assert first["kernels"] == 1 and first["front_end_s"] > 0.0 and first["back_end_s"] > 0.0
    assert first["compile_s"] == pytest.approx(first["front_end_s"] + first["back_end_s"])
    again = compile_clock.reading()
    fill(2.0)
    assert compile_clock.since(again)["kernels"] == 0
    assert compile_clock.since(again)["compile_s"] == 0.0
    assert x.to_numpy().tolist() == [2.0] * 4


def test_a_new_template_instance_counts_as_a_new_kernel():
    a, b = ti.field(float, 3), ti.field(float, 5)

    @ti.kernel
    def ones(f: ti.template()):
        for i in f:
            f[i] = 1.0

    start = compile_clock.reading()
    ones(a)
    ones(b)
    ones(a)
    assert compile_clock.since(start)["kernels"] == 2


def test_the_front_end_cache_keeps_taichis_error_excerpts():
    assert front_end.install()  # installed by init_taichi; installing again is a no-op

    @ti.kernel
    def broken():
        print(no_such_name_in_this_kernel + 1)  # noqa: F821

    with pytest.raises(ti.TaichiCompilationError) as e:
        broken()
    msg = str(e.value)
    # the file, the line and the code underlined, as Taichi formats them
    assert f'File "{__file__}"' in msg and "in broken" in msg
    assert "print(no_such_name_in_this_kernel + 1)" in msg and "^^^" in msg
    assert all(text.startswith('File "') for text in front_end._excerpts.values())
