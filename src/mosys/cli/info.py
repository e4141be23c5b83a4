"""``mosys info``: what a result file (.h5) mosys wrote holds."""

from __future__ import annotations

import argparse

from mosys.cli.verb import Family, Verb


def _info_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="an .h5 file mosys wrote")


def _info(args: argparse.Namespace) -> None:
    from mosys.io.info import describe_file

    print(describe_file(args.file), end="")
    lines = physics_lines(args.file)
    if lines:
        print("\nthe paper's rules (README, 'The simulator'), measured:")
        print("\n".join(lines))


def physics_lines(path: str) -> list[str]:
    """For each BSR motion in the file (a search's best motion, a composite's before and
    after): how deep any rod end went below the flat floor and how many lone contacts slid (the
    1995 paper's friction: a lone contact does not slide). A user checking a search of their
    own had to find these functions by hand."""
    import h5py
    import numpy as np

    from mosys.bsr.lone_contact import MAX_EXCURSION, lone_contacts, sliding
    from mosys.io.contracts import open_hdf5
    from mosys.io.trajectory import read_figure_motion
    from mosys.plots.style import counted

    lines = []
    with open_hdf5(path) as h5:
        groups = []
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
            lines.append(
                f"  /{name}: deepest rod end {1000 * depth:.2f} mm below the floor; "
                f"{counted(len(contacts), 'lone contact')}, {len(slid)} of them sliding "
                f"{MAX_EXCURSION * 1000:g} mm or more"
            )
    return lines


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
