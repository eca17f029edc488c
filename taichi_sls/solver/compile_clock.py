"""The time this process spends compiling Taichi kernels, counted wherever it happens.

A kernel compiles on its first call with a new set of template arguments, which may come
long after a simulation's warm-up (the settle phase, the unheated baseline, the hybrid
hand-over, Taichi's own field <-> NumPy copies). So the clock wraps the two places every
compilation passes through: ``Kernel.materialize`` (the Python front end: AST -> Taichi IR,
which runs on every process start, offline cache or not, with the field layout compiled on the
first) and each new kernel's first launch, in which Taichi compiles its IR (or loads it from
the offline cache, which holds LLVM modules) and the LLVM JIT turns it into machine code. That
first launch also runs the kernel once, which the clock cannot tell apart: it counts it as
compiling, so the figure is an upper bound (a warm-up launch does little work).

Taichi has no public API for this, so the hooks wrap private names of upstream Taichi 1.7; on
another backend ``available()`` is False and the summary's compile time is NaN (not measured).
"""

from __future__ import annotations

import math
import time
from typing import Any

from taichi_sls.backend import NAME, ti

_seconds = {"front": 0.0, "back": 0.0, "cpu": 0.0}
_count = {"kernels": 0}
_pending: dict[int, Any] = {}  # kernels materialized but not yet compiled, by id


def _install() -> bool:
    if NAME != "taichi":  # the wrapped internals are upstream 1.7's; the forks changed them
        return False
    try:
        kernel_cls = ti.lang.kernel_impl.Kernel
        materialize, launch_kernel = kernel_cls.materialize, kernel_cls.launch_kernel
    except AttributeError:
        return False
    if getattr(materialize, "_sls_clock", False):
        return True

    def timed_materialize(self: Any, key: Any = None, *args: Any, **kwargs: Any) -> Any:
        if key is not None and key in self.compiled_kernels:  # every launch passes here
            return materialize(self, key, *args, **kwargs)
        before = dict(self.compiled_kernels)
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            return materialize(self, key, *args, **kwargs)
        finally:
            _seconds["front"] += time.perf_counter() - t0
            _seconds["cpu"] += time.process_time() - c0
            for k, t_kernel in self.compiled_kernels.items():
                if k not in before:
                    _count["kernels"] += 1
                    _pending[id(t_kernel)] = t_kernel

    def timed_launch_kernel(self: Any, t_kernel: Any, *args: Any) -> Any:
        if _pending.get(id(t_kernel)) is not t_kernel:  # launched before: compiled
            return launch_kernel(self, t_kernel, *args)
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            return launch_kernel(self, t_kernel, *args)
        finally:
            _seconds["back"] += time.perf_counter() - t0
            _seconds["cpu"] += time.process_time() - c0
            del _pending[id(t_kernel)]

    timed_materialize._sls_clock = True  # type: ignore[attr-defined]
    kernel_cls.materialize = timed_materialize
    kernel_cls.launch_kernel = timed_launch_kernel
    return True


_AVAILABLE = _install()


def available() -> bool:
    """Whether this backend's compilation can be timed."""
    return _AVAILABLE


def seconds() -> float:
    """Seconds spent compiling kernels in this process so far (front end + back end)."""
    return _seconds["front"] + _seconds["back"]


def reading() -> dict[str, float]:
    """The clock now: ``compile_s`` (wall), its ``front_end_s`` and ``back_end_s``, the CPU time
    of the process's threads while compiling (``compile_cpu_s``: steadier on a shared machine),
    ``kernels``."""
    return {
        "compile_s": seconds() if _AVAILABLE else math.nan,
        "front_end_s": _seconds["front"],
        "back_end_s": _seconds["back"],
        "compile_cpu_s": _seconds["cpu"],
        "kernels": _count["kernels"],
    }


def since(start: dict[str, float]) -> dict[str, float]:
    """The compilation between ``start`` (a :func:`reading`) and now."""
    now = reading()
    return {k: now[k] - start[k] for k in now}
