"""pyproject.toml's version floors against ``tools/oldest.txt``, the pins at those floors that
``tools/oldest_check.sh`` runs the tests with: a floor raised in one and not the other would
claim versions nobody tested (numba 0.60 and matplotlib 3.8 were allowed while mosys needed
0.62 and 3.11)."""

from __future__ import annotations

import tomllib
from pathlib import Path

from packaging.requirements import Requirement  # packaging: one of pytest's own requirements
from packaging.version import Version

ROOT = Path(__file__).resolve().parent.parent


def version_of(text: str, operator: str) -> tuple[str, Version]:
    """A requirement's name and the version of its one ``operator`` clause (``>=``, ``==``)."""
    requirement = Requirement(text)
    (version,) = [spec.version for spec in requirement.specifier if spec.operator == operator]
    return requirement.name, Version(version)


def floors() -> dict[str, Version]:
    """The ``>=`` version of every dependency and test extra in pyproject.toml, by name."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    texts = project["dependencies"] + project["optional-dependencies"]["test"]
    return dict(version_of(text, ">=") for text in texts)


def pins() -> dict[str, Version]:
    """The ``==`` version of every line of tools/oldest.txt, by name."""
    lines = (ROOT / "tools/oldest.txt").read_text().splitlines()
    pinned = [line for line in lines if line.strip() and not line.startswith("#")]
    return dict(version_of(line, "==") for line in pinned)


def test_every_floor_is_pinned_in_the_oldest_versions_file():
    assert pins() == floors()
