"""Cold compilation once per machine: two processes that start together on a cold numba cache
compile a kernel once between them, and within ``deferring`` a process leaves a kernel that
another is compiling for last (``mosys.kernels.compile_lock``)."""

from __future__ import annotations

import os
import subprocess
import sys

import h5py
import pytest

KERNEL = """
from numba import njit


@njit(cache=True)
def kernel(x):
    total = 0.0
    for i in range(x):
        total += i ** 0.5
    return total
"""

CALL = """
import sys
import mosys.kernels  # installs the lock
sys.path.insert(0, sys.argv[1])
from cold_kernel import kernel
kernel(10)
print(sum(kernel.stats.cache_misses.values()), sum(kernel.stats.cache_hits.values()))
"""


def test_two_cold_processes_compile_a_kernel_once(tmp_path):
    (tmp_path / "cold_kernel.py").write_text(KERNEL)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    processes = [
        subprocess.Popen(
            [sys.executable, "-c", CALL, str(tmp_path)],
            env=env,
            stdout=subprocess.PIPE,
            text=True,
        )
        for _ in range(2)
    ]
    outcomes = sorted(tuple(int(word) for word in p.communicate()[0].split()) for p in processes)
    assert all(p.returncode == 0 for p in processes)
    # one compiled; the other missed the cache, waited for the lock, and loaded that code (its
    # hit); without the lock both would compile (no hit)
    assert [hits for _, hits in outcomes] == [0, 1] or [hits for _, hits in outcomes] == [1, 0]
    assert (tmp_path / "cache" / "mosys-compile-cold_kernel.kernel.lock").exists()


# with a signature: compiled (or loaded from the cache) at import, not at its first call
EAGER_KERNEL = KERNEL.replace("@njit(cache=True)", '@njit("float64(int64)", cache=True)')

IMPORT_CACHE_ONLY = """
import sys
from mosys.kernels.compile_lock import ColdCompilationError, cache_only
sys.path.insert(0, sys.argv[1])
with cache_only():
    try:
        import eager_kernel
    except ColdCompilationError as cold:
        print("cold", cold, "eager_kernel" in sys.modules)
    else:
        print("loaded", eager_kernel.kernel(4))
"""


def test_within_cache_only_a_kernel_not_in_the_cache_is_refused_not_compiled(tmp_path):
    """What the job server preloads: a module whose kernel needs compiling fails to import
    (and is not left half-imported); once compiled, it loads."""
    (tmp_path / "eager_kernel.py").write_text(EAGER_KERNEL)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))

    def run(code: str) -> str:
        done = subprocess.run(
            [sys.executable, "-c", code, str(tmp_path)], env=env, capture_output=True, text=True
        )
        assert done.returncode == 0, done.stderr
        return done.stdout.strip()

    assert run(IMPORT_CACHE_ONLY) == "cold eager_kernel.kernel False"
    assert not list((tmp_path / "cache").rglob("*.nbc"))  # nothing was compiled
    run(f"import sys; sys.path.insert(0, {str(tmp_path)!r}); import mosys.kernels, eager_kernel")
    assert run(IMPORT_CACHE_ONLY) == f"loaded {sum(i**0.5 for i in range(4))!r}"


TWO_KERNELS = KERNEL + KERNEL.replace("def kernel", "def other")

LOAD_DEFERRING = """
import sys
from mosys.kernels.compile_lock import CompilationBusyError, deferring
sys.path.insert(0, sys.argv[1])
from two_kernels import kernel, other
busy = []
with deferring():
    for load in (kernel, other):
        try:
            load(10)
            print("loaded", load.__name__, flush=True)
        except CompilationBusyError as error:
            print("busy", error, flush=True)
            busy.append(load)
for load in busy:
    load(10)  # waits for the lock, then compiles
    print("loaded", load.__name__, flush=True)
"""


def test_a_kernel_another_process_compiles_is_left_for_last_within_deferring(tmp_path, monkeypatch):
    """What ``mosys dp`` does when it loads its kernels: the one whose lock another process
    holds (here, the test) is skipped, the next compiled meanwhile, then the first waited for."""
    from mosys.kernels.compile_lock import machine_lock

    (tmp_path / "two_kernels.py").write_text(TWO_KERNELS)
    cache = tmp_path / "cache"
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(cache))  # the child's cache, and its locks
    with machine_lock("two_kernels.kernel"):
        child = subprocess.Popen(
            [sys.executable, "-c", LOAD_DEFERRING, str(tmp_path)],
            stdout=subprocess.PIPE,
            text=True,
        )
        lines = [child.stdout.readline().strip() for _ in range(2)]
        assert lines == ["busy two_kernels.kernel", "loaded other"]
        assert not list(cache.rglob("two_kernels.kernel-*.nbi"))  # it waits, compiling none
    assert child.stdout.readline().strip() == "loaded kernel"  # once the lock was released
    assert child.wait(timeout=60) == 0
    assert list(cache.rglob("two_kernels.kernel-*.nbi"))


TIMED = """
import sys
from mosys.kernels import compile_lock
compile_lock.serialize_cold_compilation()
told = []
compile_lock.on_first_cold_compilation(told.append)
sys.path.insert(0, sys.argv[1])
from cold_kernel import kernel
kernel(10)
kernel(20)
print(told, compile_lock.cold_compilation_seconds() > 0)
"""


def test_a_cold_compilation_is_timed_and_told_once(tmp_path):
    """A fresh install's first BSR search counted a minute of compiling as search time; its
    command said nothing meanwhile. Warm, nothing is compiled, told or counted."""
    (tmp_path / "cold_kernel.py").write_text(KERNEL)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    for expected in ("['cold_kernel.kernel'] True", "[] False"):  # cold, then warm
        done = subprocess.run(
            [sys.executable, "-c", TIMED, str(tmp_path)],
            env=env,
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert done.returncode == 0, done.stderr
        assert done.stdout.strip() == expected


@pytest.mark.slow
def test_a_first_search_says_how_long_it_compiled(tmp_path):
    """A fresh install's first search printed '... in 57.1 s' beside its warm seeds' 1 s and
    its log said nothing of the minute of compiling (no terminal there)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    env.pop("MOSYS_JOB_SERVER", None)
    command = [
        "mosys", "bsr-search", "specs/bsr/beryl_shuffle.bsr", "--seed", "1",
        "--generations", "1", "-o",
    ]  # fmt: skip
    done = subprocess.run(
        [*command, str(tmp_path / "cold.h5")], env=env, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    compiled = float(h5py.File(tmp_path / "cold.h5", "r").attrs["compile_seconds"])
    assert compiled >= 1.0
    assert f"; {compiled:.1f} s of it compiling numba's kernels, once per machine)" in done.stdout
    warm = subprocess.run(
        [*command, str(tmp_path / "warm.h5")], env=env, capture_output=True, text=True, timeout=600
    )
    assert warm.returncode == 0, warm.stderr
    assert "compiling" not in warm.stdout
