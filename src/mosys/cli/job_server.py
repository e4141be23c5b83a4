"""``mosys job-server SOCKET``: one process that imports mosys's libraries once and runs each
``mosys`` command handed to it (``mosys.job_client``) in a fork of itself.

A pipeline job's own work is often a few tens of milliseconds (a pendulum DP, a script run);
starting Python with numpy, h5py, numba, matplotlib and pandas and loading numba's cached
kernels took 0.7-1.4 s of every job. Snakemake starts this server when a run begins
(``workflow/rules/common.smk``, ``onstart``), puts its socket in ``MOSYS_JOB_SERVER`` for the
jobs, and stops it when the run ends; a user can do the same by hand.

A job runs in a fork exactly as it would in its own process: its arguments, working directory,
environment and standard streams are the client's, and its exit code is sent back. numba read
its ``NUMBA_*`` variables when the server imported it: the fork re-reads them (so each job has
its own ``NUMBA_NUM_THREADS``), and the server declines (the client then runs the command
itself) when any other of them, the interpreter or the mosys package differs from the server's,
since the kernels' caches were set up at import. The server never runs a kernel itself: a numba
thread pool started before a fork would not survive it.

It stops on SIGTERM, SIGINT or SIGHUP and when the process that started it exits (its running
jobs are sent the signal that stopped it, SIGTERM when its parent exited, and their exit codes
reported as they end, for ``STOP_WAIT_S`` at most), after
``--idle`` seconds without a job, or, once no job runs, when its socket file is removed or
replaced; a job whose client goes away is sent SIGTERM. A job whose server has gone (killed
meanwhile) sends its exit code to its client itself. A request is declined when a file of the
mosys package has changed since the server started (``source_stamp``): a fork would run the
code as it was, and Snakemake would take its output as made by the code as it is.
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import importlib
import json
import os
import random
import select
import selectors
import shlex
import signal
import socket
import stat
import struct
import sys
import time
import traceback

from mosys.cli.verb import Verb, positive_number_problem
from mosys.job_client import FORWARDED_SIGNALS, forward, package_directory

# What jobs import, loaded here one at a time while the server is idle, in this order (the
# first jobs of a run need the first ones): the command line, numpy, h5py, numba and mosys's
# kernels (their cached code is loaded by each job), then what plots and tables use.
PRELOADED = (
    "mosys.cli",
    "numpy",
    "h5py",
    "numba",
    "mosys.ssc.generate",
    "mosys.animation.runner",
    "matplotlib",
    "PIL.Image",
    "mosys.plots.controller",
    "mosys.plots.script",
    "mosys.plots.free_swing",
    "pandas",
    "mosys.ssc.quality",
    "mosys.paper_tables.pendulum",
)
# Variables numba reads once, at import: a job must see the server's values.
NUMBA_PREFIX = "NUMBA_"
PER_JOB_VARIABLES = ("NUMBA_NUM_THREADS",)  # each job's own: numba's config re-read in the fork
PRELOAD_TRIES = 3  # tries of a module that needed compiling, one after each job's end
POLL_S = 1.0  # how often the server looks for its parent and its idle time
REQUEST_TIMEOUT_S = 2.0  # a client sends its request as it connects; others wait meanwhile
SOCKET_PATH_BYTES = 107  # a Unix socket's path, its NUL aside (sockaddr_un)
STOP_WAIT_S = 10.0  # after a stop signal, how long the server waits for its jobs to end

_started_with: tuple | None = None  # source_stamp() when the server started


def source_stamp() -> tuple:
    """The mosys package's Python files as they are on disk: (path, mtime_ns, size) of each,
    in order. A job forked from the server runs the code the server imported; a file edited
    since it started (during a build) must be run from disk, by a process of its own."""
    root = package_directory()
    stamp = []
    for folder, folders, files in os.walk(root):
        folders[:] = sorted(name for name in folders if name != "__pycache__")
        for name in sorted(files):
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                with contextlib.suppress(OSError):  # removed meanwhile: the stamp differs
                    status = os.stat(path)
                    stamp.append((path, status.st_mtime_ns, status.st_size))
    return tuple(stamp)


def serve(path: str, idle_seconds: float) -> None:
    """Listen on the Unix socket ``path`` (replacing a stale one) and run each request in a
    fork until told to stop, importing ``PRELOADED`` one module at a time while no request
    waits: a job that comes early starts at once and imports what is not loaded yet itself."""
    global _started_with
    os.close(os.pidfd_open(os.getpid()))  # Linux 5.3 or later: else fail now, not per job
    _started_with = source_stamp()
    wakeup, woken = socket.socketpair()  # a stop signal wakes the selector at once
    wakeup.setblocking(False)
    signal.set_wakeup_fd(wakeup.fileno(), warn_on_full_buffer=False)
    stopping: list[int] = []
    for number in FORWARDED_SIGNALS:  # before the socket exists: a stop is never missed
        signal.signal(number, lambda received, frame: stopping.append(received))
    listener = _listening_socket(path)
    ours = _file_identity(path)
    _log(f"listening on {path}")
    selector = selectors.DefaultSelector()
    selector.register(listener, selectors.EVENT_READ, ("listener", 0))
    selector.register(woken, selectors.EVENT_READ, ("signal", 0))
    try:
        _serve_requests(selector, listener, os.getppid(), idle_seconds, stopping, path, ours)
    finally:
        listener.close()
        if _file_identity(path) == ours:  # not another server's, nor gone
            os.unlink(path)


def _file_identity(path: str) -> tuple[int, int] | None:
    """The device and inode of the file at ``path`` (None if there is none): whether the
    socket there is still this server's."""
    try:
        status = os.lstat(path)
    except OSError:
        return None
    return status.st_dev, status.st_ino


def _unready_path(path: str) -> str:
    """Where the server's socket is bound before it is renamed to ``path``."""
    return os.path.join(os.path.dirname(path), f".mosys-job-server-{os.getpid()}")


def _listening_socket(path: str) -> socket.socket:
    """A Unix socket listening at ``path`` (replacing a stale one). It is bound and listening
    under a name of its own first, then renamed: a client that sees ``path`` can connect (a
    socket bound at ``path`` refuses connections until ``listen``)."""
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    unready = _unready_path(path)
    with contextlib.suppress(FileNotFoundError):
        os.unlink(unready)
    try:
        listener.bind(unready)
        listener.listen(64)
        os.replace(unready, path)
    except BaseException:
        listener.close()
        with contextlib.suppress(FileNotFoundError):
            os.unlink(unready)
        raise
    return listener


def _serve_requests(
    selector, listener, parent: int, idle_seconds: float, stopping, path: str, ours
) -> None:
    """The server's loop: accept requests and fork their jobs, report each job's exit code to
    its client, SIGTERM a job whose client went away, preload while idle; until a stop signal
    or the parent's exit (then, taking no more requests, it SIGTERMs its jobs and reports their
    codes as they end, for ``STOP_WAIT_S`` at most), ``idle_seconds`` without a job, or, once
    its jobs have ended, its socket's leaving ``path`` (removed or replaced: no client can
    reach it any more)."""
    jobs: dict[int, tuple[socket.socket, int]] = {}  # pid -> (its client's connection, pidfd)
    preloads = Preloads(PRELOADED)
    last_activity = time.monotonic()
    deadline = None  # once told to stop: until when the running jobs may end and be reported
    while True:
        if stopping or os.getppid() != parent:
            if not jobs or (deadline is not None and time.monotonic() > deadline):
                break
            if deadline is None:  # take no more jobs; those running are told to stop, and
                # their codes reach their clients (gone at once, it left them to say 'the job
                # server ended before job N did', exit 1, for a job stopped by Ctrl-C)
                selector.unregister(listener)
                # with the signal that stopped the server: Ctrl-C reaches the server and the
                # jobs at once, and a SIGTERM from here made them stop as if terminated (exit
                # 143, no word in their logs) rather than say 'interrupted' and exit 130
                for pid in jobs:
                    forward(pid, stopping[0] if stopping else signal.SIGTERM)
                deadline = time.monotonic() + STOP_WAIT_S
        elif not jobs and time.monotonic() - last_activity > idle_seconds:
            break
        elif not jobs and _file_identity(path) != ours:
            _log(f"{path} is no longer this server's socket: stopping")
            break
        preloading = bool(preloads.pending) and deadline is None  # not once told to stop
        events = selector.select(0.0 if preloading else POLL_S)
        if not events and preloading:
            if not preloads.import_next() and not preloads.warming_up:
                preloads.warming_up = True
                with contextlib.suppress(OSError):  # no fork: the jobs compile it all
                    pid, pidfd = _fork_warm_up(selector)
                    selector.register(pidfd, selectors.EVENT_READ, ("warmed up", pid))
            continue
        for key, _ in events:
            kind, pid = key.data
            if kind == "listener":
                connection, _ = listener.accept()
                started = _start_job(connection, selector)
                if started is None:
                    connection.close()
                    continue
                pid, pidfd = started
                jobs[pid] = (connection, pidfd)
                selector.register(pidfd, selectors.EVENT_READ, ("ended", pid))
                selector.register(connection, selectors.EVENT_READ, ("client", pid))
            elif kind == "ended":
                connection, pidfd = jobs.pop(pid)
                _, status = os.waitpid(pid, 0)
                code = os.waitstatus_to_exitcode(status)  # -N: killed by signal N
                code = code if code >= 0 else 128 - code
                # logged first: a client that has its code finds the job's end in the log
                _log(f"job {pid} ended: exit {code}")
                _send_line(connection, f"exit {code}")
                selector.unregister(pidfd)
                os.close(pidfd)
                with contextlib.suppress(KeyError):  # unless its client hung up before
                    selector.unregister(connection)
                connection.close()
                preloads.job_ended()
            elif kind == "warmed up":
                _, status = os.waitpid(pid, 0)
                _log(f"warm-up {pid} ended: exit {os.waitstatus_to_exitcode(status)}")
                selector.unregister(key.fileobj)
                os.close(key.fd)
                preloads.job_ended()
            elif kind == "signal":
                key.fileobj.recv(256)  # drained; the loop's test sees the stop
            elif kind == "client" and pid in jobs:  # readable: the client hung up
                selector.unregister(key.fileobj)
                forward(pid, signal.SIGTERM)
            last_activity = time.monotonic()
    for pid in jobs:
        forward(pid, signal.SIGTERM)


class Preloads:
    """Modules imported one at a time while the server is idle. The server never compiles: a
    module whose import would compile a kernel (not in numba's cache yet) is left out, and tried
    again after a job or the warm-up (``_fork_warm_up``) ends, ``PRELOAD_TRIES`` times at
    most."""

    def __init__(self, names: tuple[str, ...]):
        self.pending = list(names)
        self.failures: dict[str, int] = {}
        self.waiting: list[str] = []  # to try again after the next job ends
        self.warming_up = False  # whether the warm-up has been forked

    def import_next(self) -> bool:
        """Import the next pending module; False if it needs compiling first."""
        from mosys.kernels.compile_lock import ColdCompilationError, cache_only

        name = self.pending.pop(0)
        with cache_only():
            try:
                importlib.import_module(name)
            except ColdCompilationError as cold:
                _log(f"not preloaded yet: {name} ({cold} is not in numba's cache)")
                self.failures[name] = self.failures.get(name, 0) + 1
                if self.failures[name] < PRELOAD_TRIES:
                    self.waiting.append(name)
                return False
        if not self.pending:
            _log(f"preloaded {', '.join(n for n in PRELOADED if n in sys.modules)}")
        return True

    def job_ended(self) -> None:
        self.pending += self.waiting  # the job may have compiled what they need
        self.waiting.clear()


def _fork_warm_up(selector) -> tuple[int, int]:
    """Fork a process that imports ``PRELOADED``, compiling into numba's cache the kernels
    their imports compile, beside the jobs (a job that needs one meanwhile waits for it under
    the compile lock, then loads it); its pid and a pidfd readable when it ends."""
    pid = _fork()
    if pid == 0:  # never returns
        code = 1
        try:
            _leave_server(selector)
            for name in PRELOADED:
                importlib.import_module(name)
            code = 0
        except BaseException:
            traceback.print_exc()
        finally:
            sys.stdout.flush()
            os._exit(code)
    _log(f"warm-up {pid} started: compiling what the preloads need")
    return pid, os.pidfd_open(pid)


def _fork() -> int:
    """``os.fork()``, the child with the default action for each of ``FORWARDED_SIGNALS`` (a
    stop stops it) before it can receive one: they are blocked across the fork, so that one sent
    to the child at once (a client forwards its signals as soon as it has the job's pid) waits
    for the default action rather than reaching the server's handlers, which only note a stop
    in a list the child never reads."""
    before = signal.pthread_sigmask(signal.SIG_BLOCK, FORWARDED_SIGNALS)
    try:
        pid = os.fork()
        if pid == 0:
            for number in FORWARDED_SIGNALS:
                signal.signal(number, signal.SIG_DFL)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)
    return pid


def _leave_server(selector) -> None:
    """In a fork: close the server's sockets and descriptors (its listener, clients, pidfds and
    signal wake-up), which are not the fork's to use."""
    for key in list(selector.get_map().values()):
        os.close(key.fd)
    os.close(signal.set_wakeup_fd(-1))


def _log(line: str) -> None:
    """A line of the server's log (its standard output), stamped with the wall-clock time."""
    now = time.time()
    stamp = time.strftime("%H:%M:%S", time.localtime(now)) + f".{int(now % 1 * 1000):03d}"
    text = f"{stamp} {line}".encode("utf-8", "backslashreplace").decode("utf-8")  # argv's bytes
    with contextlib.suppress(OSError):  # a log that cannot be written loses a line, not the server
        print(text, flush=True)


def _send_line(connection: socket.socket, line: str) -> None:
    with contextlib.suppress(OSError):  # the client went away: its job ended or was told to
        connection.sendall(f"{line}\n".encode())


def _receive_request(connection: socket.socket) -> tuple[dict, list[int]]:
    """The client's request and the descriptors of its standard streams."""
    connection.settimeout(REQUEST_TIMEOUT_S)
    data, fds, _, _ = socket.recv_fds(connection, 1 << 16, 3)
    try:
        if len(data) < 4:
            raise OSError("short request")
        (length,) = struct.unpack(">I", data[:4])
        body = data[4:]
        while len(body) < length:
            chunk = connection.recv(length - len(body))
            if not chunk:
                raise OSError("truncated request")
            body += chunk
        connection.settimeout(None)
        request = json.loads(body)  # ValueError, or RecursionError for a deeply nested body
        if not _well_formed(request, fds):
            raise ValueError("malformed request")
    except Exception:  # the descriptors it sent are the server's to close
        for fd in fds:
            os.close(fd)
        raise
    return request, fds


def _well_formed(request, fds: list[int]) -> bool:
    """Whether ``request`` has the fields ``mosys.job_client.request_bytes`` sends, of their
    types, and one descriptor per stream it names."""
    return (
        isinstance(request, dict)
        and isinstance(request.get("argv"), list)
        and all(isinstance(arg, str) for arg in request["argv"])
        and all(isinstance(request.get(key), str) for key in ("cwd", "python", "package"))
        and isinstance(request.get("env"), dict)
        and all(isinstance(k, str) and isinstance(v, str) for k, v in request["env"].items())
        and isinstance(request.get("streams"), list)
        and sorted(request["streams"]) == request["streams"]
        and set(request["streams"]) <= {0, 1, 2}
        and len(request["streams"]) == len(fds)
    )


def decline_reason(request: dict) -> str | None:
    """Why this server cannot run the request as its own process would (None: it can)."""
    if request["python"] != sys.executable:
        return f"interpreter {request['python']}, not {sys.executable}"
    if request["package"] != package_directory():
        return f"mosys at {request['package']}, not {package_directory()}"
    env = request["env"]
    for name in sorted(set(env) | set(os.environ)):
        imported = name.startswith(NUMBA_PREFIX) and name not in PER_JOB_VARIABLES
        if imported and env.get(name) != os.environ.get(name):
            return f"{name}={env.get(name)!r}, not {os.environ.get(name)!r}"
    if _started_with is not None:
        changed = _changed_source(_started_with, source_stamp())
        if changed:
            return f"{changed} changed since the server started"
    parallel = sys.modules.get("numba.np.ufunc.parallel")
    if parallel is not None and parallel._is_initialized:
        return "numba's thread pool started in the server: a fork would inherit it broken"
    return None


def _changed_source(before: tuple, now: tuple) -> str | None:
    """The first of the package's files added, removed or changed between two stamps
    (``source_stamp``), or None."""
    if before == now:
        return None
    old, new = {path: rest for path, *rest in before}, {path: rest for path, *rest in now}
    for path in sorted(set(old) | set(new)):
        if old.get(path) != new.get(path):
            return os.path.relpath(path, os.path.dirname(package_directory()))
    return None


def _client_gone(connection: socket.socket) -> bool:
    """Whether the client has hung up: once its request is sent it only waits, so anything to
    read is the end of its connection."""
    readable, _, _ = select.select([connection], [], [], 0)
    if not readable:
        return False
    try:
        return connection.recv(1, socket.MSG_PEEK) == b""
    except OSError:
        return True


def _start_job(connection, selector) -> tuple[int, int] | None:
    """Fork a job for the request on ``connection``: its pid and a pidfd that becomes readable
    when it ends; None if the request is unreadable or declined, or the fork failed (the client
    then runs it)."""
    try:
        request, fds = _receive_request(connection)
    except Exception:  # noqa: BLE001 - whatever a request holds, the server goes on serving
        return None
    try:
        if _client_gone(connection):  # it gave up waiting and runs the command itself
            return None
        reason = decline_reason(request)
        if reason is not None:
            _log(f"declined: mosys {shlex.join(request['argv'])}: {reason}")  # it runs itself
            _send_line(connection, f"declined {reason}")
            return None
        try:
            pid = _fork()
        except OSError:
            return None
        if pid == 0:  # the job: it keeps none of the server's sockets, and never returns
            server, code = os.getppid(), 1
            try:
                _leave_server(selector)
                code = _run_job(request, fds)
            finally:
                if os.getppid() != server:  # the server is gone: tell the client its code
                    _send_line(connection, f"exit {code}")
                os._exit(code)
        pidfd = os.pidfd_open(pid)
        _send_line(connection, f"started {pid}")
        _log(f"job {pid} started: mosys {shlex.join(request['argv'])}")
        return pid, pidfd
    finally:
        for fd in fds:
            os.close(fd)


def _run_job(request: dict, fds: list[int]) -> int:
    """In the fork: become the client's process and run ``main(argv)``; its exit code as
    Python's own exit would give it."""
    try:
        _become_client(request, fds)
    except Exception as error:  # noqa: BLE001 - e.g. its working directory is gone
        with contextlib.suppress(OSError):
            os.write(2, f"mosys: the job server could not run this job: {error}\n".encode())
        return 1
    code = _exit_code(importlib.import_module("mosys.cli").main, request["argv"])
    with contextlib.suppress(BaseException):
        atexit._run_exitfuncs()
        sys.stdout.flush()
        sys.stderr.flush()
    return code


def _become_client(request: dict, fds: list[int]) -> None:
    """Take the client's standard streams (``fds``, /dev/null for those it has not), working
    directory, environment (numba's settings re-read from it) and arguments, and Python's own
    Ctrl-C (KeyboardInterrupt; ``_fork`` gave the other stop signals their default action)."""
    signal.signal(signal.SIGINT, signal.default_int_handler)
    null = os.open(os.devnull, os.O_RDWR)
    for fd in (0, 1, 2):
        os.dup2(fds[request["streams"].index(fd)] if fd in request["streams"] else null, fd)
    for fd in (null, *fds):
        os.close(fd)
    os.chdir(request["cwd"])
    os.environ.clear()
    os.environ.update(request["env"])
    sys.stdin = open(0, closefd=False)  # noqa: SIM115 (the job's own streams, never closed)
    sys.stdout = open(1, "w", buffering=1 if os.isatty(1) else -1, closefd=False)  # noqa: SIM115
    sys.stderr = open(2, "w", buffering=1, errors="backslashreplace", closefd=False)  # noqa: SIM115
    sys.argv = ["mosys", *request["argv"]]
    random.seed()  # as a new process would be
    if "numba" in sys.modules:  # numba read NUMBA_NUM_THREADS at import: read the job's
        from numba.core import config

        config.reload_config()  # allowed: no thread pool has started in this process


def _exit_code(main, argv: list[str]) -> int:
    """``main(argv)``'s exit code as ``sys.exit(main())`` would make it."""
    try:
        result = main(argv)
    except SystemExit as exit_:
        result = exit_.code
    except KeyboardInterrupt:
        return 130
    except BaseException:
        traceback.print_exc()
        return 1
    if result is None or isinstance(result, int):
        return result or 0
    print(result, file=sys.stderr)
    return 1


def _arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("socket", help="path of the Unix socket to listen on")
    parser.add_argument(
        "--idle",
        type=float,
        default=3600.0,
        help="stop after this many seconds without a job (default 3600)",
    )


def _check(args: argparse.Namespace) -> str | None:
    """Usage errors: a bad --idle; a socket path in no folder, longer than a Unix socket's
    path may be (itself, or the name it is bound at first, ``_unready_path``), naming a file
    that is not a socket (a stale socket is replaced; anything else would be destroyed), or
    where a server already answers."""
    folder = os.path.dirname(args.socket) or "."
    if not os.path.isdir(folder):
        return f"{args.socket}: expected a path in an existing folder ({folder})"
    if len(os.fsencode(args.socket)) > SOCKET_PATH_BYTES:
        return f"{args.socket}: a socket's path is at most {SOCKET_PATH_BYTES} bytes"
    unready = _unready_path(args.socket)
    if len(os.fsencode(unready)) > SOCKET_PATH_BYTES:
        return (
            f"{args.socket}: its folder's path is too long: the server binds the socket first "
            f"as {unready} ({len(os.fsencode(unready))} bytes; a socket's path is at most "
            f"{SOCKET_PATH_BYTES})"
        )
    with contextlib.suppress(OSError):
        if not stat.S_ISSOCK(os.lstat(args.socket).st_mode):
            return f"{args.socket} exists and is not a socket; not replaced"
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as probe:
            probe.connect(args.socket)  # answered: not stale
            return f"a job server is already listening on {args.socket}"
    return positive_number_problem("idle", args.idle)


def _job_server(args: argparse.Namespace) -> None:
    serve(args.socket, args.idle)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)  # at once: unloading what it preloaded took the interpreter 0.5 s


VERB = Verb(
    "job-server",
    "fork each job's mosys command from one warm process",
    _arguments,
    _job_server,
    _check,
)
