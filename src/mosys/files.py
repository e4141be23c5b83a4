"""What a command may read and write. An input must be a regular file: a FIFO blocks its read
forever, and a directory gives the reader's own confusing message. An output must be a file
name whose folder can hold it, and never a file the same command read (``mosys run -o`` its own
script would replace it): the readers record what they read while a command runs
(``command_files``), and ``io.atomic`` asks ``output_problem`` before it writes. An input that
changes while the command runs (a spec edited during a build) stops its outputs from being
written (``changed_inputs``): they would be made from the file as it was, and be newer than the
file as it is, so that Snakemake would never make them again."""

from __future__ import annotations

import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path

# the real paths this command has read, each with its identity when first read (device, inode,
# size, modification time); None: not recording
_read: dict[str, tuple[int, int, int, int]] | None = None


@contextmanager
def command_files() -> Iterator[None]:
    """Record, for the block (one command), every input file the readers open, so that no
    output replaces one of them."""
    global _read
    outer, _read = _read, {}
    try:
        yield
    finally:
        _read = outer


def _kind(mode: int) -> str:
    """What a file that is not regular is, in words."""
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "not a regular file"


def input_problem(path: str | Path) -> str | None:
    """What ``path`` is if it exists but is not a regular file ("a directory", "a FIFO", ...),
    else None, having recorded it as read by this command. A missing or unreadable path is
    None: the reader's own error names it."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):  # missing, unreadable, or a NUL in the name
        return None
    if not stat.S_ISREG(mode):
        return _kind(mode)
    if _read is not None:
        _read.setdefault(os.path.realpath(path), _identity(os.stat(path)))
    return None


def _identity(status: os.stat_result) -> tuple[int, int, int, int]:
    return status.st_dev, status.st_ino, status.st_size, status.st_mtime_ns


def changed_inputs() -> list[str]:
    """The input files this command has read that have changed since (edited, replaced or
    removed), relative to the working directory where they are within it: an output made
    from them would be out of date as it is written."""
    changed = []
    for path, identity in (_read or {}).items():
        try:
            now = _identity(os.stat(path))
        except OSError:
            now = None
        if now != identity:
            relative = os.path.relpath(path)
            changed.append(path if relative.startswith("..") else relative)
    return changed


def note_rewritten(path: str | Path) -> None:
    """``path``, an input of this command, was written by the command itself (the editor's
    Save): its new state is the one it stands for."""
    real = os.path.realpath(path)
    if _read is not None and real in _read:
        with suppress(OSError):
            _read[real] = _identity(os.stat(real))


def output_problem(path: str | Path, may_replace_input: bool = False) -> str | None:
    """Why ``path`` cannot be written as a whole new file, or None: no file name in it, a
    folder in its way that is a file, an existing directory or special file (a FIFO, a
    device: replacing it would destroy it), or (unless ``may_replace_input``) a file this
    command read."""
    text = os.fspath(path)
    if not text or text.endswith(os.sep) or Path(text).name in ("", ".", ".."):
        return "expected a file name to write"
    path = Path(text)
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None
    except OSError:  # not a directory on the way, too long, ...: the write says which
        mode = None
    if mode is not None and not stat.S_ISREG(mode):
        return f"it is {_kind(mode)}, not a file mosys may replace"
    for folder in path.absolute().parents:
        if folder.exists():
            if not folder.is_dir():
                return f"{folder} is a file, not a folder"
            break
    if not may_replace_input and _read is not None and os.path.realpath(path) in _read:
        return "it is an input of this command; write the output elsewhere"
    return None
