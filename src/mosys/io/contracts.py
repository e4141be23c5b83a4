"""The kinds of file mosys writes (docs/formats/), and reading one as the kind a verb expects.

A verb given the wrong file (a trajectory where a controller table belongs, a file that is not
HDF5, a damaged one) stops with one message that names the file and what it is, instead of a
KeyError from deep inside h5py: ``open_contract`` checks the kind before the reader looks
inside, and turns what h5py raises while it reads into the same kind of message.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import h5py

from mosys.errors import InputError
from mosys.files import input_problem


@dataclass(frozen=True)
class Contract:
    """A kind of file mosys writes: its name, its page in docs/formats/, the groups and
    datasets (paths from the root) every such file has, and the datasets of mosys's own that its
    readers need beside them (``reads``: a file another tool wrote to the contract alone is of
    the kind, but mosys cannot read it)."""

    name: str
    page: str
    groups: tuple[str, ...]
    datasets: tuple[str, ...]
    reads: tuple[str, ...] = ()

    def met_by(self, h5: h5py.File) -> bool:
        return not self.missing(h5)

    def missing(self, h5: h5py.File) -> list[str]:
        """The groups and datasets of the contract that ``h5`` lacks (or has as the other)."""
        return _absent(h5, self.groups, h5py.Group) + _absent(h5, self.datasets, h5py.Dataset)

    def unread(self, h5: h5py.File) -> list[str]:
        """The datasets of ``reads`` that ``h5`` lacks."""
        return _absent(h5, self.reads, h5py.Dataset)


def _absent(h5: h5py.File, paths: tuple[str, ...], kind: type) -> list[str]:
    """The ``paths`` that are not a ``kind`` (group or dataset) in ``h5``."""
    return [path for path in paths if not isinstance(h5.get(path), kind)]


CONTRACTS = (
    Contract("controller table", "controller_table.md", ("axes",), ("torque", "value")),
    Contract("trajectory", "trajectory.md", (), ("t", "state", "control", "controller")),
    Contract(
        "BSR search result",
        "bsr_result.md",
        ("best/controller", "best/figure_motion"),
        ("learning_curve/evaluations", "learning_curve/best_fitness", "best/active_rule"),
    ),
    Contract(  # DESIGN.md's two groups alone: the rest is mosys's own
        "composite result",
        "composite_result.md",
        ("figure_motion", "before/figure_motion"),
        (),
        ("phase", "active_rule", "before/phase", "before/active_rule", "search/best_score"),
    ),
    Contract(
        "start grid",
        "start_grid.md",
        (),
        ("start", "parked", "collided", "parking_seconds", "excluded", "cost_to_go"),
    ),
)
CONTRACT = {contract.name: contract for contract in CONTRACTS}


def kind_of(h5: h5py.File) -> Contract | None:
    """The first contract ``h5`` meets (None: none)."""
    return next((contract for contract in CONTRACTS if contract.met_by(h5)), None)


def open_hdf5(path: str | Path) -> h5py.File:
    """``path`` open for reading (recorded as read by this command); InputError naming the file
    if it is missing, a directory or FIFO, not HDF5 or unreadable (h5py's own messages omit the
    name)."""
    problem = input_problem(path)  # a FIFO would block the open forever
    if problem:
        raise InputError(f"{path}: {problem}, not an HDF5 file")
    try:
        return h5py.File(path, "r")
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except OSError as error:  # not HDF5, truncated, unreadable
        raise InputError(f"{path}: cannot read it as HDF5 ({error})") from None


@contextmanager
def open_contract(path: str | Path, name: str) -> Iterator[h5py.File]:
    """``path`` open for reading as a file of the contract ``name`` (a key of ``CONTRACT``).
    InputError naming the file: missing, not HDF5 or unreadable; of another kind (which) or of
    none (what it lacks); without the datasets of mosys's own its readers need (which); or
    lacking, inside the block, an attribute, group or dataset the reader looks for (h5py's
    KeyError)."""
    contract = CONTRACT[name]
    with open_hdf5(path) as h5:
        missing = contract.missing(h5)
        if missing:
            other = kind_of(h5)
            what = f"a {other.name}" if other is not None else f"it lacks {', '.join(missing)}"
            raise InputError(f"{path}: not a {name} ({what}; docs/formats/{contract.page})")
        lacking = contract.unread(h5)
        if lacking:
            raise InputError(
                f"{path}: a {name} without {', '.join(lacking)}, which mosys reads beside the "
                f"contract (docs/formats/{contract.page})"
            )
        try:
            yield h5
        except KeyError as error:  # an attribute or object the contract's readers need
            raise InputError(f"{path}: a {name} that lacks what mosys reads ({error})") from None
