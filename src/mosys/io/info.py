"""What a file mosys wrote holds (``mosys info``): which contract it meets, its axes or columns
with their units, its root attributes, and every group and dataset with its shape, dtype, unit
and a summary of its values (docs/formats/).

Values are read a block of rows at a time (about a million elements), so a car table of
840,840 nodes is summarised in a fraction of a second and memory stays small.
"""

from __future__ import annotations

import json
import textwrap
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

import h5py
import numpy as np

from mosys.errors import InputError
from mosys.io.attributes import MIXED, string_attr, string_tuple
from mosys.io.contracts import CONTRACTS, Contract, kind_of
from mosys.io.provenance import PROVENANCE_KEYS

BLOCK_ELEMENTS = 1 << 20  # values read at a time
ATTR_WIDTH = 76  # a shown attribute value is cut to this many characters
# a controller table's datasets with the axes attached as dimension scales
PER_NODE = ("value", "torque", "dead_end", "destination_index", "arrival_value")
# attributes HDF5 dimension scales keep for themselves (shown as the axes section instead)
SCALE_ATTRS = {"CLASS", "NAME", "REFERENCE_LIST", "DIMENSION_LIST", "DIMENSION_LABELS"}


def describe_file(path: str | Path) -> str:
    """The report ``mosys info`` prints. InputError (naming ``path``) for a missing file, a
    file that is not HDF5, or an HDF5 file that meets none of the contracts."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such file" if not path.exists() else f"{path}: not a file")
    try:
        if not h5py.is_hdf5(path):
            raise InputError(
                f"{path}: not an HDF5 file (mosys info reads the .h5 files mosys writes)"
            )
        with h5py.File(path, "r") as h5:
            contract = kind_of(h5)
            if contract is None:
                known = ", ".join(c.name for c in CONTRACTS)
                raise InputError(
                    f"{path}: an HDF5 file, but not one mosys writes: it has the groups and "
                    f"datasets of none of its kinds ({known}; docs/formats/)"
                )
            return _report(path, h5, contract)
    except (OSError, RuntimeError, KeyError) as error:  # h5py on a damaged file
        raise InputError(f"{path}: cannot read it as HDF5 ({error})") from None


def _report(path: Path, h5: h5py.File, contract: Contract) -> str:
    attrs = h5.attrs
    version = f", format_version {attrs['format_version']}" if "format_version" in attrs else ""
    lines = [f"{path}: {contract.name}{version} (docs/formats/{contract.page})"]
    made = [
        f"{key.removesuffix('_version')} {string_attr(attrs[key])}"
        for key in PROVENANCE_KEYS
        if key.endswith("_version") and key in attrs
    ]
    if "git_commit" in attrs:
        commit = f"git {string_attr(attrs['git_commit'])[:12]}"
        made = [f"{made[0]} ({commit})", *made[1:]] if made else [commit]
    lines.append(f"made by: {', '.join(made) or 'no provenance recorded (an older mosys)'}")
    if "spec_sha256" in attrs:
        lines.append(f"spec_sha256: {string_attr(attrs['spec_sha256'])}")
    summaries = {name: summarise(h5[name]) for name in _dataset_paths(h5)}
    sections_of = {
        "controller table": _table_sections,
        "trajectory": _trajectory_sections,
        "start grid": _start_grid_sections,
        "BSR search result": _bsr_sections,
        "composite result": _composite_sections,
    }[contract.name]
    try:
        sections = sections_of(h5, summaries)
    except (KeyError, IndexError, TypeError, ValueError, AttributeError) as error:
        # it has the contract's datasets but not all its attributes or shapes: say so, and
        # list what it holds below
        problem = f"  the file does not fully meet the contract ({type(error).__name__}: {error})"
        sections = [("(no summary):", [problem])]
    for title, body in sections:
        lines += ["", title, *body]
    lines += ["", f"root attributes ({len(attrs)}):"]
    lines += _attr_lines(attrs, "  ")
    lines += ["", "groups and datasets:"]
    lines += _dataset_lines(h5, summaries)
    return "\n".join(lines) + "\n"


# --- the per-contract sections ----------------------------------------------------------------


def _table_sections(h5: h5py.File, summaries: dict) -> list[tuple[str, list[str]]]:
    names = _names(h5.attrs, "state_order") or tuple(h5["axes"])
    rows = [("name", "unit", "min", "max", "count", "step", "wrap")]
    for name in names:
        axis = h5["axes"].get(name)
        if not isinstance(axis, h5py.Dataset):
            rows.append((name, "-", "(no /axes dataset)", "", "", "", ""))
            continue
        values = np.asarray(axis[()], dtype=np.float64).ravel()
        step = (values[-1] - values[0]) / (len(values) - 1) if len(values) > 1 else np.nan
        wrap = bool(axis.attrs.get("wrap", False))
        rows.append(
            (
                name,
                _unit(axis),
                _number(values.min()) if len(values) else "-",
                _number(values.max()) if len(values) else "-",
                str(len(values)),
                _number(step),
                f"yes (period {_number(step * len(values))})" if wrap else "no",
            )
        )
    axes = _table(rows)
    scaled = [
        (dataset.name, ", ".join(d.label or "?" for d in dataset.dims))
        for dataset in (h5.get(n) for n in PER_NODE)
        if isinstance(dataset, h5py.Dataset) and any(len(d) for d in dataset.dims)
    ]
    scales = _table([("dataset", "dimensions"), *scaled]) if scaled else ["  none attached"]
    controls = _names(h5.attrs, "control_names")
    units = _column_units(h5["torque"], len(controls))
    rows = [("name", "unit", "min", "max", "K", "torque in table")]
    bounds = [np.atleast_1d(h5.attrs.get(key, [])) for key in ("control_min", "control_max", "K")]
    torque = summaries["torque"]
    for k, name in enumerate(controls):
        low, high, weight = (_number(b[k]) if k < len(b) else "-" for b in bounds)
        rows.append((name, units[k], low, high, weight, torque.column_range(k)))
    sections = [
        ("axes (state_order):", axes),
        ("dimension scales (the /axes datasets):", scales),
        ("controls (control_names):", _table(rows)),
    ]
    if "dest" in h5.attrs:
        sections.append(("destination:", ["  " + _shorten(string_attr(h5.attrs["dest"]))]))
    return sections


def _trajectory_sections(h5: h5py.File, summaries: dict) -> list[tuple[str, list[str]]]:
    t = summaries["t"]
    samples = [f"  {h5['t'].shape[0] if h5['t'].ndim else 1} samples, t {t.range()} s"]
    controllers = _names(h5.attrs, "controllers")
    if controllers:
        samples.append(f"  controllers: {', '.join(controllers)}")
    sections = [
        ("samples:", samples),
        ("state columns (state_order):", _columns(h5, "state", "state_order", summaries)),
        ("control columns (control_names):", _columns(h5, "control", "control_names", summaries)),
    ]
    return sections + _motion_sections(h5, summaries)


def _start_grid_sections(h5: h5py.File, summaries: dict) -> list[tuple[str, list[str]]]:
    excluded = h5["excluded"].asstr()[()] if h5["excluded"].dtype.kind in "OSU" else None
    parked = np.asarray(h5["parked"][()], dtype=bool)
    starts = [f"  {parked.size} starts, {int(parked.sum())} parked"]
    if excluded is not None:
        counted = np.asarray(excluded == "")
        starts[0] += f"; {int(counted.sum())} counted (not excluded)"
        if counted.any():
            starts.append(f"  success rate {parked[counted].mean():.1%} of the counted starts")
    return [
        ("starts:", starts),
        ("start columns (state_order):", _columns(h5, "start", "state_order", summaries)),
    ]


def _bsr_sections(h5: h5py.File, summaries: dict) -> list[tuple[str, list[str]]]:
    controller = h5["best/controller"]
    joints = _names(controller.attrs, "joint_names")
    kind = string_attr(controller.attrs.get("kind", h5.attrs.get("controller_kind", "?")))
    rules = controller["tau"].shape[0] if isinstance(controller.get("tau"), h5py.Dataset) else "?"
    search = [
        f"  {kind}-based controller, {rules} rules, joints: {', '.join(joints) or '-'}",
        f"  learning curve: {h5['learning_curve/evaluations'].size} points, evaluations "
        f"{summaries['learning_curve/evaluations'].range()}, best fitness "
        f"{summaries['learning_curve/best_fitness'].range()}",
        *_fitness_terms_lines(h5.attrs),
    ]
    return [("search:", search), *_motion_sections(h5, summaries)]


def _fitness_terms_lines(attrs: h5py.AttributeManager) -> list[str]:
    """The measured fitness terms in full, each with its weight where the spec gave one,
    wrapped at 100 characters (the root attribute's line is cut); none if they are unreadable
    (the attribute lines below show what is there)."""
    try:
        terms = json.loads(string_attr(attrs["fitness_terms"]))
        weights = json.loads(string_attr(attrs.get("fitness_weights", "{}")))
        parts = [
            f"{name} {_number(value)}"
            + (f" (weight {_number(weights[name])})" if name in weights else "")
            for name, value in terms.items()
        ]
    except (KeyError, ValueError, TypeError, AttributeError):
        return []
    text = "fitness terms of the best motion: " + ", ".join(parts)
    return textwrap.wrap(text, 100, initial_indent="  ", subsequent_indent="    ")


def _composite_sections(h5: h5py.File, summaries: dict) -> list[tuple[str, list[str]]]:
    sections = []
    for key, title in (("phases_before", "guessed"), ("phases", "refined")):
        try:
            phases = json.loads(string_attr(h5.attrs[key]))
            rows = [("phase", "controller", "start (s)", "end (s)")] + [
                (
                    str(phase.get("name", k)),
                    str(phase.get("controller", "?")),
                    _number(phase.get("start", np.nan)),
                    _number(phase.get("end", np.nan)),
                )
                for k, phase in enumerate(phases)
            ]
        except (KeyError, ValueError, TypeError, AttributeError):
            continue  # absent or not a JSON list of objects: the root attributes show it
        sections.append((f"phases, {title} ({key}):", _table(rows)))
    return sections + _motion_sections(h5, summaries)


def _motion_sections(h5: h5py.File, summaries: dict) -> list[tuple[str, list[str]]]:
    """One line per ``figure_motion`` group: samples, time span, rods."""
    lines = []
    for name in _group_paths(h5):
        group = h5[name]
        if not name.endswith("figure_motion") or not isinstance(group.get("t"), h5py.Dataset):
            continue
        rods = _names(group.attrs, "rod_names")
        dimensions = int(group.attrs.get("dimensions", 2))
        lines.append(
            f"  /{name}: {group['t'].shape[0] if group['t'].ndim else 1} samples, "
            f"t {summaries[name + '/t'].range()} s, {dimensions}-D, "
            f"{len(rods)} rod{'s' if len(rods) != 1 else ''} ({', '.join(rods)})"
        )
    return [("figure motion (docs/formats/figure_motion.md):", lines)] if lines else []


def _columns(h5: h5py.File, dataset: str, names_attr: str, summaries: dict) -> list[str]:
    names = _names(h5.attrs, names_attr)
    width = h5[dataset].shape[-1] if h5[dataset].ndim else 0
    names = names if len(names) == width else tuple(f"[{k}]" for k in range(width))
    units = _column_units(h5[dataset], width)
    rows = [("name", "unit", "min", "max")]
    for k, name in enumerate(names):
        rows.append((name, units[k], *summaries[dataset].column_bounds(k)))
    return _table(rows)


# --- summaries of values ----------------------------------------------------------------------


class Summary:
    """What a dataset's values are, gathered a block at a time: for numbers the finite min and
    max (overall and per entry of the last axis), NaN and ±inf counts; for booleans the trues;
    for strings the commonest values."""

    def __init__(self, dataset: h5py.Dataset):
        self.kind = _value_kind(dataset)
        self.size = int(dataset.size or 0)
        self.nan = self.posinf = self.neginf = self.true = 0
        self.low: np.ndarray | None = None  # per column (last axis), finite values only
        self.high: np.ndarray | None = None
        self.strings: Counter = Counter()

    def add(self, block: np.ndarray) -> None:
        if self.kind == "bool":
            self.true += int(np.count_nonzero(block))
        elif self.kind == "string":
            self.strings.update(block.ravel().tolist())
        elif self.kind in ("float", "int"):
            self._add_numbers(block)

    def _add_numbers(self, block: np.ndarray) -> None:
        columns = block.reshape(-1, block.shape[-1]) if block.ndim >= 2 else block.reshape(-1, 1)
        if self.kind == "float" and not np.isfinite(columns).all():
            nan = np.isnan(columns)
            self.nan += int(nan.sum())
            self.posinf += int(np.count_nonzero(columns == np.inf))
            self.neginf += int(np.count_nonzero(columns == -np.inf))
            finite = ~nan & np.isfinite(columns)
            low = np.where(finite, columns, np.inf).min(axis=0)
            high = np.where(finite, columns, -np.inf).max(axis=0)
        else:
            low, high = columns.min(axis=0), columns.max(axis=0)
        low, high = low.astype(np.float64), high.astype(np.float64)
        self.low = low if self.low is None else np.minimum(self.low, low)
        self.high = high if self.high is None else np.maximum(self.high, high)

    def range(self) -> str:
        """``min … max`` of the finite values, ``-`` when there are none."""
        if self.low is None or not np.isfinite(self.low).any():
            return "-"
        low, high = _number(self.low.min()), _number(self.high.max())
        return low if low == high else f"{low} … {high}"

    def column_bounds(self, k: int) -> tuple[str, str]:
        """The finite min and max of entry ``k`` of the last axis (``-`` when none)."""
        if self.low is None or k >= len(self.low) or not np.isfinite(self.low[k]):
            return "-", "-"
        return _number(self.low[k]), _number(self.high[k])

    def column_range(self, k: int) -> str:
        """``min … max`` of the finite values of entry ``k`` of the last axis."""
        low, high = self.column_bounds(k)
        return low if low == high else f"{low} … {high}"

    def text(self, by_column: bool = False) -> str:
        """The summary; ``by_column``: the columns have different units, so no overall range
        (the per-column ranges are in the columns section)."""
        if self.size == 0:
            return "empty"
        if self.kind == "bool":
            return f"{self.true} true, {self.size - self.true} false"
        if self.kind == "string":
            common = ", ".join(
                f"{json.dumps(_shorten(value, 28, counted=False), ensure_ascii=False)} ×{count}"
                for value, count in self.strings.most_common(3)
            )
            more = len(self.strings) - 3
            return f"{len(self.strings)} distinct: {common}" + (
                f", +{more} more" if more > 0 else ""
            )
        if self.kind not in ("float", "int"):
            return "-"
        if self.kind == "int":
            return self.range()
        counts = [(self.nan, "nan"), (self.posinf, "+inf"), (self.neginf, "-inf")]
        special = ", ".join(f"{count} {what}" for count, what in counts if count)
        return f"{'by column (above)' if by_column else self.range()}; {special or 'all finite'}"


def summarise(dataset: h5py.Dataset) -> Summary:
    """``mosys info``'s summary of one dataset, read block by block (a dataset of another kind
    than numbers, booleans or strings is only named)."""
    summary = Summary(dataset)
    if summary.kind != "other":
        for block in _blocks(dataset, summary.kind):
            summary.add(block)
    return summary


def _value_kind(dataset: h5py.Dataset) -> str:
    dtype = dataset.dtype
    if h5py.check_string_dtype(dtype) is not None or dtype.kind in "SU":
        return "string"
    if dtype.kind == "b":
        return "bool"
    if dtype.kind == "f":
        return "float"
    if dtype.kind in "iu":
        return "int"
    return "other"  # compound, references, enums...


def _blocks(dataset: h5py.Dataset, kind: str) -> Iterator[np.ndarray]:
    """The dataset's values a block of leading rows at a time (strings decoded)."""
    source = dataset.asstr() if kind == "string" else dataset
    if dataset.shape is None or dataset.size == 0:
        return
    if dataset.ndim == 0:
        yield np.asarray(source[()])
        return
    row = max(1, int(np.prod(dataset.shape[1:])))
    step = max(1, BLOCK_ELEMENTS // row)
    for start in range(0, dataset.shape[0], step):
        yield np.asarray(source[start : start + step])


# --- formatting -------------------------------------------------------------------------------


def _dataset_lines(h5: h5py.File, summaries: dict) -> list[str]:
    rows = [("path", "shape", "dtype", "unit", "summary")]
    extra: dict[int, list[str]] = {}
    for name in _all_paths(h5):
        item = h5[name]
        if isinstance(item, h5py.Group):
            rows.append((f"/{name}/", "group", "", "", f"{len(item.attrs)} attrs"))
            extra[len(rows) - 1] = _attr_lines(item.attrs, "    ")
        else:
            dtype = "string" if summaries[name].kind == "string" else str(item.dtype)
            mixed = item.attrs.get("unit") == MIXED
            summary = summaries[name].text(by_column=mixed)
            rows.append((f"/{name}", str(item.shape), dtype, _unit(item), summary))
    table = _table(rows)
    lines = []
    for k, line in enumerate(table):
        lines.append(line)
        lines += extra.get(k, [])
    return lines


def _attr_lines(attrs: h5py.AttributeManager, indent: str) -> list[str]:
    keys = sorted(key for key in attrs if key not in SCALE_ATTRS)
    width = max((len(key) for key in keys), default=0)
    return [f"{indent}{key.ljust(width)}  {_attr_value(attrs[key])}" for key in keys]


def _attr_value(value) -> str:
    if isinstance(value, bytes | str):
        return _shorten(string_attr(value)) or '""'  # an empty string, visibly
    array = np.asarray(value)
    if array.dtype.kind in "OSU":
        return _shorten("[" + ", ".join(string_tuple(array)) + "]" if array.ndim else str(value))
    if array.ndim == 0:
        return _number(array.item()) if array.dtype.kind == "f" else str(array.item())
    if array.dtype.kind not in "fiub" or array.ndim > 1:
        return _shorten(" ".join(str(array.tolist()).split()))
    shown = [_number(v) if array.dtype.kind == "f" else str(v) for v in array[:12].tolist()]
    more = f", … ({array.size} values)" if array.size > 12 else ""
    return _shorten(f"[{', '.join(shown)}{more}]")


def _shorten(text: str, width: int = ATTR_WIDTH, counted: bool = True) -> str:
    """``text`` on one line, cut to ``width`` characters (``…``, and its length if ``counted``)."""
    text = text.replace("\n", "\\n")
    if len(text) <= width:
        return text
    return f"{text[: width - 1]}…" + (f" ({len(text)} chars)" if counted else "")


def _number(value) -> str:
    value = float(value)
    return "nan" if np.isnan(value) else f"{value:.6g}"


def _unit(dataset: h5py.Dataset) -> str:
    if "units" in dataset.attrs:
        return ", ".join(string_tuple(dataset.attrs["units"]))
    return string_attr(dataset.attrs["unit"]) if "unit" in dataset.attrs else "-"


def _column_units(dataset: h5py.Dataset, count: int) -> tuple[str, ...]:
    """One unit per column: ``units``, else the single ``unit`` repeated, else ``-``."""
    if "units" in dataset.attrs:
        units = string_tuple(dataset.attrs["units"])
        if len(units) == count:
            return units
    unit = string_attr(dataset.attrs["unit"]) if "unit" in dataset.attrs else "-"
    return (unit,) * count


def _names(attrs: h5py.AttributeManager, key: str) -> tuple[str, ...]:
    return string_tuple(attrs[key]) if key in attrs else ()


def _table(rows: list[tuple[str, ...]]) -> list[str]:
    widths = [max(len(row[k]) for row in rows) for k in range(len(rows[0]))]
    return [
        "  "
        + "  ".join(cell.ljust(width) for cell, width in zip(row, widths, strict=True)).rstrip()
        for row in rows
    ]


def _all_paths(h5: h5py.File) -> list[str]:
    names: list[str] = []
    h5.visit(names.append)
    return names


def _dataset_paths(h5: h5py.File) -> list[str]:
    return [name for name in _all_paths(h5) if isinstance(h5[name], h5py.Dataset)]


def _group_paths(h5: h5py.File) -> list[str]:
    return [name for name in _all_paths(h5) if isinstance(h5[name], h5py.Group)]
