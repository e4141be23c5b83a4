"""The 1995 paper's physical rules measured on the BSR motions a result file holds (``mosys
info``): how deep any rod end went below the flat floor, and how many lone contacts slid (its
friction: a lone contact does not slide; ``mosys.bsr.lone_contact``)."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from mosys.bsr.lone_contact import MAX_EXCURSION, lone_contacts, sliding
from mosys.io.contracts import open_hdf5
from mosys.io.trajectory import read_figure_motion


def rule_lines(path: str | Path) -> list[str]:
    """A line for each BSR motion in the file (a ``figure_motion`` group made by a BSR
    simulator over a flat floor: a search's best motion, a composite's before and after): its
    group, its deepest rod end below the floor (mm) and its lone contacts, how many of them
    slid MAX_EXCURSION or more; none for a file without such a motion. Raises InputError for a
    file that cannot be read (``open_hdf5``)."""
    lines = []
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
            slid = sliding(contacts)
            noun = "lone contact" if len(contacts) == 1 else "lone contacts"
            lines.append(
                f"  /{name}: deepest rod end {1000 * depth:.2f} mm below the floor; "
                f"{len(contacts)} {noun}, {len(slid)} of them sliding "
                f"{MAX_EXCURSION * 1000:g} mm or more"
            )
    return lines
