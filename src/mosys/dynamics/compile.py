"""The dynamics compiler (1990 paper, §4): a figure spec in, a generated numba module out.

``compile_figure`` = parse (parsing/figure.py) -> kinematics (model.py) -> equations (derive.py)
-> source text (emit.py) -> atomic write. A spec that does not parse raises SpecError before
anything is written, so no output file is left behind.
"""

from __future__ import annotations

from pathlib import Path

import mosys
from mosys.dynamics.derive import Equations, derive_equations
from mosys.dynamics.emit import emit_module
from mosys.dynamics.model import build_model
from mosys.dynamics.vehicle import vehicle_source
from mosys.io.atomic import write_text_atomically
from mosys.parsing.figure import Figure, parse_figure_spec
from mosys.parsing.vehicle import Vehicle


def derive_figure(figure: Figure) -> Equations:
    """The symbolic equations of motion of a parsed figure."""
    return derive_equations(build_model(figure))


def generate_source(spec_path: str | Path) -> str:
    """The text of the dynamics module for the figure spec at ``spec_path`` (nothing written).
    Raises SpecError for a spec that does not parse."""
    figure = parse_figure_spec(spec_path)
    if isinstance(figure, Vehicle):
        return vehicle_source(figure, str(spec_path), mosys.__version__)
    return emit_module(derive_figure(figure), str(spec_path), figure.spec_sha256, mosys.__version__)


def compile_figure(spec_path: str | Path, out_path: str | Path) -> None:
    """Compile the figure spec ``spec_path`` (``.fig``) into the Python module ``out_path``
    (``.py``), written atomically. Raises SpecError for a bad spec, ValueError for a bad
    ``out_path``; in both cases nothing is written."""
    out = Path(out_path)
    if out.suffix != ".py":
        raise ValueError(f"out_path must end in .py (a Python module), got {str(out_path)!r}")
    if not out.stem.isidentifier():
        raise ValueError(
            f"out_path's stem must be a Python identifier (it names the module), got {out.stem!r}"
        )
    write_text_atomically(out, generate_source(spec_path))
