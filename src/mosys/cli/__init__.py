"""The ``mosys`` command line: argument parsing and exit codes, nothing else.

Each verb family has its module here (``dynamics``, ``ssc``, ``animation``, ``bsr``,
``composite``, ``plots``, ``paper_tables``, ``index``, ``info``), declaring every verb's
arguments, checks and handler together (``verb.Verb``); this module assembles them into one
parser and runs one.

Exit codes: 0 success; 2 a bad spec or input (a ``file:line:column: expected ..., found ...``
message, no traceback, no output file) or bad arguments; 1 any other failure; 128 + the signal
for a stop by a signal (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP) or by the reader of the output
closing its pipe (141).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import select
import signal
import sys
import textwrap
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from mosys import __version__
from mosys.cli import animation, bsr, composite, dynamics, index, info, paper_tables, plots, ssc
from mosys.cli.verb import DefaultsHelpFormatter, Family, file_options, same_file_problem
from mosys.errors import Stopped, forget_stops, note_stop, stop_received

# In `mosys --help` order: the pipeline's steps, then what is drawn and tabulated from them.
FAMILIES: tuple[Family, ...] = (
    dynamics.FAMILY,
    ssc.FAMILY,
    animation.FAMILY,
    bsr.FAMILY,
    composite.FAMILY,
    plots.FAMILY,
    paper_tables.FAMILY,
    index.FAMILY,
    info.FAMILY,
)

_HELP_WIDTH = 78  # argparse's own width on an 80-column terminal


def _fill(text: str) -> str:
    """``text`` wrapped to the help's width, never breaking at a no-break space."""
    return textwrap.fill(text, _HELP_WIDTH).replace("\xa0", " ")


DESCRIPTION = (
    "Motion synthesis for physically based animation: state-space controllers (van de Panne "
    "et al. 1990) and BSR controllers (Auslander et al. 1995). Each verb is one step of the "
    "Snakemake pipeline and works on its own too; `mosys\xa0VERB\xa0--help` gives its arguments. "
    "Exit codes: 0 done; 2 a bad spec, input file or argument (the message says where; no "
    "output file is written); 1 anything else."
)

EPILOG = (
    "To build everything the 1990 pendulum example makes, from the repository root:\n"
    "  snakemake results/pendulum_all\n"
    + _fill(
        "README.md describes the other targets (results/car_all, results/luxo_all, "
        "results/bsr_all, results/bsr3d_all, results/composite_all, results/paper_tables, all), "
        "the spec formats and the verbs."
    )
)


def verb_listing(families: tuple[Family, ...] = FAMILIES) -> str:
    """The verbs of ``mosys --help``: a heading per family, one line per verb (wrapped under
    its summary when long)."""
    column = 2 + max(len(verb.name) for family in families for verb in family.verbs) + 2
    lines = []
    for family in families:
        lines.append(f"{family.title}:")
        for verb in family.verbs:
            lines += textwrap.wrap(
                verb.summary,
                _HELP_WIDTH,
                initial_indent=f"  {verb.name}".ljust(column),
                subsequent_indent=" " * column,
            )
    return "\n".join(lines)


def build_parser() -> argparse.ArgumentParser:
    """``mosys``'s parser: a subcommand per verb of every family (``plot car``: the kind
    ``car`` of the verb ``plot``), each with its arguments and its verb to call."""
    parser = argparse.ArgumentParser(
        prog="mosys",
        usage="%(prog)s [-h] [--version] VERB ...",
        description=f"{_fill(DESCRIPTION)}\n\n{verb_listing()}",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--version", action="version", version=f"mosys {__version__}", help="print the version"
    )
    # The listing above replaces argparse's; prog="mosys" keeps "usage: mosys VERB ..." per verb.
    verbs = parser.add_subparsers(dest="verb", required=True, prog="mosys", help=argparse.SUPPRESS)
    groups: dict[str, argparse._SubParsersAction] = {}
    for family in FAMILIES:
        for verb in family.verbs:
            group, _, name = verb.name.rpartition(" ")
            if group and group not in groups:  # "plot car": a kind of the verb "plot"
                groups[group] = verbs.add_parser(group).add_subparsers(dest="kind", required=True)
            subparser = (groups[group] if group else verbs).add_parser(
                name, help=verb.summary, formatter_class=DefaultsHelpFormatter
            )
            verb.add_arguments(subparser)
            subparser.set_defaults(
                command=verb, file_options=file_options(subparser), verb_parser=subparser
            )
    return parser


def environment_problem() -> str | None:
    """The usage error of an environment numba or matplotlib cannot start in (their imports
    would raise)."""
    threads = os.environ.get("NUMBA_NUM_THREADS")
    if threads is not None and not (threads.strip().isdecimal() and int(threads) >= 1):
        return f"the environment's NUMBA_NUM_THREADS={threads!r}: expected a whole number >= 1"
    backend = os.environ.get("MPLBACKEND")
    if backend:  # matplotlib is imported for this check only when the variable is set
        try:  # the import itself refuses a backend it does not know, unless already imported
            from matplotlib import rcsetup

            rcsetup.validate_backend(backend)
        except ValueError:
            return (
                f"the environment's MPLBACKEND={backend!r}: expected one of matplotlib's "
                "backends, such as Agg (or unset it)"
            )
    return None


def main(argv: list[str] | None = None) -> int:
    """Run the verb ``argv`` names (None: this command line's); its exit code."""
    parser = build_parser()
    args, unknown = parser.parse_known_args(argv)
    if unknown:  # the verb's usage, not the top level's (which names no verb)
        args.verb_parser.error(f"unrecognized arguments: {' '.join(unknown)}")
    # a usage error of the verb's arguments under the verb's usage, as argparse's own are
    problem = args.command.check(args) or same_file_problem(args, args.file_options)
    if problem:
        args.verb_parser.error(problem)
    problem = environment_problem()  # no argument's fault: under mosys's own usage
    if problem:
        parser.error(problem)
    from mosys.files import command_files
    from mosys.io.atomic import outputs_together

    forget_stops()
    try:
        # no output replaces a file the verb read; its outputs appear all together or none
        with stop_signals_raise(), command_files(), outputs_together():
            args.command.handler(args)
    except KeyboardInterrupt:
        return stopped_code(signal.SIGINT)
    except Stopped as stop:
        return stopped_code(stop.code - 128)
    except Exception as error:
        number = stop_received()
        if number is not None:  # a library turned the stop into an error of its own (numba,
            return stopped_code(number)  # stopped while compiling: "no compiled object yet")
        return error_code(error)
    finally:
        forget_stops()  # the stops were this command's (a caller may run another)
    return 0


def error_code(error: Exception) -> int:
    """Say what went wrong with a bad input and give exit code 2; any other error is raised
    again (a traceback, exit 1)."""
    from mosys.errors import InputError, SimulationError
    from mosys.parsing.tokens import SpecError

    if not isinstance(error, BrokenPipeError):
        flush_stdout()
    if isinstance(error, (SpecError, SimulationError)):
        print(error, file=sys.stderr)  # file:line:column: first, as compilers do
        return 2
    if isinstance(error, BrokenPipeError) and stdout_closed():
        # the reader of the output went away (mosys info F | head): stop quietly, as a Unix
        # tool does; nothing left to flush into the closed pipe at exit
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 128 + signal.SIGPIPE
    if isinstance(error, (OSError, InputError)):  # a missing, unreadable or corrupt input file
        print(f"mosys: {error}", file=sys.stderr)
        return 2
    raise error


def stopped_code(number: int) -> int:
    """The exit code of a command stopped by signal ``number``, nothing written: Ctrl-C says
    so; SIGTERM and SIGHUP, whose sender knows, stop without a word."""
    if number == signal.SIGINT:
        flush_stdout()
        print("mosys: interrupted; nothing written", file=sys.stderr)
    return 128 + number


def flush_stdout() -> None:
    """Put out what the command printed before its error (a summary printed before its outputs
    failed to be written): in a log of both streams the error then comes last, as it happened,
    rather than before that summary, which read as if the file were written."""
    with contextlib.suppress(OSError, ValueError):  # a closed pipe or stream
        sys.stdout.flush()


def stdout_closed() -> bool:
    """Whether standard output is a pipe whose reader has closed it (poll reports an error on
    the writing end)."""
    try:
        poller = select.poll()
        poller.register(sys.stdout.fileno(), select.POLLOUT)
        return any(event & select.POLLERR for _, event in poller.poll(0))
    except (OSError, ValueError, AttributeError):  # no descriptor, or no poll on this system
        return False


@contextmanager
def stop_signals_raise() -> Iterator[None]:
    """Within the block, SIGTERM and SIGHUP (a scheduler or a closed terminal stopping the
    command) raise ``Stopped``, as Ctrl-C raises KeyboardInterrupt, so that the partial outputs
    are removed on the way out; each is also recorded (``errors.note_stop``), so that one whose
    exception a library swallows still stops the outputs from being written. The handlers
    before are restored after. Outside the main thread (signals reach only it) the block
    changes nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def stop(number: int, _frame) -> None:
        first = stop_received() is None
        note_stop(number)  # kept, should the exception be swallowed on its way out
        compile_lock = sys.modules.get("mosys.kernels.compile_lock")
        if first and compile_lock is not None and compile_lock.compiling():
            # raised inside numba's ctypes callbacks, it would be swallowed with a traceback:
            # raised when numba lets go of its compiler lock instead (a kernel loaded from the
            # cache: at once; a cold compilation: when it ends); a second signal stops at once
            if compile_lock.compiling_cold():
                print("mosys: stopping when numba's compilation ends", file=sys.stderr, flush=True)
            return
        if number == signal.SIGINT:
            raise KeyboardInterrupt
        raise Stopped(number)

    numbers = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
    before = {number: signal.signal(number, stop) for number in numbers}
    try:
        yield
    finally:
        for number, handler in before.items():
            signal.signal(number, handler)
