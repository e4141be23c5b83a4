"""How large one job may be, checked from its spec before anything is allocated or run.

Two limits, each with a default a user can raise (README, "Limits"):

- **memory**: what one job's arrays may take, ``MOSYS_MAX_MEMORY_GIB`` GiB; by default 80 % of
  this machine's physical memory;
- **steps**: the integration steps of one run (a script's ``sim`` and ``motor`` lines together, a
  BSR or composite evaluation, one start of a start grid), ``MOSYS_MAX_STEPS``; by default
  10,000,000 (10,000 s at the 1 ms the pendulum's scripts use).

The pipeline sets both from its config keys ``limits: {memory_gib: ..., steps: ...}``. A job past
a limit is a ``LimitError``: the verb prints where it was asked for, what it needs, the limit and
this machine's memory, and exits 2 without writing anything.
"""

from __future__ import annotations

import math
import os

from mosys.errors import SimulationError

MEMORY_VARIABLE = "MOSYS_MAX_MEMORY_GIB"
STEPS_VARIABLE = "MOSYS_MAX_STEPS"
DEFAULT_MEMORY_FRACTION = 0.8  # of physical memory
DEFAULT_STEPS = 10_000_000
GIB = 2**30


class LimitError(SimulationError):
    """A job the limits refuse; the message is complete (``where: expected ..., found ...``)."""


def physical_memory_bytes() -> int:
    """This machine's physical memory, bytes (0 where the platform does not say)."""
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return 0


def _setting(variable: str, default: float) -> float:
    """The positive number in environment ``variable``, else ``default``; LimitError if it is
    set to anything else."""
    text = os.environ.get(variable, "").strip()
    if not text:
        return default
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0 < value < math.inf:
        raise LimitError(f"mosys: expected a number > 0 in {variable}, found {text[:40]!r}")
    return value


def memory_limit_bytes() -> float:
    """The memory one job may take, bytes (``MOSYS_MAX_MEMORY_GIB``, else 80 % of physical
    memory, else 16 GiB where that is unknown)."""
    physical = physical_memory_bytes()
    default = DEFAULT_MEMORY_FRACTION * physical if physical else 16 * GIB
    return _setting(MEMORY_VARIABLE, default / GIB) * GIB


def step_limit() -> float:
    """The integration steps one run may take (``MOSYS_MAX_STEPS``, else 10,000,000)."""
    return _setting(STEPS_VARIABLE, DEFAULT_STEPS)


def _count(value: float) -> str:
    return f"{value:,.0f}" if value < 1e15 else f"{value:.3g}"


def _gib(value: float) -> str:
    return f"{value / GIB:,.2f} GiB" if value < 1e15 * GIB else f"{value / GIB:.3g} GiB"


def check_job(where: str, job: str, steps: float = 0.0, memory_bytes: float = 0.0) -> None:
    """Raise LimitError unless ``steps`` (integration steps of one run) and ``memory_bytes``
    (what the job's arrays take, bytes) are within the limits. ``where``: ``file:line:column``
    of what asked for it (or the verb's name); ``job``: what it is, e.g. ``"sim 100000 at dt
    0.001 s"``. Either number may be inf or nan (a run that never ends): refused."""
    most_steps = step_limit()
    if not steps <= most_steps:
        raise LimitError(
            f"{where}: expected at most {_count(most_steps)} integration steps per run, found "
            f'{_count(steps)} ({job}); raise {STEPS_VARIABLE} to allow it (README, "Limits")'
        )
    most_memory = memory_limit_bytes()
    if not memory_bytes <= most_memory:
        physical = physical_memory_bytes()
        machine = f" (this machine has {_gib(physical)})" if physical else ""
        raise LimitError(
            f"{where}: expected a job that fits in {_gib(most_memory)} of memory{machine}, found "
            f"about {_gib(memory_bytes)} ({job}); raise {MEMORY_VARIABLE} to allow it "
            '(README, "Limits")'
        )
