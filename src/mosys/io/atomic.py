"""Atomic output: a crash or a bad input never leaves a half-written file at the final path."""

from __future__ import annotations

import os
import secrets
from collections.abc import Callable
from pathlib import Path


def write_atomically(path: str | Path, write: Callable[[Path], None]) -> None:
    """Call ``write(partial)`` on a hidden sibling path, then rename it onto ``path``.

    The rename is atomic on POSIX file systems; on any exception the partial file is removed and
    ``path`` is left as it was. The partial path is this call's own (``.NAME.PID.RANDOM.partial``),
    so that two writers of one path at once (parallel jobs, tests) never rename a file the other
    is still writing: the last rename wins, whole.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.partial")
    try:
        write(partial)
        os.replace(partial, path)
    finally:
        partial.unlink(missing_ok=True)


def write_text_atomically(path: str | Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    write_atomically(path, lambda partial: partial.write_text(text, encoding="utf-8"))
