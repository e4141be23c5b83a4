"""One ``mosys`` verb as one declaration: its name, its line in ``mosys --help``, its arguments,
its checks and its handler, kept together in the module of its family."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass

from mosys.parsing.tokens import MAX_WHOLE


def no_check(args: argparse.Namespace) -> str | None:
    return None


def whole_number_problem(
    verb: str, option: str, value: int | None, low: int, high: int = MAX_WHOLE
) -> str | None:
    """The usage error of ``--option`` outside ``low..high`` (None: not given, fine)."""
    if value is None or low <= value <= high:
        return None
    return f"{verb}: --{option} must be a whole number from {low} to {high}, got {value}"


def positive_number_problem(verb: str, option: str, value: float | None) -> str | None:
    """The usage error of ``--option`` that is not a finite number > 0 (None: not given)."""
    if value is None or 0 < value < float("inf"):
        return None
    return f"{verb}: --{option} must be a number > 0, got {value}"


def first_problem(*problems: str | None) -> str | None:
    """The first usage error of several checks, or None."""
    return next((problem for problem in problems if problem), None)


def add_budget(parser: argparse.ArgumentParser) -> None:
    """``--budget``: the name of the config that built an output (it is written into it)."""
    parser.add_argument("--budget", default="paper", help="name of the config that built it")


def add_table_outputs(parser: argparse.ArgumentParser) -> None:
    """``--csv`` and ``--md``: the two files every paper table is written to."""
    parser.add_argument("--csv", required=True)
    parser.add_argument("--md", required=True)


@dataclass(frozen=True)
class Verb:
    """A verb. ``name`` is what the user types after ``mosys``: ``"dp"``, or ``"plot car"`` for a
    kind of ``plot``. ``add_arguments`` fills the verb's parser; ``check`` returns the usage error
    of arguments that parse but do not go together (``None`` when they do), which ``mosys``
    reports as argparse does, exit 2; ``handler`` does the work, importing what it needs inside
    so that ``mosys --help`` stays fast."""

    name: str
    summary: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    handler: Callable[[argparse.Namespace], None]
    check: Callable[[argparse.Namespace], str | None] = no_check


@dataclass(frozen=True)
class Family:
    """Verbs that belong together, listed under ``title`` in ``mosys --help``."""

    title: str
    verbs: tuple[Verb, ...]
