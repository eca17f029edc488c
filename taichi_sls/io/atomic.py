"""Atomic file writes: a reader sees the old file or the complete new one, never a torn one.

The temporary file sits in the same folder (so ``os.replace`` is a rename on one filesystem),
dot-prefixed (globs for outputs never pick it up), with pid and a random token (concurrent
writers never collide)."""

from __future__ import annotations

import contextlib
import csv
import os
import secrets
from collections.abc import Iterator
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temp path next to ``path``; on success move it over ``path``, else delete it."""
    final = Path(path)
    final.parent.mkdir(parents=True, exist_ok=True)
    # Same folder so os.replace is a rename on one filesystem (atomic); dot-prefixed so globs
    # for outputs never pick it up; pid + random token so concurrent writers never collide.
    tmp = final.parent / f".{final.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp"
    try:
        yield tmp
        os.replace(tmp, final)
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` so readers see either the old file or the complete new one."""
    with atomic_path(path) as tmp:
        # os.open with mode 0o666 honours the umask (tempfile would force 0600 on outputs).
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        with os.fdopen(fd, "wb") as f:
            f.write(data)


def atomic_write_text(path: str | os.PathLike[str], text: str) -> None:
    """UTF-8 text version of :func:`atomic_write_bytes`."""
    atomic_write_bytes(path, text.encode("utf-8"))


def write_rows(
    path: str | os.PathLike[str], rows: list[dict], columns: list[str] | None = None
) -> None:
    """``rows`` as a CSV at ``path`` (columns: the first row's keys, or ``columns``), written
    whole or not at all."""
    with atomic_path(path) as tmp, tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns or list(rows[0]))
        w.writeheader()
        w.writerows(rows)
