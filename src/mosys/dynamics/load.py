"""Import a generated dynamics module from its file path.

numba's cache (``cache=True``) is keyed by the source file's path and modification time, and a
generated module is rewritten whenever its figure is compiled again — after ``rm -r results``, say
— which would throw its compiled code away although the equations are the same. So mosys imports
a content-addressed copy of the file, ``<cache>/mosys_dynamics_<stem>_<sha256 prefix>.py``, written
once and never touched again (``<cache>``: ``$MOSYS_CACHE_DIR``, else
``$XDG_CACHE_HOME/mosys/dynamics``, else ``~/.cache/mosys/dynamics``). numba must also import the
module again by name when loading cached functions, so the module is registered in
``sys.modules`` under that name before it runs.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.util
import os
import re
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

from mosys.errors import InputError
from mosys.files import input_problem
from mosys.parsing.figure import (
    MAX_GRAVITY,
    ROD_INERTIA_RANGE,
    ROD_LENGTH_RANGE,
    ROD_MASS_RANGE,
)
from mosys.parsing.tokens import SpecError, Token

# names every dynamics module defines (the controllers' first-order view), then those of each kind
REQUIRED = ("STATE_NAMES", "STATE_UNITS", "INPUT_NAMES", "INPUT_UNITS", "derivative_into")
REQUIRED_BY_KIND = {
    "figure": ("Q_NAMES", "QD_NAMES", "mass_matrix", "forcing", "qdd", "qdd_into"),
    "vehicle": ("WHEELBASE", "WHEEL_RADIUS", "STEER_LIMIT", "BODY_OUTLINE"),
}


def cache_directory() -> Path:
    """Where content-addressed copies of generated modules live (see the module docstring)."""
    if os.environ.get("MOSYS_CACHE_DIR"):
        return Path(os.environ["MOSYS_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "mosys" / "dynamics"


def module_name(path: str | Path, source: bytes) -> str:
    """The ``sys.modules`` name of a generated module: ``mosys_dynamics_<stem>_<sha256[:16]>``,
    non-identifier characters of the stem replaced by ``_``."""
    stem = re.sub(r"\W", "_", Path(path).stem)
    return f"mosys_dynamics_{stem}_{hashlib.sha256(source).hexdigest()[:16]}"


def write_once(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` if nothing is there, by a hard link of a finished temporary
    file beside it: concurrent processes never see a partial file, nor rewrite one that another
    has read (the first one's stays). Raises OSError where the directory cannot be written."""
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, partial = tempfile.mkstemp(dir=path.parent, suffix=".partial")
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
        with contextlib.suppress(FileExistsError):  # another process was first: keep theirs
            os.link(partial, path)
    finally:
        os.unlink(partial)


def content_addressed_copy(path: Path) -> Path:
    """The copy of ``path`` named by its content, written once if missing (``write_once``)."""
    source = path.read_bytes()
    copy = cache_directory() / f"{module_name(path, source)}.py"
    if not copy.exists():
        write_once(copy, source)
    return copy


def load_dynamics(path: str | Path) -> ModuleType:
    """Import the generated dynamics module at ``path`` (see the module docstring). Raises
    FileNotFoundError if it does not exist, and InputError if importing it fails or it lacks
    the generated names."""
    path = Path(path)
    if input_problem(path) or not path.is_file():  # recorded as read: no output replaces it
        raise FileNotFoundError(f"no generated dynamics module at {str(path)!r}")
    copy = content_addressed_copy(path)
    name = copy.stem
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, copy)
    if spec is None or spec.loader is None:
        raise InputError(f"{path} cannot be imported as a Python module")
    from mosys.kernels import compile_lock

    compile_lock.serialize_cold_compilation()  # its jitted functions compile as it runs
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except (Exception, SystemExit) as error:  # any Python file can be named, not only ours
        sys.modules.pop(name, None)
        raise InputError(
            f"{path} is not a dynamics module of this mosys (importing it raised "
            f"{type(error).__name__}: {error}): compile its figure again (mosys compile)"
        ) from None
    except BaseException:
        sys.modules.pop(name, None)
        raise
    kind = getattr(module, "MODEL_KIND", "figure")
    required = REQUIRED + REQUIRED_BY_KIND.get(kind, ())
    missing = [attribute for attribute in required if not hasattr(module, attribute)]
    if missing:
        raise InputError(
            f"{path} is not a dynamics module of this mosys (it lacks {missing[0]}): compile its "
            "figure again (mosys compile, or snakemake, which does so when mosys changes)"
        )
    if kind == "figure":
        _check_parameters(path, module)
    return module


def _check_parameters(path: Path, module: ModuleType) -> None:
    """InputError if a figure module's rods or gravity lie outside the figure spec's bounds
    (``parsing.figure``): a module compiled before the bounds, or edited by hand, whose numbers
    would make the kernels divide by zero or overflow."""
    ranges = (
        ("ROD_LENGTH", "length", "m", ROD_LENGTH_RANGE),
        ("ROD_MASS", "mass", "kg", ROD_MASS_RANGE),
        ("ROD_INERTIA", "inertia", "kg·m²", ROD_INERTIA_RANGE),
    )
    for constant, quantity, unit, (low, high) in ranges:
        for name, value in zip(
            getattr(module, "ROD_NAMES", ()), getattr(module, constant, ()), strict=False
        ):
            if not low <= value <= high:
                raise InputError(
                    f"{path}: rod {name}'s {quantity} is {value:g} {unit}, outside the figure "
                    f"spec's {low:g}..{high:g}: fix the figure spec and compile it again"
                )
    gravity = getattr(module, "GRAVITY", 0.0)
    if not 0 <= gravity <= MAX_GRAVITY:
        raise InputError(
            f"{path}: gravity is {gravity:g} m/s², outside the figure spec's 0..{MAX_GRAVITY:g}: "
            "fix the figure spec and compile it again"
        )


def figure_dynamics(
    figure: str,
    dynamics_dir: str | Path,
    error: Callable[[Token, str], SpecError],
    token: Token,
) -> ModuleType:
    """Load ``dynamics_dir/FIGURE.py`` for a spec that names ``figure`` at ``token``; if it is
    missing, raise ``error(token, ...)`` so the message points at that spec line."""
    path = Path(dynamics_dir) / f"{figure}.py"
    if not path.exists():
        raise error(token, f"a compiled figure ({path} does not exist: run 'mosys compile')")
    module = load_dynamics(path)
    changed = spec_changed_since(module)
    if changed is not None:
        raise error(
            token,
            f"a figure compiled from its spec as it is ({path} was compiled from an earlier "
            f"{changed}: run 'mosys compile {changed} -o {path}', or snakemake)",
        )
    return module


def spec_changed_since(module: ModuleType) -> str | None:
    """The figure spec a generated module was compiled from (``SPEC_PATH``, as given to
    ``mosys compile``, from the working directory) if that file has changed since
    (``SPEC_SHA256``); None if it has not, or cannot be found (another directory, a module
    compiled before SPEC_PATH was recorded): a controller or run made from a stale module
    silently used the old figure."""
    spec = getattr(module, "SPEC_PATH", None)
    if not isinstance(spec, str):
        return None
    try:
        text = Path(spec).read_bytes()
    except OSError:
        return None
    return None if hashlib.sha256(text).hexdigest() == module.SPEC_SHA256 else spec
