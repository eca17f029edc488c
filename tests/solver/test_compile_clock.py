"""The compile clock counts every kernel compiled, once; the front-end cache keeps Taichi's
error excerpts."""

import pytest

from taichi_sls.backend import ti
from taichi_sls.solver import compile_clock
from taichi_sls.solver.simulation import init_taichi
from taichi_sls.taichi_patches import front_end


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
    assert front_end.install(ti)  # installed by init_taichi; installing again is a no-op

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


def test_the_fast_wrapper_wraps_as_taichis_textwrapper():
    """The excerpts' wrapper (front_end._Wrapper) against textwrap's own on every line of the
    package's source and on caret lines of every length up to past the width: equal."""
    import pathlib
    import textwrap

    import taichi_sls

    lines = set()
    for path in pathlib.Path(taichi_sls.__file__).parent.rglob("*.py"):
        lines.update(path.read_text().splitlines())
    lines.update(
        " " * a + "^" * b + " " * c
        for a in range(0, 90, 7)
        for b in range(0, 90, 9)
        for c in (0, 3)
    )
    lines.update(("", " ", "\tx = 1", "a\rb", "x" * 80, "x" * 81, " " * 79 + "y"))
    ours, theirs = front_end._Wrapper(width=80), textwrap.TextWrapper(width=80)
    assert len(lines) > 5000
    for line in lines:
        assert ours.wrap(line) == theirs.wrap(line), repr(line)


def test_the_fast_class_check_answers_as_taichis():
    """front_end's ``_inside_class`` (the decorating frame's line read through linecache) and
    Taichi's own (through inspect) on decorations at module level (a module reloaded: the frame
    above is the import system's), in a function, in a plain class and in a data-oriented one."""
    import importlib

    from taichi_sls.backend import ti
    from taichi_sls.physics import small_matrix

    kernel_impl = ti.lang.kernel_impl
    fast = kernel_impl._inside_class
    assert getattr(fast, "_sls_memo", False)
    answers = []

    def both(level_of_class_stackframe):
        ours = fast(level_of_class_stackframe + 1)
        answers.append((ours, fast.original(level_of_class_stackframe + 1)))
        return ours

    kernel_impl._inside_class = both
    try:
        importlib.reload(small_matrix)

        @ti.func
        def plain(x):
            return x

        class Plain:
            @ti.func
            def method(self, x):
                return x

        @ti.data_oriented
        class Oriented:
            @ti.kernel
            def kernel(self):
                pass

    finally:
        kernel_impl._inside_class = fast
    assert len(answers) >= 5
    assert all(ours == theirs for ours, theirs in answers), answers
    assert {ours for ours, _ in answers} == {True, False}


def test_importing_the_solver_patches_nothing_and_init_taichi_installs_the_patches():
    """Taichi's private front end is patched by an explicit call only (taichi_patches.install,
    from init_taichi), never by an import."""
    import subprocess
    import sys

    code = (
        "import taichi_sls.solver.simulation as s\n"
        "from taichi_sls.backend import ti\n"
        "k = ti.lang.kernel_impl\n"
        "patched = lambda: getattr(k._inside_class, '_sls_memo', False)\n"
        "assert not patched(), 'patched on import'\n"
        "s.init_taichi()\n"
        "assert patched(), 'not patched by init_taichi'\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-2000:]
