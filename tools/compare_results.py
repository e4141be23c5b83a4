"""Compare two results/ trees built by the pipeline, file by file: every HDF5 dataset and
attribute, every CSV and Markdown table cell, every PNG's and GIF's pixels (frame by frame),
every generated module, every other file's bytes.

    python tools/compare_results.py OLD/results NEW/results

Timings differ from build to build, so values under keys that measure the machine (wall and
generation seconds, peak memory, speed-ups, rates) are reported apart as "timing" and do not make
the trees differ; everything else must be identical (arrays bit for bit, NaN equal to NaN). Logs
and Snakemake's benchmark files are timings throughout and are skipped. Exit 0 when the trees
agree, 1 when they differ (each difference printed), 2 on bad arguments.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
from PIL import Image, ImageSequence

# names of values that measure the machine, not the motion (attributes and CSV columns)
TIMING = re.compile(
    r"wall|generation_s|iteration_seconds|transition_seconds|load_seconds|peak_rss|speed-?up|"
    r"ms per|"
    r"per[ _]second|40k evaluations",
    re.IGNORECASE,
)
SKIPPED_DIRS = {"logs", "benchmarks"}
# plots that print a measured time (the transition search's wall seconds): their pixels differ
# between any two builds, so a difference there is reported as a timing
TIMED_PLOTS = ("plots/composite/*/search.png",)


def same(a, b) -> bool:
    """Bit-for-bit equality of two values read from files (arrays, scalars, strings)."""
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind == "f" or a.dtype.kind == "c":
        return bool(np.array_equal(a, b, equal_nan=True))
    return bool(np.array_equal(a, b))


def dereferenced(h5file: h5py.File, value):
    """An attribute's value with every object reference (the bookkeeping of HDF5 dimension
    scales: DIMENSION_LIST, REFERENCE_LIST) replaced by the name of the object it points to, so
    that two files' references compare by what they point at."""
    if isinstance(value, h5py.Reference):
        return h5file[value].name if value else ""
    if isinstance(value, np.void) and value.dtype.names:
        return tuple(dereferenced(h5file, value[field]) for field in value.dtype.names)
    if isinstance(value, np.ndarray) and value.dtype.kind in "OV":
        return repr([dereferenced(h5file, item) for item in value])  # ragged: compared as text
    return value


def compare_h5(old: Path, new: Path) -> tuple[list[str], list[str]]:
    """(differences, timing differences) between two HDF5 files."""
    differences: list[str] = []
    timings: list[str] = []

    def attrs(name: str, a, b, file_a: h5py.File, file_b: h5py.File) -> None:
        for key in sorted(set(a) | set(b)):
            where = f"{name}@{key}"
            if key not in a or key not in b:
                differences.append(f"{where}: only in {'new' if key in b else 'old'}")
            elif not same(dereferenced(file_a, a[key]), dereferenced(file_b, b[key])):
                (timings if TIMING.search(key) else differences).append(f"{where} differs")

    with h5py.File(old, "r") as a, h5py.File(new, "r") as b:
        names_a: list[str] = []
        names_b: list[str] = []
        a.visit(names_a.append)
        b.visit(names_b.append)
        for name in sorted(set(names_a) | set(names_b)):
            if name not in a or name not in b:
                differences.append(f"/{name}: only in {'new' if name in b else 'old'}")
                continue
            x, y = a[name], b[name]
            both_datasets = isinstance(x, h5py.Dataset) and isinstance(y, h5py.Dataset)
            if both_datasets and not same(x[()], y[()]):
                (timings if TIMING.search(name) else differences).append(f"/{name} differs")
            attrs(f"/{name}", x.attrs, y.attrs, a, b)
        attrs("/", a.attrs, b.attrs, a, b)
    return differences, timings


def compare_csv(old: Path, new: Path) -> tuple[list[str], list[str]]:
    a, b = pd.read_csv(old, dtype=str), pd.read_csv(new, dtype=str)
    if list(a.columns) != list(b.columns) or len(a) != len(b):
        return [f"columns or rows differ: {list(a.columns)} x {len(a)} vs {list(b.columns)}"], []
    differences, timings = [], []
    for column in a.columns:
        if not a[column].fillna("").equals(b[column].fillna("")):
            (timings if TIMING.search(column) else differences).append(f"column {column!r}")
    return differences, timings


def compare_markdown(old: Path, new: Path) -> tuple[list[str], list[str]]:
    """Markdown tables: the rows' cells, with timing columns (by their header) set apart."""
    a, b = old.read_text().splitlines(), new.read_text().splitlines()
    if len(a) != len(b):
        return [f"{len(a)} lines vs {len(b)}"], []
    header: list[str] = []
    differences, timings = [], []
    for line_a, line_b in zip(a, b, strict=True):
        cells_a = [c.strip() for c in line_a.strip().strip("|").split("|")]
        cells_b = [c.strip() for c in line_b.strip().strip("|").split("|")]
        if line_a.startswith("|") and not header:
            header = cells_a
        if line_a == line_b:
            continue
        if len(cells_a) != len(cells_b) or len(cells_a) != len(header):
            differences.append(f"line differs: {line_a!r}")
            continue
        key_value = len(header) == 2 and header[1].lower() == "value"  # a row per quantity
        for name, x, y in zip(header, cells_a, cells_b, strict=True):
            if x != y:
                name = cells_a[0] if key_value else name
                (timings if TIMING.search(name) else differences).append(f"column {name!r}")
    return sorted(set(differences)), sorted(set(timings))


def compare_image(old: Path, new: Path) -> tuple[list[str], list[str]]:
    """PNG and GIF: every frame's pixels and (GIF) every frame's duration."""
    with Image.open(old) as a, Image.open(new) as b:
        frames_a = [
            (np.asarray(f.convert("RGBA")), f.info.get("duration"))
            for f in ImageSequence.Iterator(a)
        ]
        frames_b = [
            (np.asarray(f.convert("RGBA")), f.info.get("duration"))
            for f in ImageSequence.Iterator(b)
        ]
    if len(frames_a) != len(frames_b):
        return [f"{len(frames_a)} frames vs {len(frames_b)}"], []
    for k, ((pa, da), (pb, db)) in enumerate(zip(frames_a, frames_b, strict=True)):
        if da != db or pa.shape != pb.shape or not np.array_equal(pa, pb):
            return [f"frame {k} differs"], []
    return [], []


def compare_text(old: Path, new: Path) -> tuple[list[str], list[str]]:
    return ([] if old.read_bytes() == new.read_bytes() else ["bytes differ"]), []


COMPARERS = {
    ".h5": compare_h5,
    ".csv": compare_csv,
    ".md": compare_markdown,
    ".png": compare_image,
    ".gif": compare_image,
}


def files(root: Path) -> set[Path]:
    return {
        p.relative_to(root)
        for p in root.rglob("*")
        if p.is_file() and p.relative_to(root).parts[0] not in SKIPPED_DIRS
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    args = parser.parse_args(argv)
    for root in (args.old, args.new):
        if not root.is_dir():
            print(f"compare_results: {root}: not a directory", file=sys.stderr)
            return 2
    old, new = files(args.old), files(args.new)
    differing = 0
    for only, side in ((old - new, "old"), (new - old, "new")):
        for path in sorted(only):
            print(f"{path}: only in {side}")
            differing += 1
    counts: dict[str, int] = {}
    for path in sorted(old & new):
        compare = COMPARERS.get(path.suffix, compare_text)
        differences, timings = compare(args.old / path, args.new / path)
        if differences and any(path.match(pattern) for pattern in TIMED_PLOTS):
            differences, timings = [], [f"pixels ({differences[0]}; the plot prints a time)"]
        counts[path.suffix or "(none)"] = counts.get(path.suffix or "(none)", 0) + 1
        for line in differences:
            print(f"{path}: {line}")
        if timings:
            print(f"{path}: timing only: {', '.join(timings)}")
        differing += bool(differences)
    summary = ", ".join(f"{n} {suffix}" for suffix, n in sorted(counts.items()))
    verdict = "identical" if not differing else f"{differing} files differ"
    print(f"compared {sum(counts.values())} files ({summary}): {verdict}")
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main())
