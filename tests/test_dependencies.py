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


def floors() -> dict[str, Version]:
    """The ``>=`` version of every dependency and test extra in pyproject.toml, by name."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    found = {}
    for text in project["dependencies"] + project["optional-dependencies"]["test"]:
        requirement = Requirement(text)
        (floor,) = [spec.version for spec in requirement.specifier if spec.operator == ">="]
        found[requirement.name] = Version(floor)
    return found


def pins() -> dict[str, Version]:
    """The ``==`` version of every line of tools/oldest.txt, by name."""
    found = {}
    for line in (ROOT / "tools/oldest.txt").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            requirement = Requirement(line)
            (pin,) = [spec.version for spec in requirement.specifier if spec.operator == "=="]
            found[requirement.name] = Version(pin)
    return found


def test_every_floor_is_pinned_in_the_oldest_versions_file():
    assert pins() == floors()
