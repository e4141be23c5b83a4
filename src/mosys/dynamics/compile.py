"""The dynamics compiler (1990 paper, §4): a figure spec in, a generated numba module out.

``compile_figure`` = parse (parsing/figure.py) -> kinematics (model.py) -> equations (derive.py)
-> source text (emit.py) -> atomic write. A spec that does not parse raises SpecError before
anything is written, so no output file is left behind.

The text depends only on the spec file (its path and bytes), the compiler's code
(COMPILER_MODULES) and sympy's version, so ``compile_figure`` keeps it under a key of those in
the dynamics cache (``load.cache_directory``, ``sources/``): compiling a figure again, after
``rm -r results`` say, reads it back instead of importing sympy (0.4 s) and deriving the
equations. sympy is imported only when a text is derived.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.metadata
import importlib.util
from pathlib import Path
from typing import TYPE_CHECKING

import mosys
from mosys.dynamics.load import cache_directory, write_once
from mosys.dynamics.vehicle import vehicle_source
from mosys.errors import InputError
from mosys.io.atomic import write_text_atomically
from mosys.parsing.figure import Figure, parse_figure_spec
from mosys.parsing.tokens import check_spec_file
from mosys.parsing.vehicle import Vehicle

if TYPE_CHECKING:
    from mosys.dynamics.derive import Equations

# every module whose code can change a generated text (a test checks that deriving one imports
# no other mosys module)
COMPILER_MODULES = (
    "mosys.dynamics.compile",
    "mosys.dynamics.derive",
    "mosys.dynamics.emit",
    "mosys.dynamics.model",
    "mosys.dynamics.vehicle",
    "mosys.parsing.figure",
    "mosys.parsing.tokens",
    "mosys.parsing.vehicle",
)


def derive_figure(figure: Figure) -> Equations:
    """The symbolic equations of motion of a parsed figure."""
    from mosys.dynamics.derive import derive_equations  # sympy: only when deriving
    from mosys.dynamics.model import build_model

    return derive_equations(build_model(figure))


def generate_source(spec_path: str | Path) -> str:
    """The text of the dynamics module for the figure spec at ``spec_path`` (nothing written).
    Raises SpecError for a spec that does not parse."""
    figure = parse_figure_spec(spec_path)
    if isinstance(figure, Vehicle):
        return vehicle_source(figure, str(spec_path), mosys.__version__)
    from mosys.dynamics.emit import emit_module  # sympy: only when deriving

    return emit_module(derive_figure(figure), str(spec_path), figure.spec_sha256, mosys.__version__)


def source_key(spec_path: str | Path) -> str:
    """The key of the text that ``generate_source`` makes of ``spec_path``: a sha256 of the
    path as given, the spec's bytes, mosys's and sympy's versions and COMPILER_MODULES' code.
    Raises OSError when the spec cannot be read."""
    digest = hashlib.sha256()
    digest.update(str(spec_path).encode() + b"\0" + Path(spec_path).read_bytes() + b"\0")
    digest.update(f"{mosys.__version__} {importlib.metadata.version('sympy')}".encode())
    for name in COMPILER_MODULES:
        spec = importlib.util.find_spec(name)
        digest.update(Path(spec.origin).read_bytes() if spec and spec.origin else name.encode())
    return digest.hexdigest()


def cached_source(spec_path: str | Path) -> str:
    """``generate_source``'s text, read from the dynamics cache when it holds the text of this
    key (``source_key``), else generated and kept there (``load.write_once``: never a partial
    text, whatever runs beside it; a cache that cannot be written is skipped)."""
    try:
        kept = cache_directory() / "sources" / f"{source_key(spec_path)}.py"
    except OSError:
        return generate_source(spec_path)  # an unreadable spec: its own error, from the parser
    if kept.is_file():
        return kept.read_text(encoding="utf-8")
    text = generate_source(spec_path)
    with contextlib.suppress(OSError):  # a read-only cache: compile without keeping the text
        write_once(kept, text.encode("utf-8"))
    return text


def compile_figure(spec_path: str | Path, out_path: str | Path) -> None:
    """Compile the figure spec ``spec_path`` (``.fig``) into the Python module ``out_path``
    (``.py``), written atomically. Raises SpecError for a bad spec, InputError for a bad
    ``out_path``; in both cases nothing is written."""
    out = Path(out_path)
    if out.suffix != ".py":
        raise InputError(f"{out_path}: expected a Python module's name, ending in .py")
    if not out.stem.isidentifier():
        raise InputError(
            f"{out_path}: expected a module name that is a Python identifier (letters, digits "
            f"and _, not starting with a digit), found {out.stem!r}"
        )
    check_spec_file(spec_path)  # a FIFO would block the read of its bytes forever
    write_text_atomically(out, cached_source(spec_path))
