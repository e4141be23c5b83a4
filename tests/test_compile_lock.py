"""Cold compilation once per machine: two processes that start together on a cold numba cache
compile a kernel once between them (``mosys.kernels.compile_lock``)."""

from __future__ import annotations

import os
import subprocess
import sys

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
    assert (tmp_path / "cache" / "mosys-compile-cold_kernel.lock").exists()
