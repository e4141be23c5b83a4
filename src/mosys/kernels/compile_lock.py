"""Cold compilation once per machine, not once per parallel job.

numba compiles a ``cache=True`` function on its first call (or at import, given a signature)
unless its machine code is in the cache. Two jobs that start together with a cold cache — the
pipeline's first two ``mosys dp`` jobs, say — would both compile the same kernels, each for
seconds, and both write the same cache entries. So every top-level compilation that misses the
cache (in memory and on disk) runs under a machine-wide file lock, one per function (numba
caches each function in files of its own, so that two jobs compiling different kernels still
run side by side), and looks at the cache again once it holds the lock: a job that waited loads
what the other compiled. Cache hits take no lock (numba reports a compilation only after a miss:
the ``numba:compile`` event), nor do the compilations of callees within one (which therefore
never wait: no deadlock), nor functions without a cache.

The lock of function F of module M is ``mosys-compile-M.F.lock`` in ``$NUMBA_CACHE_DIR`` if set
(the cache it guards), else in ``$XDG_CACHE_HOME/mosys`` (``~/.cache/mosys``); without ``fcntl``
(Windows), or if the file cannot be opened or locked, compilation goes unguarded, as numba alone
does it.

Within ``deferring()`` a top-level compilation whose lock another process holds raises
``CompilationBusyError`` instead of waiting, so that a job loading many kernels (``mosys dp``) can
compile others first and come back to it: two such jobs started together on a cold cache then
compile different kernels side by side rather than one after the other.

Within ``cache_only()`` a top-level compilation that misses the cache raises
``ColdCompilationError`` instead (the job server imports kernel modules ahead of its jobs, and
must not spend seconds compiling one while its jobs wait to be reported).

While numba holds its compiler lock it calls back into Python through ctypes (LLVM's object
cache, for a kernel loaded from the cache as for one compiled), and ctypes swallows an
exception raised there. The command line therefore keeps a stop signal that arrives then
(``compiling``) for the moment numba lets go of the lock, where it is raised
(``serialize_cold_compilation``).
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from mosys.errors import raise_if_stopped

_installed = False
_cache_only = False
_deferring = False
_cold_seconds = 0.0  # this process's time in top-level compilations after cache misses
_depth = 0  # top-level compilations under the lock in progress; numba's compiler lock guards it


def compiling() -> bool:
    """Whether numba holds its compiler lock in this thread (compiling a kernel, loading one
    from its cache, or setting itself up): a stop signal's exception raised now could be raised
    inside numba's ctypes callbacks, which swallow it. The command line keeps the stop instead,
    and it is raised where numba lets go of the lock (``serialize_cold_compilation``)."""
    if not _installed:  # numba not set up by this module: nothing would raise the kept stop
        return False
    from numba.core.compiler_lock import global_compiler_lock  # imported by the installation

    return global_compiler_lock.is_locked()


def compiling_cold() -> bool:
    """Whether numba is compiling a kernel that missed its cache (seconds, or a minute before
    a first 3-D search)."""
    return _depth > 0


def _tell_a_person(function: str) -> None:
    """On a terminal, say what the minute of silence that follows is (a fresh install's first
    3-D search printed nothing for a minute)."""
    if sys.stderr.isatty():
        print(
            "mosys: compiling numba's kernels on this machine, once (they are kept in numba's "
            f"cache; {function} first): seconds, or about a minute before a first 3-D search",
            file=sys.stderr,
            flush=True,
        )


_listeners: list[Callable[[str], None]] = [_tell_a_person]  # told of the first such compilation


class ColdCompilationError(Exception):
    """A compilation that missed numba's cache within ``cache_only()``."""


class CompilationBusyError(Exception):
    """A compilation that missed numba's cache within ``deferring()`` while another process
    compiles the same function."""


@contextlib.contextmanager
def deferring() -> Iterator[None]:
    """Within: a compilation that would wait for another process's lock raises
    ``CompilationBusyError`` (naming the function) instead; nothing has been compiled then."""
    global _deferring
    serialize_cold_compilation()
    before, _deferring = _deferring, True
    try:
        yield
    finally:
        _deferring = before


@contextlib.contextmanager
def cache_only() -> Iterator[None]:
    """Within: a cached function that is not in numba's cache raises ``ColdCompilationError`` where
    it would be compiled (at its first call, or at import given a signature)."""
    global _cache_only
    serialize_cold_compilation()
    before, _cache_only = _cache_only, True
    try:
        yield
    finally:
        _cache_only = before


def cold_compilation_seconds() -> float:
    """Seconds this process has spent compiling functions that missed numba's cache (and
    waiting for another process's compilation of them): what a timed run subtracts, since a
    fresh install's first BSR search spent a minute of its 'search' time compiling."""
    return _cold_seconds


def on_first_cold_compilation(listener: Callable[[str], None]) -> None:
    """Call ``listener(function)`` when this process first compiles a function that missed
    the cache (once; the command line says a minute of silence is compilation)."""
    _listeners.append(listener)


def lock_path(function: str) -> Path:
    """The machine-wide lock file of compilations of ``function`` (``module.name``; see the
    module docstring)."""
    name = f"mosys-compile-{function}.lock"
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"]) / name
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "mosys" / name


@contextlib.contextmanager
def machine_lock(function: str, wait: bool = True) -> Iterator[None]:
    """Hold the compilation lock of ``function`` (an exclusive ``flock``; released when the
    process ends, too); ``wait`` False: raise ``CompilationBusyError`` if another process holds
    it."""
    try:
        import fcntl

        path = lock_path(function)
        path.parent.mkdir(parents=True, exist_ok=True)
        handle = open(path, "a")  # noqa: SIM115 (closed below, after the lock is released)
    except (ImportError, OSError):
        yield
        return
    with handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
        except BlockingIOError:
            raise CompilationBusyError(function) from None
        except OSError:  # a file system without locks
            yield
            return
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def serialize_cold_compilation() -> None:
    """Make numba's dispatchers compile under ``machine_lock`` after a cache miss (see the
    module docstring). Idempotent; call it before the first ``@njit(cache=True)`` function of
    the process is compiled or loaded."""
    global _installed
    if _installed:
        return
    from numba.core import event
    from numba.core.caching import NullCache
    from numba.core.compiler_lock import global_compiler_lock
    from numba.core.dispatcher import Dispatcher

    class CacheMissError(Exception):
        """Raised at a probed cache miss, before numba compiles anything."""

    class MissProbe(event.Listener):
        """While armed, stops the compilation that follows a cache miss."""

        armed = False

        def on_start(self, _event: event.Event) -> None:
            if self.armed:
                self.armed = False
                raise CacheMissError

        def on_end(self, _event: event.Event) -> None:
            pass

    class StopAtRelease(event.Listener):
        """Raises a stop kept while numba held its compiler lock (``compiling``) as the main
        thread's outermost hold of it ends: outside numba's callbacks, before the command
        goes on."""

        def on_start(self, _event: event.Event) -> None:
            pass

        def on_end(self, _event: event.Event) -> None:
            main = threading.current_thread() is threading.main_thread()
            if main and not global_compiler_lock.is_locked():
                raise_if_stopped()

    probe = MissProbe()
    event.register("numba:compile", probe)
    event.register("numba:compiler_lock", StopAtRelease())
    compile_signature = Dispatcher.compile

    def compile_once(self: Dispatcher, sig):
        global _cold_seconds, _depth
        with global_compiler_lock:
            if _depth or isinstance(self._cache, NullCache):
                return compile_signature(self, sig)
            armed, probe.armed = probe.armed, True  # armed: when loading needs another
            try:
                return compile_signature(self, sig)  # in memory or on disk: no lock
            except CacheMissError:
                if _cache_only:
                    name = f"{self.py_func.__module__}.{self.__name__}"
                    raise ColdCompilationError(name) from None
            finally:
                probe.armed = armed
            function = f"{self.py_func.__module__}.{self.py_func.__qualname__}"
            while _listeners:
                _listeners.pop(0)(function)
            began = time.perf_counter()
            try:
                with machine_lock(function, wait=not _deferring):
                    _depth += 1
                    try:  # loads it if another process compiled it while this one waited
                        return compile_signature(self, sig)
                    finally:
                        _depth -= 1
            finally:
                _cold_seconds += time.perf_counter() - began

    compile_once.__doc__ = compile_signature.__doc__
    Dispatcher.compile = compile_once
    _installed = True
