"""A faster Taichi front end: each function's source read, and each excerpt of its debug info
formatted, once per process.

Taichi's Python front end (AST -> IR) runs for every kernel on every process start, offline
cache or not, and for each AST node it visits it formats a source excerpt (file, line and the
code underlined, wrapped by ``textwrap``) into the node's debug info. A ``ti.func`` is parsed
and visited again at each call site, and a ``ti.static`` loop visits its body once per
iteration, so the same excerpt is formatted many times: that formatting was about half of the
front end's time, and reading the function's source again (``inspect`` tokenizes its module
to find it) at each call site a quarter of the rest (docs/compile.md). This memoizes both: an
excerpt by the node's position in its source, the source by the function. The texts are the
same, byte for byte, as Taichi's, so error messages do not change; a source file edited while
the process runs is read as it was at its first compile (as Python's own ``linecache``).

It wraps the private ``ASTTransformerContext.get_pos_info`` and the ``getsourcelines`` and
``getsourcefile`` that ``taichi.lang.kernel_impl`` calls; where a backend has no such names (or
has its own cache, as taichi-forge has for the excerpts) it leaves them.
``TAICHI_SLS_FRONT_END_CACHE=0`` leaves Taichi as it is.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

from taichi_sls.backend import ti

ENV = "TAICHI_SLS_FRONT_END_CACHE"
_excerpts: dict[tuple, str] = {}


def _key(ctx: Any, node: Any) -> tuple:
    # everything Taichi's text reads: the function (by file and first line: the header names
    # it), its indent, the node's span, and for a multi-line For/While/If where its body starts
    body = getattr(node, "body", None)
    start = body[0].lineno if isinstance(body, list) and body else None
    return (
        ctx.file,
        ctx.lineno_offset,
        ctx.indent,
        len(ctx.src),
        type(node),
        node.lineno,
        node.col_offset,
        getattr(node, "end_lineno", None),
        getattr(node, "end_col_offset", None),
        start,
    )


def _memo_by_function(read: Callable[[Any], Any]) -> Callable[[Any], Any]:
    cache: dict[Any, Any] = {}

    def memo(func: Any) -> Any:
        if func not in cache:
            cache[func] = read(func)
        got = cache[func]
        return (list(got[0]), got[1]) if isinstance(got, tuple) else got  # a list it may edit

    memo._sls_memo = True  # type: ignore[attr-defined]
    return memo


def _memo_sources() -> bool:
    kernel_impl = getattr(getattr(ti, "lang", None), "kernel_impl", None)
    names = ("getsourcelines", "getsourcefile")
    if kernel_impl is None or not all(callable(getattr(kernel_impl, n, None)) for n in names):
        return False
    for n in names:
        if not getattr(getattr(kernel_impl, n), "_sls_memo", False):
            setattr(kernel_impl, n, _memo_by_function(getattr(kernel_impl, n)))
    return True


def install() -> bool:
    """Memoize the front end's sources and source excerpts (once per process). False where
    neither was applied."""
    if os.environ.get(ENV, "1") == "0":
        return False
    sources = _memo_sources()
    return _memo_excerpts() or sources


def _memo_excerpts() -> bool:
    try:
        ctx_cls = ti.lang.ast.ast_transformer_utils.ASTTransformerContext
        original = ctx_cls.get_pos_info
    except AttributeError:
        return False
    if getattr(original, "_sls_memo", False) or hasattr(ctx_cls, "_format_source_info"):
        return getattr(original, "_sls_memo", False)  # installed, or the fork has its own

    def get_pos_info(self: Any, node: Any) -> str:
        key = _key(self, node)
        text = _excerpts.get(key)
        if text is None:
            text = _excerpts[key] = original(self, node)
        return text

    get_pos_info._sls_memo = True  # type: ignore[attr-defined]
    ctx_cls.get_pos_info = get_pos_info
    return True
