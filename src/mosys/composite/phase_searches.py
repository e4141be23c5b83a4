"""The searches a composite script's phases name, checked against their specs before any of
them is run or read: each must have a spec, of the script's figure. The pipeline checks them as
it plans a composite (a mistake there ran the searches first); ``mosys composite`` before it
reads their results."""

from __future__ import annotations

from pathlib import Path

from mosys.parsing.bsr import parse_bsr_spec
from mosys.parsing.composite_script import CompositeScript
from mosys.parsing.tokens import SpecError


def check_phase_searches(script: CompositeScript, bsr_specs_dir: str | Path) -> None:
    """SpecError at a phase's ``controller=`` word whose search has no spec in
    ``bsr_specs_dir`` (SEARCH.bsr) or moves another figure than the script's; a spec that does
    not parse raises its own SpecError."""
    for phase in script.phases:
        token = script.tokens[f"phase.{phase.name}.controller"]
        spec = Path(bsr_specs_dir) / f"{phase.controller}.bsr"
        if not spec.is_file():
            raise SpecError.at(script.path, token, f"a BSR search (no spec {spec})")
        figure = parse_bsr_spec(spec).figure
        if figure != script.figure:
            raise SpecError.at(
                script.path,
                token,
                f"a search of figure '{script.figure}' ({phase.controller} moves '{figure}')",
            )
