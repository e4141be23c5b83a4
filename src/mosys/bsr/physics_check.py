"""The 1995 paper's physical rules measured on the BSR motions a result file holds (``mosys
info``): how deep any rod end went below the flat floor, and how many lone contacts slid (its
friction: a lone contact does not slide; ``mosys.bsr.lone_contact``)."""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import h5py
import numpy as np

from mosys.bsr.lone_contact import lone_contacts, sliding
from mosys.io.contracts import open_hdf5
from mosys.io.trajectory import read_figure_motion


class RulesMeasured(NamedTuple):
    """The rules measured on one BSR motion: its group in the file, its deepest rod end below
    the floor (m, >= 0), its lone contacts and how many of them slid
    ``lone_contact.MAX_EXCURSION`` or more."""

    group: str
    depth: float
    lone_contacts: int
    sliding: int


def measure_rules(path: str | Path) -> list[RulesMeasured]:
    """The rules measured on each BSR motion in the file (a ``figure_motion`` group made by a
    BSR simulator over a flat floor: a search's best motion, a composite's before and after);
    none for a file without such a motion. Raises InputError for a file that cannot be read
    (``open_hdf5``)."""
    measured = []
    with open_hdf5(path) as h5:
        groups: list[str] = []
        h5.visititems(
            lambda name, item: groups.append(name) if isinstance(item, h5py.Group) else None
        )
        for name in groups:
            group = h5[name]
            contact = str(group.attrs.get("contact", ""))
            if not name.endswith("figure_motion") or not contact.startswith("bsr"):
                continue
            motion = read_figure_motion(group)
            floor = {float(vertex[1]) for vertex in motion.terrain} or {0.0}
            if len(floor) != 1:  # not a flat floor: the rules are the flat floor's
                continue
            height = floor.pop()
            depth = max(0.0, height - float(np.min(motion.endpoints[..., 1])))
            contacts = lone_contacts(motion.t, motion.endpoints, height)
            measured.append(RulesMeasured(name, depth, len(contacts), len(sliding(contacts))))
    return measured
