"""``mosys bsr-search``: one seed of a BSR search spec -> result file."""

from __future__ import annotations

import argparse

from mosys.cli.verb import Family, Verb, add_budget


def _bsr_search_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help="the search spec (.bsr)")
    parser.add_argument("--seed", type=int, required=True, help="one of the spec's seeds")
    parser.add_argument("--figures", default="specs/figures", help="where NAME.fig lives")
    parser.add_argument("--generations", type=int, help="override the spec's G (a budget)")
    add_budget(parser)
    parser.add_argument("--threads", type=int, help="threads that run the population")
    parser.add_argument(
        "--chain",
        nargs="+",
        metavar="RESULT",
        help="3-D: the result files of the search the spec's 'chain' line continues",
    )
    parser.add_argument("-o", "--output", required=True)


def _bsr_search_check(args: argparse.Namespace) -> str | None:
    from mosys.parsing.bsr import MAX_SEED, MAX_WHOLE

    if not 0 <= args.seed <= MAX_SEED:
        return f"bsr-search: --seed must be a whole number from 0 to {MAX_SEED}, got {args.seed}"
    if args.generations is not None and not 1 <= args.generations <= MAX_WHOLE:
        return (
            f"bsr-search: --generations must be a whole number from 1 to {MAX_WHOLE}, got "
            f"{args.generations}"
        )
    if args.threads is not None and args.threads < 0:
        return f"bsr-search: --threads must be at least 0 (0: numba's default), got {args.threads}"
    return None


def _bsr_search(args: argparse.Namespace) -> None:
    from mosys.bsr.result_file import search_to_file

    outcome = search_to_file(
        args.spec,
        args.figures,
        args.seed,
        args.output,
        args.generations,
        args.budget,
        args.threads,
        args.chain,
    )
    print(
        f"{args.output}: best fitness {outcome.fitness:.3f} after {outcome.evaluations[-1]} "
        f"evaluations in {outcome.wall_seconds:.1f} s ({outcome.steps_per_second:.3g} steps/s)"
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
