"""The ``mosys`` command's side of the job server (``mosys.cli.job_server``): when
``MOSYS_JOB_SERVER`` names a server's socket, hand the command to it and wait for its exit
status, instead of importing numpy, numba, h5py, matplotlib and pandas in this process.

Standard library only, so that a delegated command starts in a few tens of milliseconds.
Whatever goes wrong before the server has started the job (no socket, no server behind it, a
request it declines) returns ``None``: the caller then runs the command in its own process as it
always did, so the server can only ever save time. SIGINT, SIGTERM and SIGHUP sent to this
process are passed on to the job (held until it has started), and its exit status becomes this
one's.

The exchange, on a Unix stream socket: the client sends a 4-byte big-endian length and that many
bytes of JSON ``{"argv", "cwd", "env", "python", "package", "streams"}`` with its standard
streams' descriptors attached (SCM_RIGHTS); the server answers one line, ``started PID`` or
``declined REASON``, and after ``started`` one more, ``exit CODE``, when the job ends.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import struct
import sys

SERVER_VARIABLE = "MOSYS_JOB_SERVER"
FORWARDED_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
CONNECT_TIMEOUT_S = 120.0  # to connect and be answered (the server answers between imports)


def package_directory() -> str:
    """The directory of the mosys package this process imports (server and client must agree)."""
    return os.path.dirname(os.path.abspath(__file__))


def open_streams() -> list[int]:
    """Which of the standard streams 0, 1, 2 are open descriptors (a job may have none)."""
    streams = []
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            continue
        streams.append(fd)
    return streams


def request_bytes(argv: list[str], streams: list[int]) -> bytes:
    """The length-prefixed JSON request for ``argv`` from this process."""
    body = json.dumps(
        {
            "argv": argv,
            "cwd": os.getcwd(),
            "env": dict(os.environ),
            "python": sys.executable,
            "package": package_directory(),
            "streams": streams,
        }
    ).encode()
    return struct.pack(">I", len(body)) + body


def read_line(connection: socket.socket) -> str | None:
    """One ``\\n``-terminated line from the server, or None if it closed first."""
    data = b""
    while not data.endswith(b"\n"):
        chunk = connection.recv(256)
        if not chunk:
            return None
        data += chunk
    return data.decode().strip()


def forward(job: int, number: int) -> None:
    """Send signal ``number`` on to the job (which may have just ended)."""
    with contextlib.suppress(ProcessLookupError):
        os.kill(job, number)


def delegate(argv: list[str]) -> int | None:
    """Run ``mosys argv`` in the job server named by ``MOSYS_JOB_SERVER``: its exit code, or
    None if there is no server to take it (run it here). A signal that comes before the job has
    started waits for it (then it is passed on), or, if the server does not take the command,
    is delivered to this process again before it runs the command itself."""
    path = os.environ.get(SERVER_VARIABLE)
    if not path:
        return None
    pending: list[int] = []
    job = 0  # the job's pid once the server has started it

    def on_signal(number: int, frame: object) -> None:
        if job:
            forward(job, number)
        else:
            pending.append(number)

    previous = {number: signal.signal(number, on_signal) for number in FORWARDED_SIGNALS}
    connection = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    connection.settimeout(CONNECT_TIMEOUT_S)
    try:
        connection.connect(path)
        streams = open_streams()
        socket.send_fds(connection, [request_bytes(argv, streams)], streams)
        answer = read_line(connection)
    except OSError:
        answer = None
    if answer is None or not answer.startswith("started "):
        connection.close()  # declined (another environment or interpreter) or gone: run here
        for number, handler in previous.items():
            signal.signal(number, handler)
        for number in pending:
            os.kill(os.getpid(), number)
        return None
    job = int(answer.split()[1])
    for number in pending:
        forward(job, number)
    connection.settimeout(None)  # a job may take hours
    try:
        answer = read_line(connection)
    except OSError:
        answer = None
    finally:
        connection.close()
    if answer is None or not answer.startswith("exit "):
        print(f"mosys: the job server ({path}) ended before job {job} did", file=sys.stderr)
        return 1
    return int(answer.split()[1])
