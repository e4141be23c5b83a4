"""The composite result contract (DESIGN.md, ``results/composite/NAME.h5``).

Beside the contract's ``figure_motion``, ``before/figure_motion`` and root attributes, ours
(documented in the README): ``phase`` and ``before/phase`` (N,) int64, the phase of each sample
(a switch sample belongs to the phase it starts); ``active_rule`` and ``before/active_rule``
(N,) int64, the rule of that phase's controller active at each sample; ``search/best_score``
(G,) float64, the best total after each generation. Root attrs ``name``, ``figure``, ``dt`` (s),
``ticks_before`` and ``ticks_after`` (P,) phase durations in simulator ticks, ``scores_before``
and ``scores_after`` (JSON object: phase -> score; a score a division by zero made non-finite
is the string ``"nan"``, ``"inf"`` or ``"-inf"``, which strict JSON readers take), ``seeds``
(P,) the seed of each phase's controller, ``controller_files``, ``search_q``, ``search_g``,
``search_h``, ``search_seed``, ``budget``, and ``script_text`` (the script as written). Each
entry of ``phases`` also names the phase (``name``), its ``seed`` and its ``ticks``.

Every dataset has a ``unit`` (``index`` for ``phase`` and ``active_rule``, ``1`` for
``search/best_score``) and the root the provenance attrs (``io.provenance``);
docs/formats/composite_result.md.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from mosys.io.atomic import write_hdf5_atomically
from mosys.io.attributes import DIMENSIONLESS, INDEX, create_with_unit, root_attributes
from mosys.io.contracts import open_contract
from mosys.io.provenance import provenance_attributes
from mosys.io.trajectory import FigureMotion, read_figure_motion, write_figure_motion

FORMAT_VERSION = 1


@dataclass(frozen=True)
class CompositeMotion:
    """One concatenation as stored: the figure's motion, the phase (N,) and the active rule (N,)
    at each sample of ``motion.t``."""

    motion: FigureMotion
    phase: np.ndarray
    active_rule: np.ndarray


@dataclass(frozen=True)
class CompositeResult:
    """A refined composite motion and its guess: ``after`` and ``before``, the best total after
    each generation (G,), and the root attributes (the contract's and ours)."""

    after: CompositeMotion
    before: CompositeMotion
    best_by_generation: np.ndarray
    attrs: dict = field(default_factory=dict)

    @property
    def phases(self) -> list[dict]:
        return json.loads(self.attrs["phases"])

    @property
    def phases_before(self) -> list[dict]:
        return json.loads(self.attrs["phases_before"])

    @property
    def scores_before(self) -> dict[str, float]:
        return decode_scores(self.attrs["scores_before"])

    @property
    def scores_after(self) -> dict[str, float]:
        return decode_scores(self.attrs["scores_after"])


def encode_scores(scores: dict[str, float]) -> str:
    """Phase -> score as strict JSON: a non-finite score as the string ``"nan"``, ``"inf"`` or
    ``"-inf"`` (``float``'s own spelling), a finite one as a number."""
    return json.dumps(
        {
            name: value if np.isfinite(value) else str(float(value))
            for name, value in scores.items()
        },
        allow_nan=False,
    )


def decode_scores(text: str) -> dict[str, float]:
    """``encode_scores``'s JSON back to phase -> score (float)."""
    return {name: float(value) for name, value in json.loads(text).items()}


def _write_motion(group: h5py.Group, stored: CompositeMotion) -> None:
    write_figure_motion(group.create_group("figure_motion"), stored.motion)
    create_with_unit(group, "phase", np.asarray(stored.phase, np.int64), INDEX)
    create_with_unit(group, "active_rule", np.asarray(stored.active_rule, np.int64), INDEX)


def _read_motion(group: h5py.Group) -> CompositeMotion:
    return CompositeMotion(
        motion=read_figure_motion(group["figure_motion"]),
        phase=group["phase"][()],
        active_rule=group["active_rule"][()],
    )


def write_composite_result(path: str | Path, result: CompositeResult) -> None:
    """Write a result file atomically."""

    def fill(h5: h5py.File) -> None:
        _write_motion(h5, result.after)
        _write_motion(h5.create_group("before"), result.before)
        search = h5.create_group("search")
        best_score = np.asarray(result.best_by_generation, np.float64)
        create_with_unit(search, "best_score", best_score, DIMENSIONLESS)
        h5.attrs["format_version"] = FORMAT_VERSION
        for key, value in result.attrs.items():
            h5.attrs[key] = value
        h5.attrs.update(provenance_attributes())  # this process wrote it, whatever was read

    write_hdf5_atomically(path, fill)


def read_composite_result(path: str | Path) -> CompositeResult:
    """Read a result file; InputError naming the file if it is not one
    (``contracts.open_contract``)."""
    with open_contract(path, "composite result") as h5:
        return CompositeResult(
            after=_read_motion(h5),
            before=_read_motion(h5["before"]),
            best_by_generation=h5["search/best_score"][()],
            attrs=root_attributes(h5),
        )
