"""One ``mosys`` verb as one declaration: its name, its line in ``mosys --help``, its arguments,
its checks and its handler, kept together in the module of its family."""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable
from dataclasses import dataclass

from mosys.files import output_problem
from mosys.parsing.tokens import MAX_WHOLE


class DefaultsHelpFormatter(argparse.HelpFormatter):
    """A verb's ``--help``: each option's default after its help, where it has one worth
    saying (not None, False or an empty list) and the help does not say it already."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help
        default = action.default
        if (
            text is None
            or not action.option_strings
            or default in (None, False, argparse.SUPPRESS)
            or (isinstance(default, list) and not default)
            or "default" in text
        ):
            return text
        shown = " ".join(map(str, default)) if isinstance(default, list) else str(default)
        return f"{text} (default: {shown.replace('%', '%%')})"


def no_check(args: argparse.Namespace) -> str | None:
    """A verb's check when its arguments need none beyond argparse's: no problem."""
    return None


def whole_number_problem(
    option: str, value: int | None, low: int, high: int = MAX_WHOLE
) -> str | None:
    """The usage error of ``--option`` outside ``low..high`` (None: not given, fine)."""
    if value is None or low <= value <= high:
        return None
    return f"--{option} must be a whole number from {low} to {high}, got {value}"


def positive_number_problem(option: str, value: float | None) -> str | None:
    """The usage error of ``--option`` that is not a finite number > 0 (None: not given)."""
    if value is None or 0 < value < float("inf"):
        return None
    return f"--{option} must be a number > 0, got {value}"


def first_problem(*problems: str | None) -> str | None:
    """The first usage error of several checks, or None."""
    return next((problem for problem in problems if problem), None)


HDF5 = (".h5", ".hdf5")
PLOT = (".png", ".pdf", ".svg")  # plots.style.FIGURE_FORMATS
GIF = (".gif",)


class OutputPath:
    """An argparse type: a file a verb writes, its name ending in one of ``suffixes`` (any
    case; none given: any name), which can be written as a whole new file
    (``files.output_problem``). Checked as the command line is read, so that a verb writing
    several files refuses a bad one before it writes any."""

    def __init__(self, *suffixes: str):
        self.suffixes = suffixes

    def __call__(self, text: str) -> str:
        problem = output_problem(text)
        if problem:
            raise argparse.ArgumentTypeError(f"cannot write {text!r}: {problem}")
        if self.suffixes and not text.lower().endswith(self.suffixes):
            raise argparse.ArgumentTypeError(
                f"expected a file name ending in {' or '.join(self.suffixes)}, got {text!r}"
            )
        return text


class InputThenOutput(argparse.Action):
    """An argparse action for an option of two values, an input file then an output file
    (``--map START_GRID PNG``), the output checked as ``OutputPath(*suffixes)`` checks one."""

    def __init__(self, option_strings, dest, suffixes: tuple[str, ...] = (), **kwargs):
        self.output = OutputPath(*suffixes)
        super().__init__(option_strings, dest, nargs=2, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        try:
            self.output(values[1])
        except argparse.ArgumentTypeError as error:
            raise argparse.ArgumentError(self, str(error)) from None
        setattr(namespace, self.dest, values)


@dataclass(frozen=True)
class FileOptions:
    """A verb's arguments by role: ``outputs`` (dest, option) of those that name an output
    (of type ``OutputPath``, or ``InputThenOutput``: the dests in ``pairs``); ``others`` the
    dests of the rest that take values (the inputs among them)."""

    outputs: tuple[tuple[str, str], ...]
    pairs: frozenset[str]
    others: tuple[str, ...]

    def output(self, args: argparse.Namespace, dest: str) -> str | None:
        """The output path ``args`` give for ``dest`` (None: not given)."""
        value = getattr(args, dest)
        return value[1] if value and dest in self.pairs else value

    def inputs(self, args: argparse.Namespace) -> list:
        """The values ``args`` give that may name input files (strings, or lists of them)."""
        pairs = [getattr(args, dest) for dest in self.pairs]
        return [getattr(args, dest) for dest in self.others] + [pair[0] for pair in pairs if pair]


def file_options(parser: argparse.ArgumentParser) -> FileOptions:
    """The ``FileOptions`` of a verb's parser."""
    actions = [  # argparse keeps no public list of a parser's arguments
        action for action in parser._actions if action.nargs != 0 and action.dest != "help"
    ]
    pairs = [action for action in actions if isinstance(action, InputThenOutput)]
    outputs = pairs + [action for action in actions if isinstance(action.type, OutputPath)]
    return FileOptions(
        tuple((a.dest, a.option_strings[-1] if a.option_strings else a.dest) for a in outputs),
        frozenset(action.dest for action in pairs),
        tuple(action.dest for action in actions if action not in outputs),
    )


def same_file_problem(args: argparse.Namespace, options: FileOptions) -> str | None:
    """The usage error of two outputs naming one file, or of an output naming a file the
    command line also gives as an input (it would be replaced before or while it is read);
    None if neither."""
    written: dict[str, str] = {}
    for dest, option in options.outputs:
        value = options.output(args, dest)
        if value:
            other = written.setdefault(os.path.realpath(value), option)
            if other != option:
                return f"{other} and {option} name the same file, {value}"
    for value in options.inputs(args):
        for text in value if isinstance(value, list) else [value]:
            for path in text if isinstance(text, list) else [text]:
                if isinstance(path, str) and os.path.isfile(path):
                    option = written.get(os.path.realpath(path))
                    if option:
                        return (
                            f"{option} {path} is also an input of this "
                            "command; write the output elsewhere"
                        )
    return None


def budget_name(text: str) -> str:
    """An argparse type: a config's name, written into the outputs as text."""
    if not text or not text.isprintable() or len(text) > 200:  # bytes not UTF-8: surrogates
        raise argparse.ArgumentTypeError(
            f"expected a config's name (printable text, 1 to 200 characters), got {text!r:.60}"
        )
    return text


def add_budget(parser: argparse.ArgumentParser, default: str | None = "paper") -> None:
    """``--budget``: the name of the config that built an output (it is written into it);
    ``default`` None leaves the verb to choose (``bsr-search``: 'custom' when
    ``--generations`` overrides the spec's G)."""
    parser.add_argument(
        "--budget",
        type=budget_name,
        default=default,
        help="name of the config that built it (default: "
        + (default or "paper, or custom with --generations")
        + ")",
    )


def add_table_outputs(parser: argparse.ArgumentParser) -> None:
    """``--csv`` and ``--md``: the two files every paper table is written to."""
    parser.add_argument("--csv", required=True, type=OutputPath(".csv"), help="the table as CSV")
    parser.add_argument("--md", required=True, type=OutputPath(".md"), help="the table as Markdown")


@dataclass(frozen=True)
class Verb:
    """A verb. ``name`` is what the user types after ``mosys``: ``"dp"``, or ``"plot car"`` for a
    kind of ``plot``. ``add_arguments`` fills the verb's parser; ``check`` returns the usage error
    of arguments that parse but do not go together (``None`` when they do; the message alone,
    without the verb's name), which ``mosys`` reports under the verb's usage as argparse reports
    its own (``mosys VERB: error: ...``), exit 2; ``handler`` does the work, importing what it
    needs inside so that ``mosys --help`` stays fast."""

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
