"""``mosys info``: what a result file (.h5) mosys wrote holds."""

from __future__ import annotations

import argparse

from mosys.cli.verb import Family, Verb


def _info_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="an .h5 file mosys wrote")


def _info(args: argparse.Namespace) -> None:
    from mosys.bsr.lone_contact import MAX_EXCURSION
    from mosys.bsr.physics_check import measure_rules
    from mosys.io.info import describe_file
    from mosys.plots.style import counted

    print(describe_file(args.file), end="")
    measured = measure_rules(args.file)
    if measured:
        print("\nthe paper's rules (README, 'The simulator'), measured:")
    for rules in measured:
        print(
            f"  /{rules.group}: deepest rod end {1000 * rules.depth:.2f} mm below the floor; "
            f"{counted(rules.lone_contacts, 'lone contact')}, {rules.sliding} of them sliding "
            f"{MAX_EXCURSION * 1000:g} mm or more"
        )


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
