"""State-space controllers: ``mosys dp`` (spec -> table) and ``mosys starts`` (a car controller
run from a grid of start states)."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from mosys.cli.verb import (
    HDF5,
    Family,
    OutputPath,
    Verb,
    first_problem,
    positive_number_problem,
    whole_number_problem,
)

if TYPE_CHECKING:  # for the annotations only: the command loads these when a verb runs
    import numpy as np

    from mosys.io.controller_table import ControllerTable


def _dp_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help="controller spec (.ssc)")
    parser.add_argument(
        "--dynamics-dir",
        default="results/dynamics",
        help="where the generated dynamics module FIGURE.py of the spec's dyn line is",
    )
    parser.add_argument(
        "-o", "--output", required=True, type=OutputPath(*HDF5), help="controller table (.h5)"
    )
    parser.add_argument("--tol", type=float, default=None, help="override the spec's tolerance, s")
    parser.add_argument(
        "--max-iterations", type=int, default=None, help="override the spec's maxiter"
    )
    parser.add_argument("--quiet", action="store_true", help="no progress lines")


def _dp_check(args: argparse.Namespace) -> str | None:
    return first_problem(
        positive_number_problem("tol", args.tol),
        whole_number_problem("max-iterations", args.max_iterations, 1),
    )


def _dp(args: argparse.Namespace) -> None:
    from mosys.dynamics.load import figure_dynamics
    from mosys.parsing.controller import parse_controller_spec
    from mosys.ssc.generate import generate_controller

    spec = parse_controller_spec(args.spec)
    table = generate_controller(
        spec,
        figure_dynamics(spec.figure, args.dynamics_dir, spec.error, spec.figure_token),
        args.output,
        tolerance=args.tol,
        max_iterations=args.max_iterations,
        quiet=args.quiet,
    )
    attrs = table.attrs
    removed = int(attrs["removed_nodes"])
    unreachable = f"{attrs['unreachable_nodes']} unreachable"
    if removed:  # the removed nodes (value inf) are among the unreachable ones: say which is which
        unreachable = (
            f"{int(attrs['unreachable_nodes']) - removed} of {attrs['table_states']} table states "
            f"unreachable ({removed} nodes removed)"
        )
    print(
        f"{args.output}: {table.value.size} nodes, {attrs['iterations']} sweeps, residual "
        f"{attrs['residual']:.3g} s, {unreachable}, {attrs['generation_seconds']:.3f} s"
    )


def _starts_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("table", help="controller table (.h5)")
    parser.add_argument("--dynamics", required=True, help="generated dynamics module")
    for axis, unit in (("x", "m"), ("y", "m")):
        parser.add_argument(
            f"--{axis}",
            nargs=3,
            type=float,
            required=True,
            metavar=("MIN", "MAX", "COUNT"),
            help=f"start {axis} values, {unit}",
        )
    parser.add_argument(
        "--heading", nargs="+", type=float, default=[0.0], help="start headings, deg"
    )
    parser.add_argument(
        "--steer", nargs="+", type=float, default=[0.0], help="start wheel angles, deg"
    )
    parser.add_argument("--seconds", type=float, default=20.0, help="simulated time per start, s")
    parser.add_argument("--dt", type=float, default=0.01, help="simulator step, s")
    parser.add_argument("--threads", type=int, default=1, help="runs at once")
    parser.add_argument(
        "-o", "--output", required=True, type=OutputPath(*HDF5), help="start grid (.h5)"
    )
    parser.add_argument("--quiet", action="store_true", help="no progress lines")


MAX_STARTS = 1_000_000  # a start runs for seconds; a million take days on two cores


def _starts_check(args: argparse.Namespace) -> str | None:
    problem = first_problem(
        whole_number_problem("threads", args.threads, 1),
        positive_number_problem("seconds", args.seconds),
        positive_number_problem("dt", args.dt),
    )
    if problem:
        return problem
    for name in ("x", "y", "heading", "steer"):
        values = getattr(args, name)
        if not all(math.isfinite(value) for value in values):
            return f"--{name} must be finite numbers, got {' '.join(map(str, values))}"
    for axis in ("x", "y"):
        low, high, count = getattr(args, axis)
        if count < 1 or count != int(count):
            return f"--{axis}'s COUNT must be a whole number >= 1, got {count:g}"
        if low > high:
            return f"--{axis}'s MIN must not exceed its MAX, got {low:g} {high:g}"
        if count == 1 and low != high:  # it used MIN alone, without a word
            return f"--{axis} {low:g} {high:g} 1: one start needs MIN = MAX"
    starts = args.x[2] * args.y[2] * len(args.heading) * len(args.steer)
    if starts > MAX_STARTS:
        return f"at most {MAX_STARTS:,} starts, asked for {starts:,.0f}"
    return None


def _starts(args: argparse.Namespace) -> None:
    import itertools

    import numpy as np

    from mosys.dynamics.load import load_dynamics
    from mosys.io.start_grid import write_start_grid
    from mosys.ssc.controller import Controller
    from mosys.ssc.parking import evaluate_starts

    controller = Controller.load(args.table, load_dynamics(args.dynamics))
    axes = {
        "x": np.linspace(*args.x[:2], int(args.x[2])),
        "y": np.linspace(*args.y[:2], int(args.y[2])),
        "heading": np.array(args.heading),
        "steer": np.array(args.steer),
        "speed": np.array([0.0]),
    }
    order = controller.state_order
    not_a_car_problem(args.table, controller.table, axes)
    off_table_problem(controller.table, {name: axes[name] for name in ("heading", "steer")})
    starts = np.array(list(itertools.product(*(axes[name] for name in order))))
    grid = evaluate_starts(
        controller, starts, args.seconds, args.dt, args.threads, quiet=args.quiet
    )
    if not grid.counted.any():  # a grid off the domain ran nothing, without a word
        print(
            f"warning: none of the {len(starts)} starts can park (each lies on an obstacle or "
            "off the domain, or no path leads from it): none was run",
            file=sys.stderr,
        )
    write_start_grid(args.output, grid)


def not_a_car_problem(path: str, table: ControllerTable, axes: dict[str, np.ndarray]) -> None:
    """InputError for a table whose state is not a car's pose and motion (x, y, heading and
    maybe steer and speed): the pendulum's table with its own dynamics raised a KeyError
    ('angle') with a traceback, exit 1."""
    from mosys.errors import InputError

    order = tuple(table.state_order)
    if {"x", "y", "heading"} <= set(order) <= set(axes):
        return
    raise InputError(
        f"{path}: controller {Path(path).stem} (a table of figure '{table.figure}', state "
        f"{', '.join(order)}) is not a car's: mosys starts runs a car controller, whose state "
        "is x, y and heading (and steer and speed if it has them)"
    )


def off_table_problem(table: ControllerTable, values: dict[str, np.ndarray]) -> None:
    """InputError for a start heading or steer outside the table's axis (one that does not
    wrap): a start off the table was run and counted as a failure without a word."""
    from mosys.errors import InputError

    for name, asked in values.items():
        if name not in table.state_order:
            continue
        k = table.state_order.index(name)
        low, high = float(table.axes[k][0]), float(table.axes[k][-1])
        outside = [v for v in asked if not table.wrap[k] and not low - 1e-9 <= v <= high + 1e-9]
        if outside:
            raise InputError(
                f"starts: --{name} {outside[0]:g} lies outside the table's {name} axis "
                f"({low:g}..{high:g} {table.axis_units[k]}): a start there is off the table"
            )


FAMILY = Family(
    "state-space controllers (the 1990 paper)",
    (
        Verb(
            "dp",
            "controller spec (.ssc) -> controller table (.h5)",
            _dp_arguments,
            _dp,
            _dp_check,
        ),
        Verb(
            "starts",
            "a car controller from a grid of start states",
            _starts_arguments,
            _starts,
            _starts_check,
        ),
    ),
)
