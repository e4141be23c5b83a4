"""The papers' tables: ``pendulum-table`` (Figure 13), ``car-table``, ``luxo-table``, ``bsr-table``,
``bsr3d-table``, ``composite-table`` and ``robustness-table``."""

from __future__ import annotations

import argparse

from mosys.cli.verb import Family, Verb, add_budget, add_table_outputs


def _pendulum_table_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("controllers", nargs="+", help="the controller tables (.h5)")
    parser.add_argument("--dynamics", required=True, help="their figure's dynamics module (.py)")
    add_table_outputs(parser)
    add_budget(parser)


def _pendulum_table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.pendulum import write_pendulum_table

    write_pendulum_table(args.controllers, args.dynamics, args.csv, args.md, args.budget)


def _car_table_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("table", help="controller table (.h5)")
    parser.add_argument("--starts", required=True, help="start grid (.h5, mosys starts)")
    parser.add_argument(
        "--trajectories", nargs="+", required=True, help="the Figure 19 trajectories (.h5)"
    )
    add_table_outputs(parser)
    add_budget(parser)


def _car_table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.car import write_car_table

    write_car_table(args.table, args.starts, args.trajectories, args.csv, args.md, args.budget)


def _luxo_table_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("trajectory", help="a trajectory of Luxo's show (.h5)")
    parser.add_argument(
        "--landing", required=True, help="the landing controller's table (its dest: standing)"
    )
    add_table_outputs(parser)
    add_budget(parser)


def _luxo_table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.luxo import write_luxo_table

    write_luxo_table(args.trajectory, args.landing, args.csv, args.md, args.budget)


def _bsr_table_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("results", nargs="+", help="seed files (.h5) of the searches")
    add_table_outputs(parser)


def _bsr_table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.bsr import write_bsr_table

    write_bsr_table(args.results, args.csv, args.md)


def _bsr3d_table_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("results", nargs="+", help="seed files (.h5) of the 3-D searches")
    add_table_outputs(parser)


def _bsr3d_table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.bsr3d import write_bsr3d_table

    write_bsr3d_table(args.results, args.csv, args.md)


def _bsr3d_targets_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("results", nargs="+", help="seed files (.h5) of the 3-D searches")
    parser.add_argument("--bound", required=True, help="the bounding search (Cujo)")
    parser.add_argument(
        "--chain",
        nargs=3,
        required=True,
        metavar=("WALK", "TURN", "WALK_AGAIN"),
        help="Rex's three chained searches",
    )
    parser.add_argument("--walk", required=True, help="the sense-based biped walk (Bob)")
    parser.add_argument("--time-walk", required=True, help="its time-based twin")
    add_table_outputs(parser)


def _bsr3d_targets(args: argparse.Namespace) -> None:
    from mosys.paper_tables.bsr3d_targets import write_bsr3d_targets

    write_bsr3d_targets(
        args.results, args.csv, args.md, args.bound, args.chain, args.walk, args.time_walk
    )


def _composite_table_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("results", nargs="+", help="composite results (.h5)")
    add_table_outputs(parser)


def _composite_table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.composite import write_composite_table

    write_composite_table(args.results, args.csv, args.md)


def _robustness_table_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("results", nargs="+", help="seed files (SEARCH/seedK.h5) of both")
    parser.add_argument(
        "--pair",
        nargs=2,
        action="append",
        required=True,
        metavar=("ROBUST", "PLAIN"),
        help="a robust search and its plain twin (search names); repeat for more",
    )
    parser.add_argument("--bsr-specs", default="specs/bsr", help="where SEARCH.bsr lives")
    parser.add_argument("--figures", default="specs/figures", help="where NAME.fig lives")
    add_table_outputs(parser)


def _robustness_table_check(args: argparse.Namespace) -> str | None:
    same = next((pair for pair in args.pair if pair[0] == pair[1]), None)
    if same:
        return f"--pair {same[0]} {same[1]}: a robust search and another, its twin"
    return None


def _robustness_table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.robustness import write_robustness_table

    write_robustness_table(
        [tuple(pair) for pair in args.pair],
        args.results,
        args.csv,
        args.md,
        args.bsr_specs,
        args.figures,
    )


FAMILY = Family(
    "the papers' tables",
    (
        Verb(
            "pendulum-table",
            "the Figure 13 table of the pendulum controllers",
            _pendulum_table_arguments,
            _pendulum_table,
        ),
        Verb(
            "car-table",
            "the car controller's table",
            _car_table_arguments,
            _car_table,
        ),
        Verb(
            "luxo-table",
            "Luxo's motions table",
            _luxo_table_arguments,
            _luxo_table,
        ),
        Verb(
            "bsr-table",
            "the BSR runs table",
            _bsr_table_arguments,
            _bsr_table,
        ),
        Verb(
            "bsr3d-table",
            "the 3-D BSR runs table",
            _bsr3d_table_arguments,
            _bsr3d_table,
        ),
        Verb(
            "bsr3d-targets",
            "the 3-D motions against their targets",
            _bsr3d_targets_arguments,
            _bsr3d_targets,
        ),
        Verb(
            "composite-table",
            "the composite-motion table",
            _composite_table_arguments,
            _composite_table,
        ),
        Verb(
            "robustness-table",
            "robust BSR searches against their plain twins",
            _robustness_table_arguments,
            _robustness_table,
            _robustness_table_check,
        ),
    ),
)
