"""``mosys compile``: figure spec -> generated dynamics module."""

from __future__ import annotations

import argparse

from mosys.cli.verb import Family, OutputPath, Verb


def _compile_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("spec", help="figure spec (.fig)")
    parser.add_argument(
        "-o", "--output", required=True, type=OutputPath(".py"), help="dynamics module (.py)"
    )


def _compile(args: argparse.Namespace) -> None:
    from mosys.dynamics.compile import compile_figure

    compile_figure(args.spec, args.output)


FAMILY = Family(
    "equations of motion",
    (
        Verb(
            "compile",
            "figure spec (.fig) -> generated dynamics module",
            _compile_arguments,
            _compile,
        ),
    ),
)
