"""Provenance: the root attributes every file mosys writes carries, saying what made it
(docs/formats/README.md, "Provenance").

``mosys_version``, ``python_version``, ``numpy_version``, ``numba_version`` and
``h5py_version`` (str, always), and ``git_commit`` (str, the hex commit checked out) only when
the package runs from a git checkout: the work tree that holds this ``mosys`` package, not an
installed copy. Uncommitted edits are not recorded. The spec's ``spec_sha256`` is the writers'
callers' to give (not every file is made from a spec).

Computed once per process. The commit is read from ``.git`` directly (HEAD, the branch's ref
file or ``packed-refs``; worktrees too), with no subprocess: a fraction of a millisecond, and it
never fails (anything unreadable means no ``git_commit``).
"""

from __future__ import annotations

import functools
import platform
import re
import sys
from pathlib import Path

import mosys

PROVENANCE_KEYS = (
    "mosys_version",
    "python_version",
    "numpy_version",
    "numba_version",
    "h5py_version",
    "git_commit",
)
_COMMIT = re.compile(r"[0-9a-f]{40}|[0-9a-f]{64}")  # SHA-1 or SHA-256 object names
_INSTALLED = ("site-packages", "dist-packages")


def provenance_attributes() -> dict[str, str]:
    """The provenance root attributes of a file written now (a new dict each call)."""
    return dict(_provenance())


@functools.cache
def _provenance() -> tuple[tuple[str, str], ...]:
    attrs = {
        "mosys_version": mosys.__version__,
        "python_version": platform.python_version(),
        "numpy_version": _version("numpy"),
        "numba_version": _version("numba"),
        "h5py_version": _version("h5py"),
    }
    commit = checkout_commit(Path(mosys.__file__).resolve().parent)
    if commit is not None:
        attrs["git_commit"] = commit
    return tuple(attrs.items())


def _version(distribution: str) -> str:
    """A library's version: its module's ``__version__`` when imported (numpy, h5py), else
    its installed metadata (numba, without importing it); ``unknown`` when neither says."""
    version = getattr(sys.modules.get(distribution), "__version__", None)
    if version:
        return str(version)
    import importlib.metadata  # 45 ms to import: only when a library is not imported already

    try:
        return importlib.metadata.version(distribution)
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


def checkout_commit(package_dir: Path) -> str | None:
    """The commit checked out in the git work tree holding ``package_dir``: the first folder
    up from it with a ``.git``. None when there is none, when an installed copy
    (``site-packages``) is met first, or when ``.git`` cannot be read."""
    for directory in (package_dir, *package_dir.parents):
        if directory.name in _INSTALLED:
            return None
        dot_git = directory / ".git"
        try:
            found = dot_git.exists()
        except OSError:
            return None
        if found:
            return _head_commit(dot_git)
    return None


def _head_commit(dot_git: Path) -> str | None:
    try:
        git_dir = dot_git
        if dot_git.is_file():  # a linked worktree or submodule: "gitdir: PATH"
            text = dot_git.read_text(encoding="utf-8").strip()
            if not text.startswith("gitdir:"):
                return None
            git_dir = dot_git.parent / text.removeprefix("gitdir:").strip()
        common = git_dir  # where the shared refs live (a worktree names it in "commondir")
        if (git_dir / "commondir").is_file():
            common = git_dir / (git_dir / "commondir").read_text(encoding="utf-8").strip()
        head = (git_dir / "HEAD").read_text(encoding="utf-8").strip()
        if head.startswith("ref:"):
            head = _ref_commit(git_dir, common, head.removeprefix("ref:").strip()) or ""
    except (OSError, ValueError):
        return None
    return head if _COMMIT.fullmatch(head) else None


def _ref_commit(git_dir: Path, common: Path, ref: str) -> str | None:
    """The object a ref names: its loose file, else its line in ``packed-refs``."""
    for base in (git_dir, common):
        if (base / ref).is_file():
            return (base / ref).read_text(encoding="utf-8").strip()
    packed = common / "packed-refs"
    if packed.is_file():
        for line in packed.read_text(encoding="utf-8").splitlines():
            commit, _, name = line.partition(" ")
            if name == ref and not line.startswith(("#", "^")):
                return commit
    return None
