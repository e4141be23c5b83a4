"""``mosys bsr-search``: one seed of a BSR search spec -> result file."""

from __future__ import annotations

import argparse

from mosys.cli.verb import (
    HDF5,
    Family,
    OutputPath,
    Verb,
    add_budget,
    first_problem,
    whole_number_problem,
)

COMPILE_NOTE_S = 1.0  # s: a search that spent this long compiling says so in its last line


def _bsr_search_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help="the search spec (.bsr)")
    parser.add_argument("--seed", type=int, required=True, help="one of the spec's seeds")
    parser.add_argument("--figures", default="specs/figures", help="where NAME.fig lives")
    parser.add_argument("--generations", type=int, help="override the spec's G (a budget)")
    add_budget(parser, default=None)  # 'paper', or 'custom' with --generations
    parser.add_argument("--threads", type=int, help="threads that run the population")
    parser.add_argument(
        "--chain",
        nargs="+",
        metavar="RESULT",
        help="3-D: the result files of the search the spec's 'chain' line continues",
    )
    parser.add_argument(
        "-o", "--output", required=True, type=OutputPath(*HDF5), help="result file (.h5)"
    )


def _bsr_search_check(args: argparse.Namespace) -> str | None:
    from mosys.parsing.tokens import MAX_INT64

    return first_problem(
        whole_number_problem("seed", args.seed, 0, MAX_INT64),
        whole_number_problem("generations", args.generations, 1),
        # 0: numba's default
        whole_number_problem("threads", args.threads, 0),
    )


def _bsr_search(args: argparse.Namespace) -> None:
    from mosys.bsr.result_file import search_to_file

    outcome = search_to_file(
        args.spec,
        args.figures,
        args.seed,
        args.output,
        args.generations,
        args.budget or ("paper" if args.generations is None else "custom"),
        args.threads,
        args.chain,
    )
    compiling = (
        f"; {outcome.compile_seconds:.1f} s of it compiling numba's kernels, once per machine"
        if outcome.compile_seconds >= COMPILE_NOTE_S
        else ""
    )
    print(
        f"{args.output}: best fitness {outcome.fitness:.3f} after {outcome.evaluations[-1]} "
        f"evaluations in {outcome.wall_seconds:.1f} s ({outcome.steps_per_second:.3g} steps/s"
        f"{compiling})"
    )


FAMILY = Family(
    "BSR controllers (the 1995 paper)",
    (
        Verb(
            "bsr-search",
            "BSR search spec (.bsr) -> result (.h5)",
            _bsr_search_arguments,
            _bsr_search,
            _bsr_search_check,
        ),
    ),
)
