"""The kernels' machine-code cache stands for the whole package: a change to any kernel source
removes every cached compilation (numba alone would keep a caller compiled against the callee
of another file as it was)."""

from __future__ import annotations

from pathlib import Path

from mosys.kernels import _forget_stale_machine_code


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
