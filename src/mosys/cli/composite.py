"""Composite motion: ``mosys composite`` (the transition search) and ``mosys edit`` (the
concatenation editor)."""

from __future__ import annotations

import argparse
from pathlib import Path

from mosys.cli.verb import (
    HDF5,
    Family,
    OutputPath,
    Verb,
    add_budget,
    first_problem,
    whole_number_problem,
)


def _composite_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("script", help="the composite-motion script (.comp)")
    parser.add_argument(
        "--controllers",
        nargs="*",
        help="BSR result files (SEARCH/seedK.h5) the phases may use (the pipeline lists them)",
    )
    parser.add_argument(
        "--bsr-results", help="where SEARCH/seedK.h5 live (default results/bsr; no --controllers)"
    )
    parser.add_argument("--figures", default="specs/figures", help="where NAME.fig lives")
    parser.add_argument("--bsr-specs", default="specs/bsr", help="where SEARCH.bsr lives")
    for key, what in (("q", "Q arrays"), ("g", "G generations"), ("h", "H mutations")):
        parser.add_argument(f"--{key}", type=int, help=f"override the script's {what}")
    add_budget(parser)
    parser.add_argument(
        "-o", "--output", required=True, type=OutputPath(*HDF5), help="result file (.h5)"
    )


def _composite_check(args: argparse.Namespace) -> str | None:
    if args.controllers is not None and args.bsr_results is not None:
        return "give --controllers or --bsr-results, not both"
    from mosys.composite.session import SEED_FILE

    odd = [path for path in args.controllers or () if not SEED_FILE.fullmatch(Path(path).name)]
    if odd:
        return f"--controllers {odd[0]}: expected a seed file, SEARCH/seedK.h5"
    return first_problem(
        *(whole_number_problem(key, getattr(args, key), 1) for key in ("q", "g", "h"))
    )


def _composite_controller_files(args: argparse.Namespace, script) -> tuple[dict, str]:
    """The BSR result files the script may use: the ``--controllers`` given (grouped by their
    directory, the search's name), else every seed file under ``--bsr-results``; and where a
    search's files were looked for (``session.open_session``'s ``looked_in``)."""
    from mosys.composite.session import files_by_search, find_controller_files

    if args.controllers is None:
        results = args.bsr_results or "results/bsr"
        return find_controller_files(script, results), f"{results}/{{search}}/seed*.h5"
    return files_by_search(args.controllers), "--controllers file {search}/seedK.h5"


def _composite(args: argparse.Namespace) -> None:
    from mosys.composite.result_file import composite_to_file
    from mosys.parsing.composite import parse_composite_script

    script = parse_composite_script(args.script)
    sizes = {key: getattr(args, key) for key in ("q", "g", "h") if getattr(args, key) is not None}
    files, looked_in = _composite_controller_files(args, script)
    found = composite_to_file(
        args.script,
        files,
        args.output,
        args.figures,
        args.bsr_specs,
        sizes,
        args.budget,
        looked_in,
    )
    print(
        f"{args.output}: total {found.guess_score:.3f} -> {found.score:.3f}, durations "
        f"{found.guess_durations.tolist()} -> {found.durations.tolist()} ticks, "
        f"{found.simulations} simulations"
    )


def _edit_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("script", help="the composite-motion script (.comp); Save rewrites it")
    parser.add_argument("--bsr-results", default="results/bsr", help="where SEARCH/seedK.h5 live")
    parser.add_argument("--figures", default="specs/figures", help="where NAME.fig lives")
    parser.add_argument("--bsr-specs", default="specs/bsr", help="where SEARCH.bsr lives")


def _edit(args: argparse.Namespace) -> None:
    from mosys.editor.concatenation import run_editor

    run_editor(args.script, args.bsr_results, args.figures, args.bsr_specs)


FAMILY = Family(
    "composite motion (the 1995 paper)",
    (
        Verb(
            "composite",
            "composite script (.comp) -> refined transition points (.h5)",
            _composite_arguments,
            _composite,
            _composite_check,
        ),
        Verb(
            "edit",
            "the concatenation editor: a slider per phase of a script (.comp)",
            _edit_arguments,
            _edit,
        ),
    ),
)
