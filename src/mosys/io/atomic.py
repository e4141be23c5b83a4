"""Atomic output: a crash or a bad input never leaves a half-written file at the final path."""

from __future__ import annotations

import contextlib
import os
import re
import secrets
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from glob import escape as glob_escape
from pathlib import Path
from typing import TYPE_CHECKING

from mosys.errors import InputError, raise_if_stopped
from mosys.files import changed_inputs, note_rewritten, output_problem

if TYPE_CHECKING:  # for the annotation only: verbs that write text (index) start without h5py
    import h5py

PARTIAL_NAME_BYTES = 120  # of the final name kept in the partial's: NAME_MAX is 255 bytes
_PARTIAL_TAIL = re.compile(r"\.(\d+)\.[0-9a-f]{8}\.partial")  # what follows .NAME: PID, RANDOM


@dataclass
class _Outputs:
    """What a command has written so far: its partial files held back, (partial, path), and
    the folders made for them."""

    partials: list[tuple[Path, Path]] = field(default_factory=list)
    folders: list[Path] = field(default_factory=list)


_held: _Outputs | None = None  # the running command's; None: each write is renamed at once


@contextmanager
def outputs_together() -> Iterator[None]:
    """One command's outputs, all or none: within the block every ``write_atomically`` writes
    its partial file and holds it back; when the block ends they are renamed onto their paths
    together, and if it raises (a later output failing, a signal made an exception), or a
    stop signal was received (``errors.raise_if_stopped``), every partial is removed, and every
    folder made for them, and no output changes."""
    global _held
    outer, _held = _held, _Outputs()
    held, renamed = _held, False
    try:
        yield
        raise_if_stopped()  # a stop whose exception a library swallowed: none are renamed
        changed = changed_inputs() if held.partials else []
        if changed:  # made from the file as it was, the outputs would look newer than it is
            raise InputError(
                f"{changed[0]}: changed while this command ran (it read the file as it was "
                "before); nothing written: run it again"
            )
        for partial, path in held.partials:
            try:
                os.replace(partial, path)
            except OSError as error:
                raise InputError(f"{path}: cannot write it: {error.strerror or error}") from None
        renamed = True
    finally:
        for partial, _ in held.partials:
            with contextlib.suppress(OSError):  # never written, or not ours to remove
                partial.unlink()
        if not renamed:
            _remove_empty(held.folders)
        _held = outer


def _missing_folders(folder: Path) -> list[Path]:
    """``folder`` and its parents that do not exist yet, deepest first."""
    missing = []
    for candidate in (folder, *folder.parents):
        if candidate.exists():
            break
        missing.append(candidate)
    return missing


def _remove_empty(folders: list[Path]) -> None:
    """Remove those of ``folders`` that are empty, deepest first."""
    for folder in sorted(folders, key=lambda folder: len(folder.parts), reverse=True):
        with contextlib.suppress(OSError):
            folder.rmdir()


def write_atomically(
    path: str | Path, write: Callable[[Path], None], saves_opened_file: bool = False
) -> None:
    """Call ``write(partial)`` on a hidden sibling path, then rename it onto ``path`` (within
    ``outputs_together``, when the command ends).

    The rename is atomic on POSIX file systems; on any exception the partial file is removed and
    ``path`` is left as it was. The partial path is this call's own (``.NAME.PID.RANDOM.partial``,
    NAME cut short if long), so that two writers of one path at once (parallel jobs, tests)
    never rename a file the other is still writing: the last rename wins, whole. InputError
    naming ``path``, before anything is written, where it is no file name, an existing
    directory or special file, or a file this command read (``files.output_problem``); and for
    a write the system refuses (a folder that cannot be made, no room, a name too long).
    ``saves_opened_file``: the editor's Save, writing the file it opened, which may be an input
    of the command and is written at once.
    """
    problem = output_problem(path, may_replace_input=saves_opened_file)
    if problem:
        raise InputError(f"{os.fspath(path) or repr('')}: cannot write it: {problem}")
    path = Path(path)
    name = path.name.encode("utf-8", "surrogateescape")[:PARTIAL_NAME_BYTES]
    short = name.decode("utf-8", "ignore")
    partial = path.with_name(f".{short}.{os.getpid()}.{secrets.token_hex(4)}.partial")
    _remove_abandoned_partials(path.with_name(f".{short}"))
    made = _missing_folders(path.parent.absolute())
    held_back = False  # the partial handed to ``outputs_together``, which renames or removes it
    written = False
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write(partial)
        if _held is not None and not saves_opened_file:
            _held.partials.append((partial, path))
            _held.folders += made
            held_back = True
        else:
            os.replace(partial, path)
            if saves_opened_file:
                note_rewritten(path)
        written = True
    except OSError as error:  # the partial's name in the system's message means nothing to a user
        raise InputError(f"{path}: cannot write it: {error.strerror or error}") from None
    finally:
        if not held_back:  # OSError: never made (a read-only file system refuses even that)
            with contextlib.suppress(OSError):
                partial.unlink()
        if not written:
            _remove_empty(made)


def _remove_abandoned_partials(stem: Path) -> None:
    """Remove the partial files ``STEM.PID.RANDOM.partial`` of writers that no longer run: a
    process killed outright (SIGKILL, a crash) cannot remove its own, and they stayed beside
    the output for good (a 2 MB one beside the car's table). A partial whose writer runs, or
    may (a process of another user), is left alone."""
    with contextlib.suppress(OSError):
        for candidate in stem.parent.glob(f"{glob_escape(stem.name)}.*.*.partial"):
            own = _PARTIAL_TAIL.fullmatch(candidate.name[len(stem.name) :])
            pid = int(own.group(1)) if own else os.getpid()  # another output's, if no match
            if pid != os.getpid() and not _process_runs(pid):
                with contextlib.suppress(OSError):
                    candidate.unlink()


def _process_runs(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's: it runs
        return True
    return True


def write_hdf5_atomically(path: str | Path, fill: Callable[[h5py.File], None]) -> None:
    """Write the HDF5 file that ``fill(h5)`` makes to ``path`` atomically. The file is built in
    memory (HDF5's core driver, nothing on disk) and written as plain bytes: a write the system
    refuses (no room left) is then an OSError like any other file's, where HDF5 failing to
    flush a file on disk crashed the process as it tore the file's objects down."""
    import h5py

    name = f"mosys-{secrets.token_hex(8)}.h5"  # HDF5 knows an open file by its name
    with h5py.File(name, "w", driver="core", backing_store=False) as h5:
        fill(h5)
        h5.flush()
        image = h5.id.get_file_image()
    write_atomically(path, lambda partial: partial.write_bytes(image))


def write_text_atomically(path: str | Path, text: str, saves_opened_file: bool = False) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically (``write_atomically``)."""
    write_atomically(
        path, lambda partial: partial.write_text(text, encoding="utf-8"), saves_opened_file
    )
