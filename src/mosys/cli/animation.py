"""``mosys run``: animation script -> trajectory."""

from __future__ import annotations

import argparse

from mosys.cli.verb import HDF5, Family, OutputPath, Verb, positive_number_problem


def _run_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("script", help="animation script (.anim)")
    parser.add_argument("--controllers", required=True, help="directory of controller tables")
    parser.add_argument(
        "--dynamics-dir",
        default="results/dynamics",
        help="where the generated dynamics modules FIGURE.py are",
    )
    parser.add_argument(
        "--motor-dir", default="specs/motor", help="motor programs: DIR/FIGURE/NAME.mot"
    )
    parser.add_argument("--dt", type=float, default=0.001, help="simulator step, s")
    parser.add_argument(
        "-o", "--output", required=True, type=OutputPath(*HDF5), help="trajectory (.h5)"
    )


def _run_check(args: argparse.Namespace) -> str | None:
    return positive_number_problem("dt", args.dt)


def _run(args: argparse.Namespace) -> None:
    from mosys.animation.trajectory_file import run_animation_script

    run_animation_script(
        args.script, args.controllers, args.dynamics_dir, args.output, args.dt, args.motor_dir
    )


FAMILY = Family(
    "animation",
    (
        Verb(
            "run",
            "animation script (.anim) -> trajectory (.h5)",
            _run_arguments,
            _run,
            _run_check,
        ),
    ),
)
