"""``mosys index``: an aggregate target's file, the list of the files it stands for."""

from __future__ import annotations

import argparse
from pathlib import Path

from mosys.cli import job_server
from mosys.cli.verb import Family, OutputPath, Verb


def _index_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("inputs", nargs="*", help="the files the target stands for")
    parser.add_argument(
        "-o", "--output", required=True, type=OutputPath(), help="the list, one path a line"
    )


def _index(args: argparse.Namespace) -> None:
    from mosys.io.atomic import write_text_atomically

    missing = [path for path in args.inputs if not Path(path).exists()]
    if missing:
        raise FileNotFoundError(f"cannot index missing files: {', '.join(missing)}")
    write_text_atomically(args.output, "".join(f"{path}\n" for path in args.inputs))


FAMILY = Family(
    "pipeline",
    (
        Verb(
            "index",
            "write an aggregate target: the list of its files",
            _index_arguments,
            _index,
        ),
        job_server.VERB,
    ),
)
