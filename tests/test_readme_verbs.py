"""The README's table of verbs (section "The command line") against the parser itself: every verb
of ``mosys --help`` has a row, and each row's options are that verb's, bracketed exactly where
argparse lets them be left out. The table had drifted: ``plot controller``'s options, all
optional, were shown as required (found by reading the README against ``--help``, 2026-12-07).
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from mosys.cli import FAMILIES, build_parser

README = Path(__file__).resolve().parents[1] / "README.md"
# the one row that names several verbs at once, each described in its own section
GROUPED = {"composite", "plot composite", "composite-table", "robustness-table", "edit"}


def table_rows() -> dict[str, str]:
    """Verb -> its command as the table's first column writes it (without ``mosys``)."""
    text = README.read_text(encoding="utf-8")
    table = text.split("| command | does |", 1)[1].split("\n\n", 1)[0]
    rows = {}
    for line in table.splitlines()[2:]:
        if "`, `" in line.split(" | ")[0]:
            continue  # the GROUPED row
        command = re.match(r"\| `mosys ([^`]*)`", line).group(1)
        words = command.split()
        verb = " ".join(words[:2]) if words[0] == "plot" else words[0]
        rows[verb] = command
    return rows


def verb_parsers() -> dict[str, argparse.ArgumentParser]:
    """Verb (``plot car``: two words) -> its subparser."""
    parsers = {}

    def walk(parser: argparse.ArgumentParser, prefix: str) -> None:
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    walk(sub, f"{prefix} {name}".strip())
                return
        parsers[prefix] = parser

    walk(build_parser(), "")
    return parsers


def written_options(command: str) -> dict[str, bool]:
    """Each option a row writes -> whether it stands outside every bracket."""
    options, depth = {}, 0
    for word in command.split():
        depth += word.count("[")
        option = word.strip("[]")
        if option.startswith("-"):
            options[option] = depth == 0
        depth -= word.count("]")
    return options


ROWS = table_rows()
PARSERS = verb_parsers()


def test_every_verb_has_a_row():
    verbs = {verb.name for family in FAMILIES for verb in family.verbs}
    assert verbs == set(PARSERS)
    assert verbs - GROUPED == set(ROWS), "rows and verbs differ"


@pytest.mark.parametrize("verb", sorted(ROWS))
def test_a_rows_options_are_its_verbs_and_bracketed_where_optional(verb):
    actions = [
        action
        for action in PARSERS[verb]._actions
        if action.option_strings and "--help" not in action.option_strings
    ]
    written = written_options(ROWS[verb])
    known = {flag for action in actions for flag in action.option_strings}
    assert set(written) <= known, f"{verb}: options the parser does not have"
    for action in actions:
        spellings = [flag for flag in action.option_strings if flag in written]
        name = "/".join(action.option_strings)
        assert spellings, f"{verb}: the row leaves out {name}"
        outside = any(written[flag] for flag in spellings)
        assert outside == action.required, (
            f"{verb}: {name} is {'required' if action.required else 'optional'}, "
            f"written {'outside' if outside else 'inside'} brackets"
        )
