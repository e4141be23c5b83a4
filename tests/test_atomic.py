"""Atomic output (``io.atomic``): two writers of one path at once each finish whole, and the file
left is one of theirs, never a mix; a writer that fails leaves neither its partial file nor a
change at the path; a command's outputs appear together or not at all, also when a later one
fails, the disk is full or a signal stops it."""

from __future__ import annotations

import contextlib
import errno
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from mosys.cli import main, stop_signals_raise
from mosys.errors import InputError, Stopped
from mosys.io.atomic import (
    outputs_together,
    write_atomically,
    write_hdf5_atomically,
    write_text_atomically,
)


def slow_writer(letter: str, started: threading.Barrier):
    def write(partial: Path) -> None:
        with partial.open("w") as out:
            started.wait()  # both writers are inside write() at once
            for _ in range(20):
                out.write(letter * 1000)
                out.flush()
                time.sleep(0.001)

    return write


def test_two_writers_of_one_path_at_once_leave_one_whole_file(tmp_path):
    path = tmp_path / "table.csv"
    started = threading.Barrier(2)
    errors = []

    def run(letter: str) -> None:
        try:
            write_atomically(path, slow_writer(letter, started))
        except Exception as error:  # noqa: BLE001 - reported below
            errors.append(error)

    threads = [threading.Thread(target=run, args=(letter,)) for letter in "AB"]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not errors
    assert path.read_text() in ("A" * 20_000, "B" * 20_000)
    assert [p.name for p in tmp_path.iterdir()] == ["table.csv"]


def test_a_failed_write_leaves_the_old_file_and_no_partial(tmp_path):
    path = tmp_path / "plot.png"
    path.write_text("old")

    def fail(partial: Path) -> None:
        partial.write_text("half")
        raise ValueError("bad input")

    with pytest.raises(ValueError, match="bad input"):
        write_atomically(path, fail)
    assert path.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["plot.png"]


def no_room(real_method):
    """``real_method`` (a Path writer) failing as on a full disk."""

    def write(self: Path, *args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(self))

    return write


def test_an_hdf5_file_is_built_in_memory_and_a_full_disk_is_one_clear_error(tmp_path, monkeypatch):
    """HDF5 flushing a file on a full disk crashed the process at teardown (exit 139) and could
    leave its partial file: the file is now made in memory and written as bytes."""
    path = tmp_path / "x.h5"

    def fill(h5: h5py.File) -> None:
        h5["x"] = np.arange(5.0)
        h5["x"].make_scale("x")
        h5.attrs["kind"] = "test"

    write_hdf5_atomically(path, fill)
    with h5py.File(path, "r") as h5:
        np.testing.assert_array_equal(h5["x"][()], np.arange(5.0))
        assert h5.attrs["kind"] == "test" and h5["x"].is_scale
    monkeypatch.setattr(Path, "write_bytes", no_room(Path.write_bytes))
    with pytest.raises(InputError) as error:
        write_hdf5_atomically(tmp_path / "y.h5", fill)
    assert str(error.value) == f"{tmp_path / 'y.h5'}: cannot write it: No space left on device"
    assert sorted(tmp_path.iterdir()) == [path]


def test_a_commands_outputs_appear_together_or_not_at_all(tmp_path):
    first, second = tmp_path / "t.csv", tmp_path / "t.md"
    with outputs_together():
        write_text_atomically(first, "csv")
        assert not first.exists()  # held back until the command ends
        write_text_atomically(second, "md")
    assert (first.read_text(), second.read_text()) == ("csv", "md")
    first.write_text("old")
    with pytest.raises(ValueError, match="the table failed"), outputs_together():
        write_text_atomically(first, "new")
        write_text_atomically(tmp_path / "new" / "folders" / "t.md", "md")
        raise ValueError("the table failed")
    assert first.read_text() == "old"
    # nothing new: the folders made for the outputs are gone with them
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv", "t.md"]


def test_a_full_disk_under_a_tables_second_file_leaves_neither(
    pendulum, tmp_path, monkeypatch, capsys
):
    """Every table verb writes a CSV and then a Markdown file: the CSV stayed when the second
    could not be written."""
    real_write_text = Path.write_text

    def write_text(self: Path, *args, **kwargs):
        if ".md." in self.name:  # the Markdown file's partial
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(self))
        return real_write_text(self, *args, **kwargs)

    monkeypatch.setattr(Path, "write_text", write_text)
    out = tmp_path / "out"
    out.mkdir()
    argv = ["pendulum-table", pendulum / "controllers" / "A.h5", "--dynamics",
            pendulum / "dynamics" / "link1.py", "--csv", out / "t.csv",
            "--md", out / "t.md"]  # fmt: skip
    assert main([str(arg) for arg in argv]) == 2
    assert capsys.readouterr().err.strip() == (
        f"mosys: {out / 't.md'}: cannot write it: No space left on device"
    )
    assert not list(out.iterdir())


def test_sigterm_stops_a_command_and_leaves_no_partial(tmp_path):
    handler = signal.getsignal(signal.SIGTERM)
    with pytest.raises(Stopped) as stopped, stop_signals_raise(), outputs_together():
        write_text_atomically(tmp_path / "a.txt", "written, held back")
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)  # the handler raises at the next instruction
    assert stopped.value.code == 128 + signal.SIGTERM
    assert not list(tmp_path.iterdir())
    assert signal.getsignal(signal.SIGTERM) == handler  # restored


def test_ctrl_c_is_one_line_and_exit_130(tmp_path, monkeypatch, capsys):
    import mosys.io.info

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(mosys.io.info, "describe_file", interrupted)
    (tmp_path / "x.h5").write_bytes(b"")
    assert main(["info", str(tmp_path / "x.h5")]) == 130
    assert capsys.readouterr().err == "mosys: interrupted; nothing written\n"


@pytest.mark.parametrize("number", [signal.SIGINT, signal.SIGTERM])
def test_a_stop_whose_exception_a_library_swallowed_still_writes_nothing(
    pendulum, tmp_path, monkeypatch, capsys, number
):
    """numba compiling a kernel calls back through ctypes, which swallows an exception raised
    there ('Exception ignored on calling ctypes callback function'): a Ctrl-C or SIGTERM
    arriving then was lost, and the command wrote its outputs and exited 0. The stop is
    recorded as it arrives, so the command still writes nothing and exits with the signal's
    code."""
    import mosys.paper_tables.pendulum as table

    real = table.write_pendulum_table

    def swallowing(*args, **kwargs):
        with contextlib.suppress(KeyboardInterrupt, Stopped):  # as the ctypes callback does
            os.kill(os.getpid(), number)
            time.sleep(5)  # the handler raises at the next instruction
        return real(*args, **kwargs)

    monkeypatch.setattr(table, "write_pendulum_table", swallowing)
    out = tmp_path / "out"
    argv = ["pendulum-table", pendulum / "controllers" / "A.h5", "--dynamics",
            pendulum / "dynamics" / "link1.py", "--csv", out / "t.csv",
            "--md", out / "t.md"]  # fmt: skip
    assert main([str(arg) for arg in argv]) == 128 + number
    assert not out.exists()
    from mosys.errors import stop_received

    assert stop_received() is None  # forgotten as main returns: the next command is not stopped
    said = "mosys: interrupted; nothing written\n" if number == signal.SIGINT else ""
    assert capsys.readouterr().err == said


def test_an_error_after_a_stop_is_the_stop(tmp_path, monkeypatch, capsys):
    """numba stopped while compiling raised RuntimeError('no compiled object yet') and the
    command died with its traceback, exit 1: after a stop, any error is the stop's."""
    import mosys.io.info

    def stopped_then_broken(*args, **kwargs):
        with contextlib.suppress(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(5)
        raise RuntimeError("no compiled object yet")

    monkeypatch.setattr(mosys.io.info, "describe_file", stopped_then_broken)
    (tmp_path / "x.h5").write_bytes(b"")
    assert main(["info", str(tmp_path / "x.h5")]) == 130
    assert capsys.readouterr().err == "mosys: interrupted; nothing written\n"
    monkeypatch.setattr(mosys.io.info, "describe_file", lambda *a, **k: 1 / 0)
    with pytest.raises(ZeroDivisionError):  # without a stop, an error is still a fault
        main(["info", str(tmp_path / "x.h5")])


def test_a_read_only_folder_is_named_not_the_hidden_partial(tmp_path, monkeypatch):
    """The partial could not be made, and removing it (in the clean-up) raised EROFS, which
    replaced the message: 'mosys: [Errno 30] Read-only file system: .../.A.h5.123.ab.partial'."""
    real_open = Path.open

    def read_only(self: Path, *args, **kwargs):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(self))

    def unlink(self: Path, missing_ok=False):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(self))

    monkeypatch.setattr(Path, "open", read_only)
    monkeypatch.setattr(Path, "unlink", unlink)
    for together in (False, True):
        held = outputs_together() if together else contextlib.nullcontext()
        with pytest.raises(InputError) as error, held:
            write_text_atomically(tmp_path / "a.txt", "text")
        assert str(error.value) == f"{tmp_path / 'a.txt'}: cannot write it: Read-only file system"
    monkeypatch.setattr(Path, "open", real_open)


def test_a_stop_during_a_kernels_compilation_waits_for_its_end(monkeypatch, capsys):
    """Raised inside numba's compilation, the exception went through a ctypes callback, which
    printed 'Exception ignored ...' with a traceback and lost it: a first stop is kept while
    numba holds its compiler lock and raised as it lets go, a second stops at once."""
    from numba.core.compiler_lock import global_compiler_lock

    from mosys.errors import forget_stops, stop_received
    from mosys.kernels import compile_lock

    forget_stops()
    # as while a kernel missing from the cache compiles, numba holding its compiler lock
    monkeypatch.setattr(compile_lock, "_depth", 1)
    held_to_the_end = slept = False
    try:
        with pytest.raises(KeyboardInterrupt), stop_signals_raise(), global_compiler_lock:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.2)  # the handler has run by now, and raised nothing
            assert stop_received() == signal.SIGINT
            assert capsys.readouterr().err == "mosys: stopping when numba's compilation ends\n"
            held_to_the_end = True
        assert held_to_the_end  # raised as the lock was let go, not inside
        with pytest.raises(KeyboardInterrupt), stop_signals_raise(), global_compiler_lock:
            os.kill(os.getpid(), signal.SIGINT)  # a second Ctrl-C: at once, lock or not
            time.sleep(5)
            slept = True
        assert not slept
    finally:
        forget_stops()  # else this process's next outputs would be held back as stopped


def test_a_stop_inside_numbas_callbacks_stops_the_command_as_numba_lets_go(tmp_path):
    """A SIGTERM that came while numba loaded a kernel from its cache (a served job stopped in
    its first second) was raised inside LLVM's object-cache callback, where ctypes swallowed it:
    the command ran on (here, for good, into a module that sleeps). The stop is now kept while
    numba holds its compiler lock and raised as it lets go. Here it arrives inside that very
    callback, at the first kernel the command loads or compiles (llvmlite's module-level ctypes
    hook, ``executionengine._notify_c_hook``, replaced before numba makes its engine)."""
    script = tmp_path / "stopped_in_callback.py"
    script.write_text(
        textwrap.dedent(
            """
            import os, signal, sys
            from llvmlite.binding import executionengine

            sent = []

            def notify(engine, data):  # LLVM's callback, one stop arriving inside it
                if not sent:
                    sent.append(os.kill(os.getpid(), signal.SIGTERM))
                return engine._raw_object_cache_notify(data)

            executionengine._notify_c_hook = executionengine._ObjectCacheNotifyFunc(notify)
            from mosys.cli import main

            sys.exit(main(sys.argv[1:]))
            """
        )
    )
    sleeper = tmp_path / "sleeper.py"
    sleeper.write_text("import time\n\ntime.sleep(600)\n")
    argv = [sys.executable, str(script), "plot", "free-swing", "--dynamics", str(sleeper)]
    done = subprocess.run(
        [*argv, "-o", str(tmp_path / "x.png")], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 128 + signal.SIGTERM, done.stderr
    assert "Exception ignored" not in done.stderr
    assert not (tmp_path / "x.png").exists()


def test_a_partial_left_by_a_killed_writer_goes_with_the_next_write(tmp_path):
    """A writer killed outright (SIGKILL) cannot remove its partial file: one stayed beside a
    plot after a rebuild. The next write of that output removes the partials of writers that
    no longer run; a running writer's, and another output's, stay."""
    dead = int(subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                              capture_output=True, text=True, check=True).stdout)  # fmt: skip
    path = tmp_path / "C_portrait.png"
    abandoned = tmp_path / f".C_portrait.png.{dead}.0123abcd.partial"
    running = tmp_path / f".C_portrait.png.{os.getppid()}.89abcdef.partial"
    other = tmp_path / f".C_portrait.png.5.{dead}.0123abcd.partial"  # C_portrait.png.5's
    for partial in (abandoned, running, other):
        partial.write_bytes(b"half a plot")
    write_text_atomically(path, "a whole plot")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [path.name, running.name, other.name]
    )
