"""Import a generated dynamics module from its file path.

numba's cache (``cache=True``) records functions by their module's name and must import that
module again when loading them, so the module is registered in ``sys.modules`` under a stable
name derived from the file stem (``mosys_dynamics_link1``) before it runs.
"""

from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path
from types import ModuleType

REQUIRED = ("Q_NAMES", "QD_NAMES", "mass_matrix", "forcing", "qdd", "qdd_into")


def module_name(path: str | Path) -> str:
    """The ``sys.modules`` name of the generated module at ``path``: ``mosys_dynamics_<stem>``,
    non-identifier characters replaced by ``_``."""
    return "mosys_dynamics_" + re.sub(r"\W", "_", Path(path).stem)


def load_dynamics(path: str | Path) -> ModuleType:
    """Import the generated dynamics module at ``path`` (see the module docstring). Raises
    FileNotFoundError if it does not exist and ValueError if it lacks the generated names."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no generated dynamics module at {str(path)!r}")
    name = module_name(path)
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ValueError(f"{str(path)!r} cannot be imported as a Python module")
    module = importlib.util.module_from_spec(spec)
    previous = sys.modules.get(name)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        if previous is None:
            sys.modules.pop(name, None)
        else:
            sys.modules[name] = previous
        raise
    missing = [attribute for attribute in REQUIRED if not hasattr(module, attribute)]
    if missing:
        raise ValueError(f"{str(path)!r} is not a generated dynamics module (no {missing[0]})")
    return module
