"""BSR search results as the plots read them (``mosys.io.bsr_result``, checked for drawing:
``read_result``), which file of a search's seeds to draw (``best_result_path``,
``group_by_search``) and the texts drawn from them: the controller kind, the fitness function and
its measured terms. Shared by the 2-D plots (``mosys.plots.bsr``, ``mosys.plots.bsr_learning``)
and the 3-D ones.
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path

from mosys.errors import InputError
from mosys.io.bsr_result import BsrResult, read_bsr_result
from mosys.io.contracts import open_hdf5
from mosys.plots.style import PlotInputError, number_text

KIND_TEXT = {"sense": "sense-based", "time": "time-based"}
# fitness terms: (label, unit, format) for the titles; other terms show by name, unitless
TERMS = {
    "distance": ("distance", "m", "+.2f"),
    "rotations": ("rotations", "", ".2f"),
    "contact_distance": ("contact distance", "m", ".2f"),
    "max_height": ("max height", "m", ".2f"),
}
TITLE_WIDTH = 110  # characters of a title line at the learning figures' width


# --------------------------------------------------------------------------- reading the inputs


def read_result(path: str | Path, dimensions: int | None = 2) -> BsrResult:
    """Read a BSR result file and check that its parts agree: PlotInputError naming the file
    and what is missing or malformed. ``dimensions``: those of the figure the plot draws (2:
    endpoints (N, rods, 2, 2); 3: (N, rods, 2, 3)); None: either."""
    try:
        result = read_bsr_result(path)
    except InputError as error:  # missing, not HDF5, another kind of file (io.contracts)
        raise PlotInputError(str(error)) from None
    evaluations, best = result.evaluations, result.best_fitness
    if evaluations.ndim != 1 or evaluations.shape != best.shape or len(evaluations) == 0:
        raise PlotInputError(
            f"{path}: learning_curve/evaluations {evaluations.shape} and best_fitness "
            f"{best.shape} must be one non-empty row each, the same length"
        )
    samples = len(result.motion.t)
    if samples == 0:
        raise PlotInputError(f"{path}: best/figure_motion has no samples")
    drawn = result.motion.dimensions
    if dimensions is not None and drawn != dimensions:
        other = {2: "plot bsr", 3: "plot bsr3d"}.get(drawn)  # the verb that draws it
        raise PlotInputError(
            f"{path}: best/figure_motion is the motion of a {drawn}-D figure; this plot draws "
            f"{dimensions}-D figures" + (f" (mosys {other} draws {drawn}-D ones)" if other else "")
        )
    endpoints = result.motion.endpoints
    if endpoints.ndim != 4 or endpoints.shape[0] != samples or endpoints.shape[2:] != (2, drawn):
        raise PlotInputError(
            f"{path}: best/figure_motion/endpoints has shape {endpoints.shape}, expected "
            f"({samples}, rods, 2, {drawn}): one row per sample of t"
        )
    if result.active_rule.shape != (samples,):
        raise PlotInputError(
            f"{path}: best/active_rule has shape {result.active_rule.shape}, expected "
            f"({samples},): one rule per sample of best/figure_motion/t"
        )
    for key in ("controller_kind", "seed", "best_fitness"):
        if key not in result.attrs:
            raise PlotInputError(f"{path}: no root attribute {key!r}")
    return result


def root_attrs(path: str | Path) -> dict:
    """A result file's root attributes, without reading its datasets."""
    try:
        with open_hdf5(path) as h5:
            return {key: h5.attrs[key] for key in h5.attrs}
    except InputError as error:  # missing, unreadable, not HDF5
        raise PlotInputError(str(error)) from None


def search_name(attrs: Mapping, path: str | Path) -> str:
    """A result's search name: its ``name`` attribute, else the folder it is in
    (``results/bsr/NAME/seedK.h5``)."""
    return str(attrs["name"]) if "name" in attrs else Path(path).parent.name


def motion_fitness(attrs: Mapping) -> float:
    """The fitness of the motion a result records: ``nominal_fitness`` (the best controller
    run from the spec's start), else ``best_fitness``. They are the same unless the search's
    starts were perturbed (a ``perturb`` line); then ``best_fitness`` is one lucky perturbed
    draw's, not that of the recorded motion, whose ``fitness_terms`` add up to
    ``nominal_fitness`` (and the composite chooses its seed by it)."""
    key = "nominal_fitness" if "nominal_fitness" in attrs else "best_fitness"
    return float(attrs[key])


def best_result_path(paths: Sequence[str | Path]) -> Path:
    """The result whose recorded motion scores best (``motion_fitness``: from the nominal
    start, as the composite chooses), ties to the lowest ``seed``."""
    if not paths:
        raise PlotInputError("no BSR result files given")
    ranked = []
    for path in paths:
        attrs = root_attrs(path)
        for key in ("best_fitness", "seed"):
            if key not in attrs:
                raise PlotInputError(f"{path}: not a BSR result file: no root attribute {key!r}")
        ranked.append((-motion_fitness(attrs), int(attrs["seed"]), str(path)))
    return Path(min(ranked)[2])


def group_by_search(paths: Sequence[str | Path]) -> dict[str, list[Path]]:
    """The result files grouped by search (``search_name``), in the order first met."""
    groups: dict[str, list[Path]] = {}
    for path in paths:
        groups.setdefault(search_name(root_attrs(path), path), []).append(Path(path))
    return groups


def fitness_formula(weights: Mapping[str, float]) -> str:
    """``fitness = 1·distance + 0.5·max_height − 2·rotations`` from term -> weight (zero
    weights left out)."""
    parts = []
    for term, weight in weights.items():
        if weight == 0:
            continue
        sign = "−" if weight < 0 else "+"
        parts.append((sign, f"{abs(weight):g}·{term}"))
    if not parts:
        return "fitness = 0"
    text = ("−" if parts[0][0] == "−" else "") + parts[0][1]
    text += "".join(f" {sign} {part}" for sign, part in parts[1:])
    return f"fitness = {text}"


def wrapped(text: str, width: int = TITLE_WIDTH) -> str:
    """``text`` broken into lines of at most ``width`` characters (a long fitness formula or
    list of terms would run off the figure)."""
    return textwrap.fill(text, width, break_on_hyphens=False)


def terms_text(
    terms: Mapping[str, float], known: Mapping[str, tuple[str, str, str]] = TERMS
) -> str:
    """The measured fitness terms with their units, those ``known`` (term -> label, unit,
    format; default the four of the 2-D contract) first, in its order."""
    shown = [name for name in known if name in terms]
    shown += [name for name in terms if name not in known]
    parts = []
    for name in shown:
        label, unit, fmt = known.get(name, (name.replace("_", " "), "", ".3g"))
        value = number_text(float(terms[name]), fmt)
        parts.append(f"{label} {value}{' ' + unit if unit else ''}")
    return ", ".join(parts)


def result_kind(result: BsrResult) -> str:
    """The result's controller kind (``time`` or ``sense``), as its file says it."""
    return str(result.attrs.get("controller_kind", result.controller.kind))
