"""Atomic output: a crash or a bad input never leaves a half-written file at the final path."""

from __future__ import annotations

import contextlib
import os
import secrets
from collections.abc import Callable
from pathlib import Path

from mosys.errors import InputError
from mosys.files import output_problem

PARTIAL_NAME_BYTES = 120  # of the final name kept in the partial's: NAME_MAX is 255 bytes


def write_atomically(
    path: str | Path, write: Callable[[Path], None], replaces_input: bool = False
) -> None:
    """Call ``write(partial)`` on a hidden sibling path, then rename it onto ``path``.

    The rename is atomic on POSIX file systems; on any exception the partial file is removed and
    ``path`` is left as it was. The partial path is this call's own (``.NAME.PID.RANDOM.partial``,
    NAME cut short if long), so that two writers of one path at once (parallel jobs, tests)
    never rename a file the other is still writing: the last rename wins, whole. InputError
    naming ``path``, before anything is written, where it is no file name, an existing
    directory or special file, or (unless ``replaces_input``: an editor saving the file it
    opened) a file this command read (``files.output_problem``); and for a write the system
    refuses (a folder that cannot be made, no room, a name too long).
    """
    problem = output_problem(path)
    if problem and not (replaces_input and problem.startswith("it is an input")):
        raise InputError(f"{os.fspath(path) or repr('')}: cannot write it: {problem}")
    path = Path(path)
    name = path.name.encode("utf-8", "surrogateescape")[:PARTIAL_NAME_BYTES]
    short = name.decode("utf-8", "ignore")
    partial = path.with_name(f".{short}.{os.getpid()}.{secrets.token_hex(4)}.partial")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write(partial)
        os.replace(partial, path)
    except OSError as error:  # the partial's name in the system's message means nothing to a user
        raise InputError(f"{path}: cannot write it: {error.strerror or error}") from None
    finally:
        with contextlib.suppress(FileNotFoundError, NotADirectoryError):
            partial.unlink()


def write_text_atomically(path: str | Path, text: str, replaces_input: bool = False) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically (``write_atomically``)."""
    write_atomically(
        path, lambda partial: partial.write_text(text, encoding="utf-8"), replaces_input
    )
