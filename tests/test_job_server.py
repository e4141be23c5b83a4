"""The job server (``mosys job-server``, README "The job server"): a command handed to it runs
as it would in its own process (arguments, working directory, environment, streams, exit code,
files written bit for bit the same); signals reach the job; a job whose client dies is stopped;
a request the server cannot serve as its own process would runs in the client instead; and the
server stops cleanly. Every command here is a real ``mosys`` process started the way Snakemake
starts one, and the server's log says which of them it ran."""

from __future__ import annotations

import os
import re
import signal
import socket
import struct
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import h5py
import numpy as np
import pytest

from mosys.cli import job_server

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "controllers" / "pendulum" / "A.ssc"


class Server:
    def __init__(self, socket_path: Path, log: Path, process: subprocess.Popen):
        self.socket, self.log, self.process = socket_path, log, process

    def jobs(self) -> list[tuple[str, str]]:
        """(pid, "started: mosys ..." or "ended: exit N") for each job line of the log."""
        return re.findall(r"job (\d+) (started: .*|ended: .*)$", self.log.read_text(), re.M)

    def declined(self) -> list[str]:
        """The commands the server declined, each 'mosys ...: reason', from its log."""
        return re.findall(r"declined: (.*)$", self.log.read_text(), re.M)

    def wait_for_end(self, pid: str, timeout: float = 20.0) -> str:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            ended = [line for job, line in self.jobs() if job == pid and line.startswith("ended")]
            if ended:
                return ended[0]
            time.sleep(0.02)
        raise AssertionError(f"job {pid} did not end: {self.log.read_text()}")


def environment(**extra: str) -> dict[str, str]:
    bin_dir = str(Path(sys.executable).parent)
    env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ.get("PATH", ""), **extra)
    env.pop("MOSYS_JOB_SERVER", None)
    return env


def start_server(directory: Path, **env: str) -> Server:
    socket_path, log = directory / "server.sock", directory / "server.log"
    with open(log, "w") as stream:
        process = subprocess.Popen(
            [sys.executable, "-m", "mosys.cli", "job-server", str(socket_path), "--idle", "600"],
            stdout=stream,
            stderr=subprocess.STDOUT,
            env=environment(**env),
        )
    deadline = time.monotonic() + 20.0
    while not socket_path.exists() and time.monotonic() < deadline:
        time.sleep(0.01)
    assert socket_path.exists(), log.read_text()
    return Server(socket_path, log, process)


@pytest.fixture
def server(tmp_path) -> Iterator[Server]:
    server = start_server(tmp_path)
    yield server
    server.process.terminate()
    server.process.wait(timeout=20)


def mosys(server: Server | None, *argv: str, cwd: Path, **env: str) -> subprocess.CompletedProcess:
    """``mosys argv`` as its own process (the command line a job runs), handed to ``server``."""
    extra = {"MOSYS_JOB_SERVER": str(server.socket)} if server else {}
    return subprocess.run(
        [sys.executable, "-m", "mosys.command", *argv],
        cwd=cwd,
        capture_output=True,
        text=True,
        env={**environment(**env), **extra},
        timeout=120,
    )


def test_a_served_job_runs_in_the_clients_directory_with_its_streams_and_exit_code(
    server, tmp_path
):
    (tmp_path / "a.txt").write_text("a")
    done = mosys(server, "index", "a.txt", "-o", "listed.txt", cwd=tmp_path)
    assert (done.returncode, done.stdout, done.stderr) == (0, "", "")
    assert (tmp_path / "listed.txt").read_text() == "a.txt\n"  # relative to the client's cwd
    failed = mosys(server, "index", "missing.txt", "-o", "none.txt", cwd=tmp_path)
    assert failed.returncode == 2
    assert failed.stderr == "mosys: cannot index missing files: missing.txt\n"
    assert not (tmp_path / "none.txt").exists()
    version = mosys(server, "--version", cwd=tmp_path)
    assert (version.returncode, version.stdout) == (0, "mosys 0.1.0\n")
    usage = mosys(server, "dp", cwd=tmp_path)  # argparse's own exit 2 on stderr
    assert usage.returncode == 2 and "the following arguments are required" in usage.stderr
    started = [line for _, line in server.jobs() if line.startswith("started")]
    assert started == [
        "started: mosys index a.txt -o listed.txt",
        "started: mosys index missing.txt -o none.txt",
        "started: mosys --version",
        "started: mosys dp",
    ]
    # the server logs a job's end when it reaps the job, which can be after the client has its
    # exit code: wait for each line rather than read the log once
    jobs = [pid for pid, line in server.jobs() if line.startswith("started")]
    assert [server.wait_for_end(pid) for pid in jobs] == [
        "ended: exit 0",
        "ended: exit 2",
        "ended: exit 0",
        "ended: exit 2",
    ]


def test_a_served_dp_writes_the_same_table_and_sees_the_clients_environment(
    server, tmp_path, pendulum
):
    args = ("dp", str(SPEC), "--dynamics-dir", str(pendulum / "dynamics"), "--quiet")
    alone = mosys(None, *args, "-o", "alone.h5", cwd=tmp_path)
    served = mosys(server, *args, "-o", "served.h5", cwd=tmp_path, NUMBA_NUM_THREADS="1")
    assert alone.returncode == served.returncode == 0, served.stderr
    with h5py.File(tmp_path / "alone.h5") as a, h5py.File(tmp_path / "served.h5") as b:
        for name in ("value", "torque"):
            np.testing.assert_array_equal(a[name][()], b[name][()])
    refused = mosys(server, *args, "-o", "big.h5", cwd=tmp_path, MOSYS_MAX_MEMORY_GIB="1e-9")
    assert refused.returncode == 2 and "raise MOSYS_MAX_MEMORY_GIB" in refused.stderr
    assert not (tmp_path / "big.h5").exists()
    assert sum(line.startswith("started: mosys dp") for _, line in server.jobs()) == 2


@pytest.mark.slow
def test_a_served_job_compiles_on_a_cold_cache_with_its_own_thread_count(tmp_path, pendulum):
    """A compilation re-reads numba's config from the environment: the fork's must be the job's
    (NUMBA_NUM_THREADS=1 here, unset in the server) before any thread starts."""
    cache = str(tmp_path / "numba_cache")
    server = start_server(tmp_path, NUMBA_CACHE_DIR=cache)
    try:
        args = ("dp", str(SPEC), "--dynamics-dir", str(pendulum / "dynamics"), "--quiet")
        done = mosys(
            server,
            *args,
            "-o",
            "cold.h5",
            cwd=tmp_path,
            NUMBA_CACHE_DIR=cache,
            NUMBA_NUM_THREADS="1",
        )
    finally:
        server.process.terminate()
        server.process.wait(timeout=20)
    assert done.returncode == 0, done.stderr
    assert [line for _, line in server.jobs()] == [
        f"started: mosys {' '.join(args)} -o cold.h5",
        "ended: exit 0",
    ]
    assert any(Path(cache).rglob("*.nbi"))  # it compiled, into the job's cache
    # the server itself compiled nothing: it left the DP's kernels to the job, and the
    # closed-loop simulator (compiled at import, which the job never needed) to its warm-up
    log = server.log.read_text()
    assert "not preloaded yet: mosys.animation.runner" in log, log


def test_signals_reach_the_job_and_a_job_whose_client_dies_is_stopped(server, tmp_path):
    """A plot whose dynamics module sleeps as it is imported: a job that runs until told. (A
    FIFO as an input, which would block forever, is refused.)"""
    sleeper = tmp_path / "sleeper.py"
    sleeper.write_text("import time\n\ntime.sleep(600)\n")
    for kill_client in (signal.SIGTERM, signal.SIGKILL):
        known = {pid for pid, _ in server.jobs()}
        client = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "mosys.command",
                "plot",
                "free-swing",
                "--dynamics",
                str(sleeper),
                "-o",
                "x.png",
            ],
            cwd=tmp_path,
            env={**environment(), "MOSYS_JOB_SERVER": str(server.socket)},
            stderr=subprocess.PIPE,
        )
        deadline = time.monotonic() + 20.0
        while not (new := {pid for pid, _ in server.jobs()} - known):
            assert time.monotonic() < deadline, server.log.read_text()
            time.sleep(0.02)
        (job,) = new
        # the job is loading its kernels or asleep importing the module: stopped either way (in
        # the first, until 2026-12-07, a stop was lost in numba's callbacks: README, "A full
        # disk, a signal")
        time.sleep(0.3)
        client.send_signal(kill_client)
        client.wait(timeout=20)
        assert server.wait_for_end(job) == "ended: exit 143"  # SIGTERM, forwarded or sent
        if kill_client == signal.SIGTERM:
            assert client.returncode == 143  # the job's status became the client's
    assert not (tmp_path / "x.png").exists()


def served_sleeper(server: Server, directory: Path, seconds: float) -> subprocess.Popen:
    """A served job (``plot free-swing``) whose dynamics module sleeps ``seconds`` as it is
    loaded, then is found to be none (exit 2), once the server has started it; its client."""
    sleeper = directory / "sleeper.py"
    sleeper.write_text(f"import time\n\ntime.sleep({seconds})\n")
    client = subprocess.Popen(
        [sys.executable, "-m", "mosys.command", "plot", "free-swing", "--dynamics", str(sleeper)]
        + ["-o", "x.png"],
        cwd=directory,
        env={**environment(), "MOSYS_JOB_SERVER": str(server.socket)},
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 20.0
    while not server.jobs():
        assert time.monotonic() < deadline, server.log.read_text()
        time.sleep(0.02)
    return client


def test_a_job_reports_its_own_exit_code_when_the_server_is_killed(server, tmp_path):
    """The job is the server's fork and outlives it; its client used to exit 1 ("the job
    server ended before job N did") although the job went on and ended with its own code."""
    client = served_sleeper(server, tmp_path, 2)  # then it is no dynamics module: exit 2
    server.process.kill()
    server.process.wait(timeout=20)
    _, stderr = client.communicate(timeout=60)
    assert client.returncode == 2, stderr
    assert "ended before" not in stderr and "sleeper.py" in stderr


@pytest.mark.parametrize("replacement", ["", "a file"])
def test_the_server_stops_when_its_socket_is_removed_or_replaced(server, replacement):
    """No client can reach it any more: it used to run on until --idle (an hour), and on
    stopping removed whatever then had its socket's name."""
    server.socket.unlink()
    if replacement:
        server.socket.write_text(replacement)
    assert server.process.wait(timeout=20) == 0
    assert "is no longer this server's socket: stopping" in server.log.read_text()
    assert server.socket.exists() == bool(replacement)


def test_a_request_the_server_cannot_serve_runs_in_the_client(server, tmp_path):
    """numba set up its kernels' caches (NUMBA_CACHE_DIR) and their optimisation (NUMBA_OPT)
    when the server imported it: a job asking for others runs itself; so does a job whose
    server is not there."""
    (tmp_path / "a.txt").write_text("a")
    other = mosys(
        server, "index", "a.txt", "-o", "1.txt", cwd=tmp_path, NUMBA_CACHE_DIR=str(tmp_path)
    )
    unoptimised = mosys(server, "index", "a.txt", "-o", "2.txt", cwd=tmp_path, NUMBA_OPT="0")
    absent = mosys(None, "index", "a.txt", "-o", "3.txt", cwd=tmp_path, MOSYS_JOB_SERVER="/nowhere")
    for done, out in ((other, "1.txt"), (unoptimised, "2.txt"), (absent, "3.txt")):
        assert done.returncode == 0, done.stderr
        assert (tmp_path / out).read_text() == "a.txt\n"
    assert server.jobs() == []
    assert server.declined() == [  # the log says why each ran by itself
        f"mosys index a.txt -o 1.txt: NUMBA_CACHE_DIR={str(tmp_path)!r}, not None",
        "mosys index a.txt -o 2.txt: NUMBA_OPT='0', not None",
    ]


@pytest.mark.parametrize(
    "request_bytes",
    [
        b"",
        b"\x00\x00\x00\x05hello",
        b"\x00\x00\x00\x02{}",
        b"\x00\x00\x00\x0f" + b'{"argv": [1,2]}',
        b"\xff\xff\xff\xff",
        struct.pack(">I", 200_000) + b"[" * 200_000,  # json's RecursionError ended the server
    ],
    # short names: a test id holding 200,000 brackets went into PYTEST_CURRENT_TEST, past the
    # kernel's 128 KiB limit on one environment string, and every subprocess of the test failed
    # to start (E2BIG) under pytest 8.0
    ids=["empty", "short text", "not an object", "argv not text", "past the limit", "brackets"],
)
def test_a_malformed_request_is_refused_and_the_server_serves_on(server, tmp_path, request_bytes):
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as connection:
        connection.settimeout(30)
        connection.connect(str(server.socket))
        connection.sendall(request_bytes)
        connection.shutdown(socket.SHUT_WR)
        assert connection.recv(256) == b""  # closed without an answer
    (tmp_path / "a.txt").write_text("a")
    done = mosys(server, "index", "a.txt", "-o", "listed.txt", cwd=tmp_path)
    assert done.returncode == 0 and server.process.poll() is None
    started = [line for _, line in server.jobs()][:1]  # (a source edited meanwhile: declined)
    assert started == ["started: mosys index a.txt -o listed.txt"], server.log.read_text()


HUNG_UP_CLIENT = """
import socket, sys
from mosys.job_client import request_bytes
with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as connection:
    connection.connect(sys.argv[1])
    socket.send_fds(connection, [request_bytes(sys.argv[2:], [2])], [2])
"""  # sends a whole request and hangs up at once, as a client that gave up waiting does


def test_a_request_whose_client_hung_up_is_not_run(server, tmp_path):
    """A client that waited too long runs the command itself: the server, reaching its request
    late, used to run it a second time. Here a silent connection holds the server for its
    request timeout while the request's client hangs up."""
    (tmp_path / "a.txt").write_text("a")
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as silent:
        silent.connect(str(server.socket))
        time.sleep(0.2)  # the server is now waiting for the silent client's request
        argv = ["index", "a.txt", "-o", "late.txt"]
        subprocess.run(
            [sys.executable, "-c", HUNG_UP_CLIENT, str(server.socket), *argv],
            cwd=tmp_path,
            env=environment(),
            check=True,
            timeout=60,
        )
        time.sleep(job_server.REQUEST_TIMEOUT_S + 1.0)
    done = mosys(server, "index", "a.txt", "-o", "listed.txt", cwd=tmp_path)
    assert done.returncode == 0
    assert [line for _, line in server.jobs()] == [
        "started: mosys index a.txt -o listed.txt",
        "ended: exit 0",
    ]
    assert not (tmp_path / "late.txt").exists()


def test_a_second_server_on_a_live_servers_socket_is_refused(server):
    """It used to take the socket over: stopping the first then removed the second's."""
    done = subprocess.run(
        [sys.executable, "-m", "mosys.command", "job-server", str(server.socket), "--idle", "1"],
        capture_output=True,
        text=True,
        env=environment(),
        timeout=60,
    )
    assert done.returncode == 2
    assert done.stderr.strip().splitlines()[-1] == (
        f"mosys job-server: error: a job server is already listening on {server.socket}"
    )
    assert server.process.poll() is None and server.socket.exists()


def test_the_server_stops_on_sigterm_and_removes_its_socket(server):
    server.process.send_signal(signal.SIGTERM)
    assert server.process.wait(timeout=20) == 0
    assert not server.socket.exists()


def test_the_socket_appears_only_once_it_listens(tmp_path, monkeypatch):
    """The fixture (and Snakemake's onstart) connect the moment the socket's path exists: the
    server binds and listens under another name and renames, so that moment never refuses."""
    from mosys.cli import job_server

    path = tmp_path / "server.sock"
    path.write_text("stale")
    seen: list[bool] = []
    rename = os.replace

    def replace(source, target):
        seen.append(Path(target).exists())  # the stale file, still there until the rename
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as early:
            early.connect(source)  # already listening before it gets its name
        rename(source, target)

    monkeypatch.setattr(job_server.os, "replace", replace)
    with job_server._listening_socket(str(path)) as listener:
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as client:
            client.connect(str(path))
        assert seen == [True]
        assert sorted(p.name for p in tmp_path.iterdir()) == ["server.sock"]
        listener.accept()[0].close()


@pytest.mark.parametrize(
    "stop, code, message",
    [
        (signal.SIGINT, 130, "mosys: interrupted; nothing written"),
        (signal.SIGTERM, 143, ""),
    ],
)
def test_a_stopped_server_waits_for_its_jobs_and_reports_their_codes(
    server, tmp_path, stop, code, message
):
    """Ctrl-C on a build reaches the server too: it left at once, and a job that ended in that
    moment had nobody to send its code ('the job server ended before job N did', exit 1). Now
    it takes no more jobs, tells those running to stop and reports each one's code. It tells
    them with the signal that stopped it: after Ctrl-C it sent SIGTERM, and a build's jobs
    ended with 143 and no word in their logs instead of 'interrupted' and 130."""
    client = served_sleeper(server, tmp_path, 30)
    ((job, _),) = server.jobs()
    server.process.send_signal(stop)
    _, stderr = client.communicate(timeout=60)
    assert client.returncode == code, stderr  # the job's own code
    assert stderr.strip() == message
    assert server.process.wait(timeout=20) == 0
    assert server.wait_for_end(job) == f"ended: exit {code}"  # reported by the server itself
    assert not (tmp_path / "x.png").exists()


def test_a_request_is_declined_once_the_package_has_changed(monkeypatch):
    """A job forks the server, so it runs the code the server imported: a file edited during a
    build ran as it was, and Snakemake took the output as made by the edited code."""
    request = {"python": sys.executable, "package": job_server.package_directory(), "env": {}}
    monkeypatch.setattr(os, "environ", {})
    monkeypatch.delitem(sys.modules, "numba.np.ufunc.parallel", raising=False)  # this process's
    stamp = job_server.source_stamp()
    assert stamp and all(path.endswith(".py") for path, _, _ in stamp)
    monkeypatch.setattr(job_server, "_started_with", stamp)
    assert job_server.decline_reason(request) is None
    path, mtime, size = stamp[3]
    changed = (*stamp[:3], (path, mtime + 1, size), *stamp[4:])
    monkeypatch.setattr(job_server, "_started_with", changed)
    relative = os.path.relpath(path, os.path.dirname(job_server.package_directory()))
    assert job_server.decline_reason(request) == f"{relative} changed since the server started"
    monkeypatch.setattr(job_server, "_started_with", stamp[1:])  # a file added since
    assert "changed since the server started" in job_server.decline_reason(request)
