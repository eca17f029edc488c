"""A faster Taichi front end: each function's source read and its lines normalised, and each
excerpt of its debug info formatted, once per process.

Taichi's Python front end (AST -> IR) runs for every kernel on every process start, offline
cache or not, and for each AST node it visits it formats a source excerpt (file, line and the
code underlined, wrapped by ``textwrap``) into the node's debug info. A ``ti.func`` is parsed
and visited again at each call site, and a ``ti.static`` loop visits its body once per
iteration, so the same excerpt is formatted many times: that formatting, and reading the
function's source again (``inspect`` tokenizes its module to find it) at each call site, are
much of the front end's time (docs/record/compile.md). This memoizes both: an excerpt by the
node's position in its source, the source by the function. The texts are the same, byte for
byte, as Taichi's, so error messages do not change; a source file edited while the process
runs is read as it was at its first compile (as Python's own ``linecache``).

Two more pieces of ``textwrap`` work go the same way. Each excerpt not yet seen wraps its code
line and its caret line at 80 columns with a new ``textwrap.TextWrapper``: a line that already
fits (nearly all) comes back as itself less its trailing blanks, which :class:`_Wrapper` returns
without splitting it into words (longer lines, or ones with tabs or other whitespace, take
Taichi's path). And each call site re-normalises every line of the function's source with
``textwrap.fill``: memoized by line.

It wraps the private ``ASTTransformerContext.get_pos_info``, the ``TextWrapper`` that module
names, and the ``getsourcelines``, ``getsourcefile`` and ``textwrap`` that
``taichi.lang.kernel_impl`` calls; where a backend has no such names (or has its own cache, as
taichi-forge has for the excerpts) it leaves them. ``TAICHI_SLS_FRONT_END_CACHE=0`` leaves
Taichi as it is.
"""

from __future__ import annotations

import functools
import inspect
import linecache
import os
import sys
import textwrap
import types
from collections.abc import Callable
from typing import Any

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


def _memo_sources(ti: Any) -> bool:
    kernel_impl = getattr(getattr(ti, "lang", None), "kernel_impl", None)
    names = ("getsourcelines", "getsourcefile")
    if kernel_impl is None or not all(callable(getattr(kernel_impl, n, None)) for n in names):
        return False
    for n in names:
        if not getattr(getattr(kernel_impl, n), "_sls_memo", False):
            setattr(kernel_impl, n, _memo_by_function(getattr(kernel_impl, n)))
    return True


def install(ti: Any) -> bool:
    """Memoize the front end's sources and source excerpts of the Taichi module ``ti`` (once per
    process: installing again changes nothing; init_taichi calls it). False where none was
    applied."""
    if os.environ.get(ENV, "1") == "0":
        return False
    sources = _memo_sources(ti)
    lines = _memo_line_fill(ti)
    inside = _fast_inside_class(ti)
    return _memo_excerpts(ti) or sources or lines or inside


def _fast_inside_class(ti: Any) -> bool:
    """Taichi's ``_inside_class`` (is a ``ti.func`` or ``ti.kernel`` being decorated in a class
    body?) reads the decorating frame's current line through ``inspect.getframeinfo``, which
    finds the frame's module by scanning ``sys.modules`` (about a millisecond each: a few
    hundred decorations at import, and Taichi's ``matrix_ops`` imported inside the first
    kernel's compilation). The same line read through ``linecache`` directly, the same patterns
    matched; where it cannot be read, Taichi's own."""
    kernel_impl = getattr(getattr(ti, "lang", None), "kernel_impl", None)
    original = getattr(kernel_impl, "_inside_class", None)
    patterns = getattr(kernel_impl, "_KERNEL_CLASS_STACKFRAME_STMT_RES", None)
    position = getattr(inspect, "_get_code_position", None)
    if not callable(original) or patterns is None or not callable(position):
        return False
    if getattr(original, "_sls_memo", False):
        return True

    def inside_class(level_of_class_stackframe: int) -> bool:
        try:
            frame = sys._getframe(level_of_class_stackframe)
            lineno = position(frame.f_code, frame.f_lasti)[0] or frame.f_lineno
            filename = frame.f_code.co_filename
            line = linecache.getline(filename, lineno)
        except Exception:  # noqa: BLE001 -- Taichi's own answers (it catches everything too)
            filename, line = "", ""
        if not line:
            # a module-level decoration: the frame above is the import system's, frozen, whose
            # source inspect cannot read either (Taichi's answer, through an exception: False)
            if filename.startswith("<frozen "):
                return False
            return original(level_of_class_stackframe + 1)  # one frame deeper: this one
        first = line.strip()
        return any(pattern.match(first) for pattern in patterns)

    inside_class._sls_memo = True  # type: ignore[attr-defined]
    inside_class.original = original  # type: ignore[attr-defined]
    kernel_impl._inside_class = inside_class
    return True


_OTHER_WHITESPACE = frozenset("\t\n\x0b\x0c\r")  # TextWrapper turns these into spaces first


class _Wrapper(textwrap.TextWrapper):
    """``TextWrapper.wrap`` with its outcome for a text that fits the width: with the default
    options (which Taichi's excerpts use) such a text is one line, the text less its trailing
    spaces, or no line if it is blank (leading spaces kept on the first line)."""

    def wrap(self, text: str) -> list[str]:
        if len(text) <= self.width and _OTHER_WHITESPACE.isdisjoint(text) and self._defaults():
            body = text.rstrip(" ")
            return [body] if body else []
        return super().wrap(text)

    def _defaults(self) -> bool:
        return (
            self.drop_whitespace
            and not self.fix_sentence_endings
            and not self.initial_indent
            and not self.subsequent_indent
            and self.max_lines is None
        )


def _memo_line_fill(ti: Any) -> bool:
    """``textwrap.fill`` as ``kernel_impl`` calls it (each source line, at every call site),
    memoized; the ``TextWrapper`` of the excerpts replaced by :class:`_Wrapper`."""
    kernel_impl = getattr(getattr(ti, "lang", None), "kernel_impl", None)
    utils = getattr(getattr(getattr(ti, "lang", None), "ast", None), "ast_transformer_utils", None)
    wrapped = isinstance(getattr(utils, "TextWrapper", None), type) and issubclass(
        utils.TextWrapper, textwrap.TextWrapper
    )
    if wrapped and utils.TextWrapper is not _Wrapper:
        utils.TextWrapper = _Wrapper
    module = getattr(kernel_impl, "textwrap", None)
    if module is textwrap:
        proxy = types.ModuleType("textwrap")
        proxy.__dict__.update(textwrap.__dict__)
        fill = functools.lru_cache(maxsize=None)(textwrap.fill)
        proxy.fill = lambda text, **kw: fill(text, **kw)
        proxy._sls_memo = True
        kernel_impl.textwrap = proxy
        module = proxy
    return wrapped or getattr(module, "_sls_memo", False)


def _memo_excerpts(ti: Any) -> bool:
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
