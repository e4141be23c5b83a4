"""The kernels' machine-code cache stands for the whole package: a change to any kernel source
removes every cached compilation (numba alone would keep a caller compiled against the callee
of another file as it was)."""

from __future__ import annotations

from pathlib import Path

import pytest
from numba.core import config

from mosys.kernels import _forget_stale_machine_code, machine_code_directories


def cached(directory: Path) -> set[str]:
    return {path.name for path in (directory / "__pycache__").glob("*.nb[ic]")}


def test_editing_any_kernel_file_forgets_every_cached_compilation(tmp_path: Path):
    (tmp_path / "simulate.py").write_text("def step(): return 1\n")
    (tmp_path / "controller.py").write_text("from simulate import step\n")
    (tmp_path / "__pycache__").mkdir()
    (tmp_path / "__pycache__" / "controller.run-1.py311.nbi").write_text("old")
    _forget_stale_machine_code(tmp_path)  # no record of what built it: forget
    assert cached(tmp_path) == set()
    (tmp_path / "__pycache__" / "controller.run-1.py311.nbi").write_text("new")
    (tmp_path / "__pycache__" / "controller.run-1.py311.1.nbc").write_text("new")
    _forget_stale_machine_code(tmp_path)  # nothing changed: kept
    assert cached(tmp_path) == {"controller.run-1.py311.nbi", "controller.run-1.py311.1.nbc"}
    (tmp_path / "simulate.py").write_text("def step(): return 2\n")  # the callee's file only
    _forget_stale_machine_code(tmp_path)
    assert cached(tmp_path) == set()


def test_a_cache_under_numba_cache_dir_is_forgotten_too(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
):
    """With NUMBA_CACHE_DIR set numba keeps the machine code there, in a directory named after
    the sources' one: that copy goes stale the same way and is removed the same way."""
    sources = tmp_path / "kernels"
    sources.mkdir()
    (sources / "simulate.py").write_text("def step(): return 1\n")
    monkeypatch.setattr(config, "CACHE_DIR", str(tmp_path / "numba"))
    beside, elsewhere = machine_code_directories(sources)
    assert beside == sources / "__pycache__"
    assert elsewhere.parent == tmp_path / "numba" and elsewhere.name.startswith("kernels_")
    _forget_stale_machine_code(sources)
    (elsewhere / "controller.run-1.py311.nbi").write_text("built with step() = 1")
    _forget_stale_machine_code(sources)  # nothing changed: kept
    assert (elsewhere / "controller.run-1.py311.nbi").exists()
    (sources / "simulate.py").write_text("def step(): return 2\n")
    _forget_stale_machine_code(sources)
    assert not (elsewhere / "controller.run-1.py311.nbi").exists()
