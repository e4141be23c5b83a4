"""``mosys info``: what a result file (.h5) mosys wrote holds."""

from __future__ import annotations

import argparse

from mosys.cli.verb import Family, Verb


def _info_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="an .h5 file mosys wrote")


def _info(args: argparse.Namespace) -> None:
    from mosys.bsr.physics_check import rule_lines
    from mosys.io.info import describe_file

    print(describe_file(args.file), end="")
    lines = rule_lines(args.file)
    if lines:
        print("\nthe paper's rules (README, 'The simulator'), measured:")
        print("\n".join(lines))


FAMILY = Family(
    "looking inside results",
    (
        Verb(
            "info",
            "a result file (.h5): its kind, axes, units and datasets",
            _info_arguments,
            _info,
        ),
    ),
)
