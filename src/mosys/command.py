"""The ``mosys`` command, as installed: hand the command line to the job server that
``MOSYS_JOB_SERVER`` names, when there is one to take it (``mosys.job_client``), else run it in
this process (``mosys.cli.main``). Kept out of ``mosys.cli``, whose import (every verb family's
arguments) would cost a handed-over command more than the rest of its start."""

from __future__ import annotations

import sys

from mosys.job_client import delegate


def main() -> int:
    """Run this process's command line; its exit code."""
    code = delegate(sys.argv[1:])
    if code is None:
        from mosys.cli import main as run_here

        code = run_here(sys.argv[1:])
    return code


if __name__ == "__main__":
    sys.exit(main())
