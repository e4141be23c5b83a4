"""The BSR search result contract (DESIGN.md, ``results/bsr/NAME/seedK.h5``).

Layout of ``best/controller`` (ours; documented in the README): datasets ``target`` (R, J) deg,
``tau`` (R,) s; sense-based also ``center`` and ``side`` (R, V) in normalised sense units (the
hyper-rectangle of rule i spans ``center ± side/2``); time-based also ``segment`` (R,) s. Group
attrs ``kind``, ``period`` (s, time-based; NaN otherwise), ``joint_names``, ``sense_names``.

Every dataset has a ``unit`` (``1`` for the learning curve and the normalised sense units,
``index`` for ``best/active_rule``, ``SI`` for ``best/final_state``) and the root the provenance
attrs (``io.provenance``); docs/formats/bsr_result.md.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from mosys.io.atomic import write_hdf5_atomically
from mosys.io.attributes import (
    DIMENSIONLESS,
    INDEX,
    SI_STATE,
    create_with_unit,
    root_attributes,
    string_list,
    string_tuple,
)
from mosys.io.contracts import open_contract
from mosys.io.provenance import provenance_attributes
from mosys.io.trajectory import FigureMotion, read_figure_motion, write_figure_motion


@dataclass(frozen=True)
class BsrController:
    """A BSR controller's parameters as arrays (what the kernels read and this file stores).

    A sense-based controller (the 1995 paper's §2.1.2) has R rules, each a stimulus
    hyper-rectangle over the V normalised sense variables, given by its ``center`` (mu) and
    ``side`` (2/lambda) per variable, and a response: a target pose (one angle per joint) and a
    time constant. A time-based controller (§2.3) has R rules, each active for its ``segment`` of
    the period ``t_per``, one after another, the sequence repeating to fill the run.

    R rules. ``target``: (R, J) joint angles, rad; ``tau``: (R,) time constants, s.
    Sense-based: ``center`` and ``side``: (R, V), in normalised sense units; ``segment`` is
    empty. Time-based: ``segment``: (R,) seconds, summing to ``period`` (s); ``center`` and
    ``side`` are (R, 0)."""

    kind: str
    target: np.ndarray
    tau: np.ndarray
    center: np.ndarray
    side: np.ndarray
    segment: np.ndarray
    period: float

    @property
    def rules(self) -> int:
        return int(self.tau.shape[0])

    def copy(self) -> BsrController:
        return BsrController(
            self.kind,
            self.target.copy(),
            self.tau.copy(),
            self.center.copy(),
            self.side.copy(),
            self.segment.copy(),
            self.period,
        )


FORMAT_VERSION = 1


@dataclass(frozen=True)
class BsrResult:
    """One search's result. ``evaluations``/``best_fitness``: (M,) the learning curve;
    ``controller``: the best controller; ``motion``: its motion from the nominal start;
    ``active_rule``: (N,) int64, the rule active at each sample of ``motion.t`` (-1: none);
    ``joint_names`` (J) and ``sense_names`` (V, empty for time-based); ``attrs``: the root
    attributes of the contract plus ours (``name``, ``budget``, ``generations``,
    ``controllers``, ``reseed``, ``rules``, ``period``, ``steps_per_second``, ...);
    ``final_state`` (S,) and ``final_force`` (E,) N: where the best motion ends (simulator
    state and endpoint forces; what a search that continues this one starts from)."""

    evaluations: np.ndarray
    best_fitness: np.ndarray
    controller: BsrController
    motion: FigureMotion
    active_rule: np.ndarray
    joint_names: tuple[str, ...]
    sense_names: tuple[str, ...]
    attrs: dict = field(default_factory=dict)
    final_state: np.ndarray | None = None
    final_force: np.ndarray | None = None

    @property
    def fitness_terms(self) -> dict[str, float]:
        return json.loads(self.attrs["fitness_terms"])

    @property
    def fitness_weights(self) -> dict[str, float]:
        return json.loads(self.attrs["fitness_weights"])


def write_bsr_result(path: str | Path, result: BsrResult) -> None:
    """Write a result file atomically."""

    def fill(h5: h5py.File) -> None:
        curve = h5.create_group("learning_curve")
        evaluations = np.asarray(result.evaluations, np.int64)
        create_with_unit(curve, "evaluations", evaluations, DIMENSIONLESS)
        fitness = np.asarray(result.best_fitness, np.float64)
        create_with_unit(curve, "best_fitness", fitness, DIMENSIONLESS)
        best = h5.create_group("best")
        controller = best.create_group("controller")
        _write_controller(controller, result.controller)
        controller.attrs["joint_names"] = string_list(result.joint_names)
        controller.attrs["sense_names"] = string_list(result.sense_names)
        write_figure_motion(best.create_group("figure_motion"), result.motion)
        create_with_unit(best, "active_rule", np.asarray(result.active_rule, np.int64), INDEX)
        if result.final_state is not None:
            final_state = np.asarray(result.final_state, np.float64)
            create_with_unit(best, "final_state", final_state, SI_STATE)
            final_force = np.asarray(result.final_force, np.float64)
            create_with_unit(best, "final_force", final_force, "N")
        h5.attrs["format_version"] = FORMAT_VERSION
        for key, value in result.attrs.items():
            h5.attrs[key] = value
        h5.attrs.update(provenance_attributes())  # this process wrote it, whatever was read

    write_hdf5_atomically(path, fill)


def _write_controller(group: h5py.Group, controller: BsrController) -> None:
    group.attrs["kind"] = controller.kind
    create_with_unit(group, "target", np.degrees(controller.target), "deg")
    create_with_unit(group, "tau", np.asarray(controller.tau, np.float64), "s")
    if controller.kind == "sense":
        center = np.asarray(controller.center, np.float64)
        create_with_unit(group, "center", center, DIMENSIONLESS)
        create_with_unit(group, "side", np.asarray(controller.side, np.float64), DIMENSIONLESS)
        group.attrs["period"] = float("nan")
    else:
        segment = np.asarray(controller.segment, np.float64)
        create_with_unit(group, "segment", segment, "s")
        group.attrs["period"] = float(controller.period)


def read_bsr_result(path: str | Path) -> BsrResult:
    """Read a result file; InputError naming the file if it is not one
    (``contracts.open_contract``)."""
    with open_contract(path, "BSR search result") as h5:
        group = h5["best/controller"]
        kind = str(group.attrs["kind"])
        rules = group["tau"].shape[0]
        empty = np.zeros((rules, 0))
        controller = BsrController(
            kind=kind,
            target=np.radians(group["target"][()]),
            tau=group["tau"][()],
            center=group["center"][()] if kind == "sense" else empty,
            side=group["side"][()] if kind == "sense" else empty,
            segment=group["segment"][()] if kind == "time" else np.zeros(0),
            period=float(group.attrs["period"]),
        )
        return BsrResult(
            evaluations=h5["learning_curve/evaluations"][()],
            best_fitness=h5["learning_curve/best_fitness"][()],
            controller=controller,
            motion=read_figure_motion(h5["best/figure_motion"]),
            active_rule=h5["best/active_rule"][()],
            joint_names=string_tuple(group.attrs["joint_names"]),
            sense_names=string_tuple(group.attrs["sense_names"]),
            attrs=root_attributes(h5),
            final_state=h5["best/final_state"][()] if "best/final_state" in h5 else None,
            final_force=h5["best/final_force"][()] if "best/final_force" in h5 else None,
        )
