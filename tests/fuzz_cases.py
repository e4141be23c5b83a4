"""The verb fuzz suite's cases and runner (issue 27; tests/test_fuzz_verbs.py runs it).

A case is a shipped spec of one kind mutated by hypothesis (numbers made extreme, tokens and
lines deleted, duplicated, swapped or borrowed from other specs, unknown keywords, truncation,
binary bytes, invalid UTF-8, 100 kB lines, deeply nested composite expressions), or a numeric
command-line option made hostile, together with the ``mosys`` command lines that run it: one
``Step`` (argv, the outputs it writes, the HDF5 contract they follow) or two (``compile`` a mutated
figure, then ``run`` a script on it; or any verb, then draw what it wrote: ``plot script``,
``plot car`` (frames; a start grid's map), ``plot controller``, ``plot bsr``, ``plot bsr3d``,
``plot composite``).

``Pool`` runs cases in long-lived worker processes (spawned, so nothing of pytest's process leaks
in): each worker calls ``mosys.cli.main(argv)`` in-process, with its stdout and stderr (the file
descriptors, so C-level output and faulthandler's dump too) sent to a log per step, in a fresh
directory per case. The parent gives each step ``timeout`` seconds (past it: a *hang*, the worker is
killed and replaced) and notices a worker killed by a signal (a *signal*, replaced). ``judge`` then
sorts every case into one class; the failing ones are those of ``FAILING``.

Argv placeholders: ``{case}`` the case's directory, ``{shared}`` the inputs built once per session
by ``build_shared`` (link1's and the car's dynamics, the pendulum tables A-G, a small car table,
tiny BSR results for the composite script), ``{specs}`` the repository's specs/.
"""

from __future__ import annotations

import collections
import contextlib
import difflib
import gc
import math
import multiprocessing
import os
import pickle
import re
import shutil
import signal
import subprocess
import sys
import time
import traceback
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from multiprocessing.connection import wait
from pathlib import Path

from hypothesis import HealthCheck, Phase, given, seed, settings
from hypothesis import strategies as st
from test_car import SMALL

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"

# --- what a case is ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Step:
    """One ``mosys`` command line. ``outputs``: the files (relative to the case directory) it
    writes when it exits 0, each checked against ``contract`` (a key of ``CONTRACTS``).
    ``scratch_cache``: run with ``MOSYS_CACHE_DIR`` in the session's scratch directory (the step
    loads dynamics generated in the case, whose copies must not pile up in the user's cache)."""

    argv: tuple[str, ...]
    outputs: tuple[str, ...]
    contract: str
    scratch_cache: bool = False

    @property
    def verb(self) -> str:
        return self.argv[0]


@dataclass(frozen=True)
class Case:
    """``files`` (name relative to the case directory, bytes) are written into a fresh directory,
    then ``steps`` run in order until one exits non-zero. ``source``: the shipped spec the mutated
    file was made from (relative to the repository; ``""`` when no spec was mutated), ``original``
    its text, ``mutations`` what was done to it, for the reproducer."""

    kind: str
    source: str
    mutations: tuple[str, ...]
    files: tuple[tuple[str, bytes], ...]
    steps: tuple[Step, ...]
    original: bytes = b""

    @property
    def verbs(self) -> str:
        return "+".join(step.verb for step in self.steps)

    def size(self) -> int:
        return sum(len(data) for _, data in self.files) + sum(
            len(" ".join(step.argv)) for step in self.steps
        )


KINDS = ("fig", "ssc", "anim", "mot", "bsr", "comp", "cli")

# --- the shipped specs ------------------------------------------------------------------------

# A smaller grid of specs/controllers/car/park.ssc (its 366,240 nodes take minutes): the car test's
# SMALL scene with the lookahead policy, so that `run` and `starts` drive the lookahead runtime.
CAR_SMALL_SSC = (SMALL + "policy lookahead x=0.1 y=0.1 heading=4\n").encode()
CAR_SMALL_NAME = "specs/controllers/car/park.ssc (small grid)"

PENDULUM_TABLES = "ABCDEFG"
PENDULUM_SCRIPTS = ("pendulum", "pendulum_catch", "pendulum_slew", "pendulum_swing")
CAR_SCRIPTS = tuple(f"park_{number}" for number in range(1, 7))
COMPILED_FIGURES = ("link1", "double_pendulum", "car")  # sympy is quick on these
BSR_FIGURES = {  # a figure and a search of it
    "starman": "starman_jump",
    "beryl": "beryl_shuffle",
    "cujo": "cujo_bound",
    "bob": "bob_walk",
    "rex": "rex_walk",
}
BSR_SEARCHES = (  # 2-D, then 3-D without a chain
    "starman_jump",
    "starman_shuffle",
    "starman_cartwheel",
    "starman_jump_robust",
    "starman_shuffle_robust",
    "starman_cartwheel_robust",
    "beryl_shuffle",
    "beryl_tumble",
    "cujo_bound",
    "rex_walk",
    "rex_walk_sense",
    "bob_walk",
    "bob_walk_time",
)
COMPOSITE_SEARCHES = ("starman_cartwheel_robust", "starman_jump_robust", "starman_shuffle_robust")
TINY_BSR = ("--seed", "1", "--generations", "1", "--threads", "1")
TINY_COMPOSITE = ("--q", "2", "--g", "1", "--h", "1")


def spec_text(relative: str) -> bytes:
    if relative == CAR_SMALL_NAME:
        return CAR_SMALL_SSC
    return (ROOT / relative).read_bytes()


def _same_kind(pattern: str) -> tuple[bytes, ...]:
    """Every non-comment line of the shipped specs matching ``pattern`` (donors for insertion)."""
    lines = []
    for path in sorted(SPECS.glob(pattern)):
        for line in path.read_bytes().split(b"\n"):
            code = line.split(b"#")[0].strip()
            if code:
                lines.append(code)
    return tuple(dict.fromkeys(lines))


DONORS = {
    "fig": _same_kind("figures/*.fig"),
    "ssc": _same_kind("controllers/*/*.ssc") + tuple(CAR_SMALL_SSC.strip().split(b"\n")),
    "anim": _same_kind("scripts/*.anim"),
    "mot": _same_kind("motor/*/*.mot"),
    "bsr": _same_kind("bsr/*.bsr"),
    "comp": _same_kind("composite/*.comp"),
}

# --- mutations --------------------------------------------------------------------------------

NUMBER = re.compile(rb"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])")

EXTREME_NUMBERS = (
    "0", "-0", "0.0", "-1", "1", "2", "nan", "NaN", "inf", "-inf", "1e400", "-1e400", "1e300",
    "-1e300", "1e-300", "5e-324", "1e308", "1.7976931348623157e308", "1e-6", "1e6", "1e-20",
    "1e20", "1e-5", "1e-9", "1e9", "1e12", "1e15", "1e150", "99999999999999999999", "100000",
    "1000000", "10000000", "100000000", "2147483647", "2147483648", "4294967296",
    "9223372036854775807", "9223372036854775808", "0.5", "0.001", "3", "7", "10", "360",
    "-360", "720", "1e-3", "0x10", "1_0", "+3", ".5", "5.", "1e", "--1", "1e+", "\u0661", "\u00bd",
)  # fmt: skip
SCALES = (1, -1, 2, -2, 3, -3, 4, -4, 6, -6, 9, -9, 12, -12, 20, -20, 300, -300)
GARBAGE_WORDS = (
    "frobnicate", "=", "==", ",", ",,", "x=", "=1", "#", "wrap", "once", "link", "conA.ctab",
    "conZ.ctab", "dest", "ssd", "sim", "key", "phase", "state", "when", "swapcon", "motor", "torq",
    "rod", "pin", "hinge", "free", "\u221e", "\u2014", "max_t(", ")", "(", "?=", "1,2,3", "a,b",
    "angle=", "omega=1e400", "ticks=", "controller=", "seed=", "rules=", "dt=", "=", "..",
)  # fmt: skip
HOSTILE_BYTES = (
    b"\x00", b"\xff", b"\xc3", b"\xed\xa0\x80", b"\xef\xbb\xbf", b"\r", b"\r\n", b"\t", b"\x0b",
    b"\x1b[2J", b"\xe2\x80\xae", b"\xf4\x90\x80\x80", b"\xfe\xff", b"\x7f",
)  # fmt: skip
LONG = 100_000
LONG_LINES = (
    b"9" * LONG, b"x" * LONG, b"# " + b"y" * LONG, b"sim " + b"1" * LONG, b"(" * LONG,
    b"state " + b"1," * (LONG // 2), b"key 0 " + b"angle=1 " * (LONG // 8),
)  # fmt: skip
LONG_NUMBERS = (b"1" * LONG, b"0." + b"0" * LONG + b"1", b"1" + b"0" * 400, b"9" * 5000)
MAX_TEXT = 3_000_000  # a mutated file never grows past this many bytes


def _lines(text: bytes) -> list[bytes]:
    return text.split(b"\n")


def number_spans(text: bytes) -> list[tuple[int, int]]:
    """(start, end) byte offsets of the numbers in ``text``, outside comments."""
    spans, offset = [], 0
    for line in _lines(text):
        code = line.split(b"#")[0]
        spans += [(offset + m.start(), offset + m.end()) for m in NUMBER.finditer(code)]
        offset += len(line) + 1
    return spans


def _format(value: float) -> str:
    return repr(value) if math.isfinite(value) else ("inf" if value > 0 else "-inf")


@st.composite
def hostile_number(draw, original: bytes) -> bytes:
    """A number to put where ``original`` was: an extreme value, the original scaled by a power
    of ten, negated, or a whole number near a machine limit."""
    how = draw(
        st.sampled_from(["scaled", "extreme", "scaled", "extreme", "scaled", "negated", "long"])
    )
    if how == "extreme":
        return draw(st.sampled_from(EXTREME_NUMBERS)).encode()
    if how == "long":
        return draw(st.sampled_from(LONG_NUMBERS))
    try:
        value = float(original)
    except ValueError:
        value = 1.0
    if how == "negated":
        return original[1:] if original.startswith(b"-") else b"-" + original
    power = draw(st.sampled_from(SCALES))
    if re.fullmatch(rb"-?\d{1,30}", original) and power > 0:  # a count stays a whole number
        return str((int(original) or 1) * 10**power).encode()
    scaled = (value if value != 0 else 1.0) * 10.0**power
    return _format(scaled).encode()


def _pick_line(draw, lines: list[bytes], with_tokens: bool = False) -> int:
    """A line's index: with ``with_tokens``, a line with code (not only a comment) if any."""
    if with_tokens:
        code = [i for i, line in enumerate(lines) if line.split(b"#")[0].split()]
        if code:
            return draw(st.sampled_from(code))
    return draw(st.integers(0, max(len(lines) - 1, 0)))


def mutate_number(draw, text: bytes, kind: str) -> tuple[bytes, str]:
    spans = number_spans(text)
    if not spans:
        return mutate_token(draw, text, kind)
    start, end = draw(st.sampled_from(spans))
    new = draw(hostile_number(text[start:end]))
    line = text.count(b"\n", 0, start) + 1
    return text[:start] + new + text[
        end:
    ], f"line {line}: number {_show(text[start:end])} -> {_show(new)}"


def mutate_token(draw, text: bytes, kind: str) -> tuple[bytes, str]:
    lines = _lines(text)
    row = _pick_line(draw, lines, with_tokens=True)
    code, hash_sign, comment = lines[row].partition(b"#")
    tokens = code.split()
    if not tokens:
        return mutate_line(draw, text, kind)
    column = draw(st.integers(0, len(tokens) - 1))
    action = draw(st.sampled_from(["delete", "duplicate", "swap", "garbage", "keyword"]))
    old = tokens[column]
    if action == "delete":
        del tokens[column]
    elif action == "duplicate":
        tokens.insert(column, old)
    elif action == "swap" and len(tokens) > 1:
        other = draw(st.integers(0, len(tokens) - 1))
        tokens[column], tokens[other] = tokens[other], tokens[column]
    elif action == "keyword":
        donor = draw(st.sampled_from(DONORS[kind] or (b"x",)))
        tokens[column] = donor.split()[0]
    else:
        tokens[column] = draw(st.sampled_from(GARBAGE_WORDS)).encode()
    lines[row] = b" ".join(tokens) + (b"  " + hash_sign + comment if hash_sign else b"")
    return b"\n".join(lines), f"line {row + 1}: token {column + 1} {_show(old)}: {action}"


def mutate_line(draw, text: bytes, kind: str) -> tuple[bytes, str]:
    lines = _lines(text)
    row = _pick_line(draw, lines, with_tokens=True)
    action = draw(
        st.sampled_from(["delete", "duplicate", "repeat", "swap", "donor", "donor", "unknown"])
    )
    note = f"line {row + 1}: {action}"
    if action == "delete":
        del lines[row]
    elif action == "duplicate":
        lines.insert(row, lines[row])
    elif action == "repeat":
        times = draw(st.sampled_from([2, 10, 1000, 10000]))
        times = max(1, min(times, MAX_TEXT // (len(lines[row]) + 1)))
        lines[row : row + 1] = [lines[row]] * times
        note += f" x{times}"
    elif action == "swap":
        other = _pick_line(draw, lines, with_tokens=True)
        lines[row], lines[other] = lines[other], lines[row]
        note += f" with line {other + 1}"
    elif action == "donor":
        donor = draw(st.sampled_from(DONORS[kind] or (b"x",)))
        lines.insert(row, donor)
        note += f" {_show(donor)} inserted"
    else:
        word = draw(st.sampled_from(["wibble 1 2 3", "frobnicate", "dyn", "=", "1 2 3"]))
        lines.insert(row, word.encode())
        note += f" {word!r} inserted"
    return b"\n".join(lines), note


def mutate_bytes(draw, text: bytes, kind: str) -> tuple[bytes, str]:
    action = draw(
        st.sampled_from(
            ["truncate", "insert", "insert", "crlf", "long_line", "long_number", "binary"]
        )
    )
    at = draw(st.integers(0, len(text)))
    if action == "truncate":
        return text[:at], f"truncated to {at} bytes"
    if action == "insert":
        data = draw(st.sampled_from(HOSTILE_BYTES))
        return text[:at] + data + text[at:], f"byte {at}: {data!r} inserted"
    if action == "binary":
        data = draw(st.binary(min_size=1, max_size=24))
        return text[:at] + data + text[at:], f"byte {at}: {data!r} inserted"
    if action == "crlf":
        return text.replace(b"\n", b"\r\n"), "line ends CRLF"
    if action == "long_number":
        spans = number_spans(text)
        if spans:
            start, end = draw(st.sampled_from(spans))
            new = draw(st.sampled_from(LONG_NUMBERS))
            line = text.count(b"\n", 0, start) + 1
            return (
                text[:start] + new + text[end:],
                f"line {line}: number {_show(text[start:end])} -> {_show(new)}",
            )
    lines = _lines(text)
    row = draw(st.integers(0, len(lines)))
    data = draw(st.sampled_from(LONG_LINES))
    lines.insert(row, data)
    return b"\n".join(lines), f"line {row + 1}: {_show(data)} inserted"


def mutate_nesting(draw, text: bytes, kind: str) -> tuple[bytes, str]:
    """Composite scripts: a score or total expression nested or chained deeply."""
    lines = _lines(text)
    rows = [i for i, line in enumerate(lines) if re.match(rb"\s*(score\b|total\b)", line)]
    if not rows:
        return mutate_line(draw, text, kind)
    row = draw(st.sampled_from(rows))
    head, _, expression = lines[row].split(b"#")[0].partition(b"=")
    expression = expression.strip() or b"dcm_x"
    depth = draw(st.sampled_from([10, 100, 300, 1000, 3000, 10000, 100000]))
    how = draw(st.sampled_from(["parens", "chain", "unary", "functions", "power"]))
    if how == "parens":
        new = b"(" * depth + expression + b")" * depth
    elif how == "chain":
        new = expression + b" * dcm_x" * depth
    elif how == "unary":
        new = b"-" * depth + b"(" + expression + b")"
    elif how == "functions":
        new = b"max_t(" * depth + b"dcm_x" + b")" * depth
    else:
        new = b"(1e308 * 1e308) / " * min(depth, 1000) + expression
    lines[row] = head + b"= " + new
    return b"\n".join(lines), f"line {row + 1}: expression {how} x{depth}"


MUTATIONS: dict[str, Callable] = {
    "number": mutate_number,
    "token": mutate_token,
    "line": mutate_line,
    "bytes": mutate_bytes,
    "nesting": mutate_nesting,
}
WEIGHTS = {  # how often each mutation is drawn (out of the list's length)
    "number": 10,
    "token": 2,
    "line": 3,
    "bytes": 2,
}


@st.composite
def mutated(draw, original: bytes, kind: str) -> tuple[bytes, tuple[str, ...]]:
    """``original`` after one to three mutations, and what they were."""
    weights = dict(WEIGHTS, nesting=3) if kind == "comp" else WEIGHTS
    names = [name for name, weight in weights.items() for _ in range(weight)]
    text, notes = original, []
    for _ in range(draw(st.sampled_from([1, 1, 2, 3]))):
        text, note = MUTATIONS[draw(st.sampled_from(names))](draw, text, kind)
        notes.append(note)
        text = text[:MAX_TEXT]
    return text, tuple(notes)


def _show(data: bytes, most: int = 40) -> str:
    text = data.decode("utf-8", "backslashreplace")
    if len(text) > most:
        text = f"{text[:most]}...({len(data)} bytes)"
    return repr(text)


# --- the cases of each kind -------------------------------------------------------------------


def _spec_case(draw, kind: str, source: str, name: str, steps: tuple[Step, ...]) -> Case:
    original = spec_text(source)
    text, notes = draw(mutated(original, kind))
    return Case(kind, source, notes, ((name, text),), steps, original)


def _pendulum_run(script: str, dynamics: str = "{shared}/dynamics", **kw) -> Step:
    return Step(
        (
            "run", script, "--controllers", "{shared}/controllers/pendulum", "--dynamics-dir",
            dynamics, "--motor-dir", kw.get("motor", "{specs}/motor"),
            *kw.get("options", ()), "-o", "{case}/trajectory.h5",
        ),
        ("trajectory.h5",),
        "trajectory",
        kw.get("scratch_cache", False),
    )  # fmt: skip


def _compile_then_run() -> tuple[Step, Step]:
    """``compile`` the case's link1.fig, then ``run`` the pendulum script on what it made."""
    compile_step = Step(
        ("compile", "{case}/link1.fig", "-o", "{case}/dynamics/link1.py"),
        ("dynamics/link1.py",),
        "dynamics",
    )
    run_step = _pendulum_run("{specs}/scripts/pendulum.anim", "{case}/dynamics", scratch_cache=True)
    return compile_step, run_step


def _car_run(script: str, options: tuple[str, ...] = ("--dt", "0.01")) -> Step:
    return Step(
        (
            "run", script, "--controllers", "{shared}/controllers/car", "--dynamics-dir",
            "{shared}/dynamics", *options, "-o", "{case}/trajectory.h5",
        ),
        ("trajectory.h5",),
        "trajectory",
    )  # fmt: skip


def _bsr_step(spec: str, figures: str = "{specs}/figures", options=TINY_BSR) -> Step:
    argv = ("bsr-search", spec, "--figures", figures, *options, "-o", "{case}/seed.h5")
    return Step(argv, ("seed.h5",), "bsr")


def _composite_step(script: str, options=TINY_COMPOSITE) -> Step:
    argv = (
        "composite", script, "--bsr-results", "{shared}/bsr", "--figures", "{specs}/figures",
        "--bsr-specs", "{specs}/bsr", *options, "-o", "{case}/composite.h5",
    )  # fmt: skip
    return Step(argv, ("composite.h5",), "composite")


def _dp_step(spec: str, quiet: bool, options: tuple[str, ...] = ()) -> Step:
    argv = ("dp", spec, "--dynamics-dir", "{shared}/dynamics", *options, "-o", "{case}/table.h5")
    return Step(argv + (("--quiet",) if quiet else ()), ("table.h5",), "controller")


@st.composite
def fig_cases(draw) -> Case:
    """A mutated figure: compiled; compiled and run (link1 under the pendulum script); or the
    figure of a BSR search."""
    how = draw(st.sampled_from(["compile", "compile", "compile_run", "bsr", "bsr"]))
    if how == "compile":
        figure = draw(st.sampled_from(COMPILED_FIGURES))
        step = Step(
            ("compile", f"{{case}}/{figure}.fig", "-o", f"{{case}}/{figure}.py"),
            (f"{figure}.py",),
            "dynamics",
        )
        return _spec_case(draw, "fig", f"specs/figures/{figure}.fig", f"{figure}.fig", (step,))
    if how == "compile_run":
        return _spec_case(draw, "fig", "specs/figures/link1.fig", "link1.fig", _compile_then_run())
    figure = draw(st.sampled_from(sorted(BSR_FIGURES)))
    step = _bsr_step(f"{{specs}}/bsr/{BSR_FIGURES[figure]}.bsr", "{case}/figures")
    return _spec_case(draw, "fig", f"specs/figures/{figure}.fig", f"figures/{figure}.fig", (step,))


@st.composite
def ssc_cases(draw) -> Case:
    """A mutated controller spec (pendulum A-G, the small car) through ``mosys dp``; a
    pendulum table then drawn (``plot controller``: its portrait and torque map)."""
    name = draw(st.sampled_from([*PENDULUM_TABLES, "car"]))
    source = CAR_SMALL_NAME if name == "car" else f"specs/controllers/pendulum/{name}.ssc"
    step = _dp_step(f"{{case}}/{name}.ssc", draw(st.booleans()))
    if name == "car":
        return _spec_case(draw, "ssc", source, f"{name}.ssc", (step,))
    plot = Step(
        (
            "plot", "controller", "{case}/table.h5", "--dynamics", "{shared}/dynamics/link1.py",
            "--portrait", "{case}/portrait.png", "--torque", "{case}/torque.png",
        ),
        ("portrait.png", "torque.png"),
        "plot",
    )  # fmt: skip
    return _spec_case(draw, "ssc", source, f"{name}.ssc", (step, plot))


def _plot_script_step(car: bool) -> Step:
    """Draw the trajectory a ``run`` step wrote: the car's Figure 19 frames, else the script's
    state-space path (with no tables: a mutated script may name any of them or none). A file
    the run wrote is a file the plots must draw (10,000 copies of a breakpoint stacked opaque,
    300 distinct ones raised in matplotlib)."""
    if car:
        argv = ("plot", "car", "{case}/trajectory.h5", "--frames", "{case}/plot.png")
    else:
        argv = ("plot", "script", "{case}/trajectory.h5", "--path", "{case}/plot.png")
    return Step(argv, ("plot.png",), "plot")


@st.composite
def anim_cases(draw) -> Case:
    """A mutated animation script: the pendulum's four (A-G tables, swing.mot) or the car's six
    (the small car table as conpark.ctab) through ``mosys run``, then drawn."""
    script = draw(st.sampled_from(PENDULUM_SCRIPTS + CAR_SCRIPTS))
    name = f"{script}.anim"
    car = script.startswith("park")
    step = _car_run(f"{{case}}/{name}") if car else _pendulum_run(f"{{case}}/{name}")
    return _spec_case(draw, "anim", f"specs/scripts/{name}", name, (step, _plot_script_step(car)))


@st.composite
def mot_cases(draw) -> Case:
    """A mutated motor program (specs/motor/link1/swing.mot) under pendulum_swing.anim, drawn."""
    step = _pendulum_run("{specs}/scripts/pendulum_swing.anim", motor="{case}/motor")
    steps = (step, _plot_script_step(car=False))
    return _spec_case(draw, "mot", "specs/motor/link1/swing.mot", "motor/link1/swing.mot", steps)


@st.composite
def bsr_cases(draw) -> Case:
    """A mutated BSR search spec (2-D and unchained 3-D) searched for one generation, its best
    motion then drawn (``plot bsr`` or ``plot bsr3d --filmstrip``)."""
    search = draw(st.sampled_from(BSR_SEARCHES))
    step = _bsr_step(f"{{case}}/{search}.bsr")
    kind = "bsr3d" if search.split("_")[0] in ("cujo", "rex", "bob") else "bsr"
    argv = ("plot", kind, "{case}/seed.h5", "--filmstrip", "{case}/filmstrip.png")
    plot = Step(argv, ("filmstrip.png",), "plot")
    return _spec_case(draw, "bsr", f"specs/bsr/{search}.bsr", f"{search}.bsr", (step, plot))


@st.composite
def comp_cases(draw) -> Case:
    """A mutated composite script (Table 4's) on tiny BSR results, a tiny search, then drawn
    (``plot composite``: Figures 13 and 14, the search)."""
    step = _composite_step("{case}/starman_show.comp")
    argv = (
        "plot", "composite", "{case}/composite.h5", "--filmstrips", "{case}/strips.png",
        "--search", "{case}/search.png",
    )  # fmt: skip
    plot = Step(argv, ("strips.png", "search.png"), "plot")
    source = "specs/composite/starman_show.comp"
    return _spec_case(draw, "comp", source, "starman_show.comp", (step, plot))


FLOATS = (
    "0", "-0", "-0.001", "-1", "nan", "inf", "-inf", "1e400", "1e-300", "5e-324", "1e-12",
    "1e-9", "1e-7", "1e-6", "1e-5", "0.0001", "0.001", "0.01", "0.1", "0.5", "1", "10", "100",
    "1e6", "1e300", " 0.01", "0x10", "one",
)  # fmt: skip
# Budgets (--generations, --q/--g/--h, --max-iterations, --threads, start counts): out of range,
# or small. A budget in range but huge (--q 100000) is a long job the user asked for, not a hang.
BUDGETS = (
    "0", "-1", "1", "2", "3", "2147483648", "4294967296", "9223372036854775808",
    "99999999999999999999999", "-9223372036854775809", "1.5", "1e3", "nan",
)  # fmt: skip
SEEDS = ("0", "1", "2", "3", "-1", "9223372036854775807", "9223372036854775808",
         "99999999999999999999999", "1.5")  # fmt: skip
COUNTS = ("0", "-1", "1", "2", "3", "1.5", "nan", "inf", "-inf", "1e400", "2000000", "1e7")
float_option = st.sampled_from(FLOATS)
budget_option = st.sampled_from(BUDGETS)


def run_option_case(script: str, dt: str) -> Case:
    """``mosys run`` on a shipped script (pendulum, car or motor) with ``--dt dt``."""
    path = f"{{specs}}/scripts/{script}.anim"
    if script.startswith("park"):
        step = _car_run(path, ("--dt", dt))
    else:
        step = _pendulum_run(path, options=("--dt", dt))
    return Case("cli", "", (f"{script}.anim --dt {dt!r}",), (), (step,))


def starts_case(options: tuple[str, ...]) -> Case:
    """``mosys starts`` on the small car table with ``options`` (then the defaults below), then
    its success map and consistency plot."""
    given = {word for word in options if word.startswith("--")}
    defaults = {"--x": ("-1", "1", "2"), "--y": ("1.2", "1.8", "1"), "--seconds": ("2",)}
    full = list(options)
    for name, values in defaults.items():
        if name not in given:
            full += [name, *values]
    step = Step(
        (
            "starts", "{shared}/controllers/car/park.h5", "--dynamics",
            "{shared}/dynamics/car.py", *full, "-o", "{case}/starts.h5",
        ),
        ("starts.h5",),
        "start_grid",
    )  # fmt: skip
    argv = (
        "plot", "car", "--map", "{case}/starts.h5", "{case}/map.png", "--consistency",
        "{case}/starts.h5", "{case}/consistency.png",
    )  # fmt: skip
    plot = Step(argv, ("map.png", "consistency.png"), "plot")
    return Case("cli", "", (f"starts {' '.join(options)}",), (), (step, plot))


def bsr_option_case(search: str, seed: str, generations: str, threads: str) -> Case:
    options = ("--seed", seed, "--generations", generations, "--threads", threads)
    step = _bsr_step(f"{{specs}}/bsr/{search}.bsr", options=options)
    return Case("cli", "", (f"{search}.bsr {' '.join(options)}",), (), (step,))


def dp_option_case(name: str, options: tuple[str, ...]) -> Case:
    step = _dp_step(f"{{specs}}/controllers/pendulum/{name}.ssc", True, options)
    return Case("cli", "", (f"{name}.ssc {' '.join(options)}",), (), (step,))


def composite_option_case(q: str, g: str, h: str) -> Case:
    options = ("--q", q, "--g", g, "--h", h)
    step = _composite_step("{specs}/composite/starman_show.comp", options)
    return Case("cli", "", (" ".join(options),), (), (step,))


@st.composite
def cli_cases(draw) -> Case:
    """A shipped spec run with one or more numeric options made hostile at once."""
    verb = draw(st.sampled_from(["run", "run", "starts", "bsr", "bsr", "dp", "composite"]))
    if verb == "run":
        script = draw(st.sampled_from(PENDULUM_SCRIPTS + CAR_SCRIPTS))
        return run_option_case(script, draw(float_option))
    if verb == "starts":
        options: list[str] = []
        for axis, low, high in (("x", "-1", "1"), ("y", "1.2", "1.8")):
            values = [low, high, draw(st.sampled_from(["1", "2", "3"]))]
            if draw(st.integers(0, 2)) == 0:
                slot = draw(st.integers(0, 2))
                values[slot] = draw(st.sampled_from(COUNTS) if slot == 2 else float_option)
            options += [f"--{axis}", *values]
        for name in ("heading", "steer"):
            if draw(st.booleans()):
                count = draw(st.integers(1, 3))
                options += [f"--{name}", *(draw(float_option) for _ in range(count))]
        options += ["--seconds", draw(st.sampled_from(["2", "5"]) | float_option)]
        options += ["--dt", draw(st.sampled_from(["0.01", "0.02"]) | float_option)]
        if draw(st.booleans()):
            options += ["--threads", draw(budget_option)]
        return starts_case(tuple(options))
    if verb == "bsr":
        return bsr_option_case(
            draw(st.sampled_from(BSR_SEARCHES)),
            draw(st.sampled_from(SEEDS)),
            draw(st.sampled_from(["1", "2"]) | budget_option),
            draw(st.sampled_from(["1", "0", "2"]) | budget_option),
        )
    if verb == "dp":
        options = ()
        if draw(st.booleans()):
            options += ("--tol", draw(float_option))
        if draw(st.booleans()) or not options:
            options += ("--max-iterations", draw(budget_option))
        return dp_option_case(draw(st.sampled_from(PENDULUM_TABLES)), options)
    q, g, h = (draw(st.just(usual) | budget_option) for usual in ("2", "1", "1"))
    return composite_option_case(q, g, h)


def cli_grid() -> list[Case]:
    """Every hostile value of every numeric option, one option at a time, the others usual (the
    drawn cli cases combine them but need not cover each): ``run --dt`` (a pendulum script, a
    motor program, the car), ``starts --dt --seconds --x --heading --threads``,
    ``bsr-search --seed --generations --threads``, ``dp --tol --max-iterations``,
    ``composite --q --g --h``."""
    cases = [
        run_option_case(script, dt)
        for script in ("pendulum", "pendulum_swing", "park_1")
        for dt in FLOATS
    ]
    cases += [starts_case(("--dt", value)) for value in FLOATS]
    cases += [starts_case(("--seconds", value)) for value in FLOATS]
    cases += [starts_case(("--x", "-1", "1", value)) for value in COUNTS]
    cases += [starts_case(("--x", value, "1", "2")) for value in FLOATS]
    cases += [starts_case(("--heading", value)) for value in FLOATS]
    cases += [starts_case(("--threads", value)) for value in BUDGETS]
    cases += [bsr_option_case("starman_jump", seed, "1", "1") for seed in SEEDS]
    cases += [bsr_option_case("starman_jump", "1", value, "1") for value in BUDGETS]
    cases += [bsr_option_case("starman_jump", "1", "1", value) for value in BUDGETS]
    cases += [dp_option_case("A", ("--tol", value)) for value in FLOATS]
    cases += [dp_option_case("A", ("--max-iterations", value)) for value in BUDGETS]
    for slot in range(3):
        for value in BUDGETS:
            sizes = ["2", "1", "1"]
            sizes[slot] = value
            cases.append(composite_option_case(*sizes))
    return list(dict.fromkeys(cases))


STRATEGIES = {
    "fig": fig_cases(),
    "ssc": ssc_cases(),
    "anim": anim_cases(),
    "mot": mot_cases(),
    "bsr": bsr_cases(),
    "comp": comp_cases(),
    "cli": cli_cases(),
}


def draw_cases(kind: str, count: int, fresh_seed: int | None = None) -> list[Case]:
    """``count`` cases of ``kind`` from its strategy, duplicates dropped, hypothesis
    derandomized (its seed comes from this function's code), or with ``fresh_seed`` drawn from
    that seed instead (other cases, the same for the same seed). In this process: the cases
    depend on what else it imported (see ``draw_profile``)."""
    drawn: list[Case] = []

    @settings(
        max_examples=count,
        derandomize=fresh_seed is None,
        database=None,
        deadline=None,
        phases=[Phase.generate],
        suppress_health_check=list(HealthCheck),
    )
    @given(STRATEGIES[kind])
    def collect(case: Case) -> None:
        drawn.append(case)

    if fresh_seed is not None:
        collect = seed(fresh_seed)(collect)
    collect()
    return list(dict.fromkeys(drawn))


def draw_profile(sizes: dict[str, int], fresh_seed: int | None = None) -> dict[str, list[Case]]:
    """``draw_cases`` for each kind and count of ``sizes`` (and ``fresh_seed``), in a fresh
    interpreter that imports this module only. Hypothesis also draws the constants of every
    local module imported (``hypothesis.internal.conjecture.providers``: mosys's, once a verb
    has run), so in pytest's process the cases would change with the tests run before and with
    every edit to src/; here they depend on this file, the seed and hypothesis's version
    alone."""
    code = (
        "import pickle, sys\n"
        f"sys.path.insert(0, {str(Path(__file__).parent)!r})\n"
        "import fuzz_cases\n"
        f"sizes = {sizes!r}\n"
        "drawn = {kind: fuzz_cases.draw_cases(kind, count, "
        f"{fresh_seed!r}) for kind, count in sizes.items()}}\n"
        "sys.stdout.buffer.write(pickle.dumps(drawn))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, cwd=ROOT)
    if done.returncode != 0:
        raise RuntimeError(f"drawing the cases failed:\n{done.stderr.decode(errors='replace')}")
    return pickle.loads(done.stdout)


# --- the inputs every case shares -------------------------------------------------------------


def build_shared(directory: Path) -> None:
    """Build the cases' shared inputs with the verbs themselves (about 5 s with numba's cache
    warm): ``dynamics/{link1,car}.py``, ``controllers/pendulum/{A..G}.h5``,
    ``controllers/car/park.h5`` (``CAR_SMALL_SSC``) and ``bsr/SEARCH/seed1.h5`` (one generation)
    of the three searches the composite script uses."""
    from mosys.cli import main

    def mosys(*argv: str) -> None:
        with contextlib.redirect_stdout(sys.stderr):
            code = main([str(arg) for arg in argv])
        assert code == 0, f"mosys {' '.join(map(str, argv))} exited {code}"

    dynamics = directory / "dynamics"
    for figure in ("link1", "car"):
        mosys("compile", SPECS / "figures" / f"{figure}.fig", "-o", dynamics / f"{figure}.py")
    for name in PENDULUM_TABLES:
        spec = SPECS / "controllers" / "pendulum" / f"{name}.ssc"
        table = directory / "controllers" / "pendulum" / f"{name}.h5"
        mosys("dp", spec, "--dynamics-dir", dynamics, "-o", table, "--quiet")
    car = directory / "park.ssc"
    car.write_bytes(CAR_SMALL_SSC)
    table = directory / "controllers" / "car" / "park.h5"
    mosys("dp", car, "--dynamics-dir", dynamics, "-o", table, "--quiet")
    car.unlink()
    for search in COMPOSITE_SEARCHES:
        result = directory / "bsr" / search / "seed1.h5"
        mosys("bsr-search", SPECS / "bsr" / f"{search}.bsr", "--figures", SPECS / "figures",
              *TINY_BSR, "-o", result)  # fmt: skip


def baseline_cases() -> list[Case]:
    """The shipped specs unmutated, one per verb and family: each worker runs them first (numba
    loads its caches, a stale cache is compiled) and they must exit 0 with sound outputs."""
    link1 = spec_text("specs/figures/link1.fig")
    compile_step, run_on_it = _compile_then_run()
    starts = Step(
        (
            "starts", "{shared}/controllers/car/park.h5", "--dynamics", "{shared}/dynamics/car.py",
            "--x", "-1", "1", "2", "--y", "1.5", "1.5", "1", "--seconds", "2", "-o",
            "{case}/starts.h5",
        ),
        ("starts.h5",),
        "start_grid",
    )  # fmt: skip
    car = (("car.ssc", CAR_SMALL_SSC),)
    composite = _composite_step("{specs}/composite/starman_show.comp")
    baseline = [
        Case("fig", "", ("baseline",), (("link1.fig", link1),), (compile_step, run_on_it)),
        Case("ssc", "", ("baseline",), (), (_dp_step("{specs}/controllers/pendulum/A.ssc", True),)),
        Case("ssc", "", ("baseline",), car, (_dp_step("{case}/car.ssc", True),)),
        Case("anim", "", ("baseline",), (), (_pendulum_run("{specs}/scripts/pendulum.anim"),)),
        Case("mot", "", ("baseline",), (), (_pendulum_run("{specs}/scripts/pendulum_swing.anim"),)),
        Case("cli", "", ("baseline",), (), (starts,)),
        Case("comp", "", ("baseline",), (), (composite,)),
    ]  # fmt: skip
    for search in ("starman_jump", "beryl_shuffle", "cujo_bound", "rex_walk", "bob_walk"):
        step = _bsr_step(f"{{specs}}/bsr/{search}.bsr")
        baseline.append(Case("bsr", "", ("baseline",), (), (step,)))
    return baseline


# --- the worker -------------------------------------------------------------------------------

WORKER_ENVIRONMENT = {
    "MOSYS_MAX_MEMORY_GIB": "0.5",  # what one job may take (the verbs refuse more, exit 2)
    "MOSYS_MAX_STEPS": "200000",  # integration steps one run may take
    "NUMBA_NUM_THREADS": "1",  # two workers on two cores
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "PYTHONWARNINGS": "default",
}
ADDRESS_SPACE_GIB = 6  # a worker's address space: an allocation past it is a MemoryError


def worker_main(connection, environment: dict[str, str], scratch_cache: str) -> None:
    """The worker process: run the steps of each case it is sent, in-process, and report."""
    os.environ.update(environment)
    import faulthandler
    import resource
    import warnings

    limit = ADDRESS_SPACE_GIB * 2**30
    with contextlib.suppress(ValueError, OSError):
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    faulthandler.enable(all_threads=True)  # writes to fd 2, i.e. the running step's log
    warnings.simplefilter("always")  # every case shows its own warnings
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    from mosys.cli import main as mosys_main

    def main(argv: list[str]) -> int:
        misbehave = MISBEHAVIOURS.get(argv[0])
        return misbehave(argv) if misbehave else mosys_main(argv)

    home = os.getcwd()
    cases = 0
    while True:
        job = connection.recv()
        if job is None:
            return
        directory, logs, steps = job
        results = []
        for index, (argv, use_scratch) in enumerate(steps):
            connection.send(("step", index))
            extra = {"MOSYS_CACHE_DIR": scratch_cache} if use_scratch else {}
            result = _run_step(main, argv, directory, f"{logs}.{index}", extra, home)
            results.append(result)
            if result["exit"] != 0:
                break
        connection.send(("done", results))
        cases += 1
        if cases % 25 == 0:  # a full collection takes 0.1 s: not after every case
            gc.collect()


def _run_step(main, argv, directory, log, extra_env, home) -> dict:
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    before = {name: os.environ.get(name) for name in extra_env}
    error = None
    start = time.perf_counter()
    with open(f"{log}.out", "wb") as out, open(f"{log}.err", "wb") as err:
        os.dup2(out.fileno(), 1)
        os.dup2(err.fileno(), 2)
        os.environ.update(extra_env)
        try:
            os.chdir(directory)
            code = main(list(argv))
        except SystemExit as exit:
            code = exit.code
            if code is None:
                code = 0
            elif not isinstance(code, int):
                print(code, file=sys.stderr)
                code = 1
        except BaseException as exception:  # noqa: BLE001 - every escape is the finding
            code = None
            try:
                text = traceback.format_exc()
            except BaseException:  # noqa: BLE001 - formatting can fail after a MemoryError
                text = f"{type(exception).__name__} (traceback could not be formatted)"
            error = {
                "type": type(exception).__name__,
                "message": str(exception)[:500],
                "traceback": text[-6000:],
            }
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
            os.chdir(home)
            for name, value in before.items():
                if value is None:
                    os.environ.pop(name, None)
                else:
                    os.environ[name] = value
    return {"exit": code, "error": error, "seconds": time.perf_counter() - start}


def _write_nan_trajectory(argv: list[str]) -> int:
    import h5py
    import numpy as np

    with h5py.File(argv[-1], "w") as h5:
        h5["t"] = np.array([0.0, 0.1])
        h5["state"] = np.array([[0.0, 1.0], [np.nan, 1.0]])
    return 0


def _leave_partial(argv: list[str]) -> int:
    Path(argv[-1]).with_name(f".{Path(argv[-1]).name}.partial").write_bytes(b"half")
    print("bad.anim:1:1: expected a fault, found one", file=sys.stderr)
    return 2


# Pseudo-verbs for the runner's own test (tests/test_fuzz_verbs.py): each misbehaves one way.
MISBEHAVIOURS: dict[str, Callable[[list[str]], int]] = {
    "selftest-signal": lambda argv: os.kill(os.getpid(), signal.SIGSEGV) or 0,
    "selftest-hang": lambda argv: time.sleep(3600) or 0,
    "selftest-raise": lambda argv: 1 // 0,
    "selftest-exit": lambda argv: os._exit(3),
    "selftest-exit-1": lambda argv: sys.exit(1),
    "selftest-nan": _write_nan_trajectory,
    "selftest-partial": _leave_partial,
    "selftest-chatty": lambda argv: print("one\ntwo", file=sys.stderr) or 2,
}


# --- the parent: dispatch, timeouts, signals --------------------------------------------------


@dataclass
class Run:
    """What happened to one case: the worker's per-step results, or how the worker ended."""

    case: Case
    case_id: str
    directory: Path
    logs: Path
    results: list[dict] = field(default_factory=list)
    ended: str = ""  # "hang", "signal", "died" when the worker did not report
    ended_detail: str = ""
    step: int = 0  # the step that was running when the worker ended
    seconds: float = 0.0


WORKER_START_S = 60.0  # how long a new worker may take to start before its first step


class Worker:
    """One worker process, the warm-up cases it still has to run, and the run it is busy with."""

    def __init__(self, context, environment: dict[str, str], scratch_cache: str, warmup: list):
        self.connection, child = context.Pipe()
        self.process = context.Process(
            target=worker_main, args=(child, environment, scratch_cache), daemon=True
        )
        self.process.start()
        child.close()
        self.warmup = collections.deque(warmup)
        self.run: Run | None = None
        self.warming = False
        self.timeout = math.inf
        self.deadline = math.inf
        self.started = 0.0
        self.cases = 0

    def begin(self, run: Run, steps: list, timeout: float, warming: bool = False) -> None:
        self.run, self.warming, self.timeout = run, warming, timeout
        self.started = time.monotonic()
        # a new worker first imports mosys (seconds on a busy machine): not the step's time
        self.deadline = self.started + timeout + (WORKER_START_S if self.cases == 0 else 0.0)
        self.cases += 1
        self.connection.send((str(run.directory), str(run.logs), steps))

    def poll(self) -> Run | None:
        """Take in what the worker said (a step begins, the case is done), or notice that it
        died or overran its deadline (then it is killed); the finished run, if any."""
        run = self.run
        assert run is not None
        dead = False
        try:
            while self.connection.poll():
                message = self.connection.recv()
                if message[0] == "step":
                    run.step = message[1]
                    self.deadline = time.monotonic() + self.timeout
                else:
                    run.results = message[1]
                    return self._finish()
        except (EOFError, OSError):
            dead = True
        if dead or not self.process.is_alive():
            self.process.join(10)
            code = self.process.exitcode
            if code is not None and code < 0:
                run.ended, run.ended_detail = "signal", signal.Signals(-code).name
            else:
                run.ended, run.ended_detail = "died", f"the worker exited with code {code}"
            return self._finish()
        if time.monotonic() > self.deadline:
            self.kill()
            run.ended, run.ended_detail = "hang", f"no answer in {self.timeout:g} s"
            return self._finish()
        return None

    def _finish(self) -> Run:
        run, self.run = self.run, None
        run.seconds = time.monotonic() - self.started
        return run

    @property
    def alive(self) -> bool:
        return self.process.is_alive() and not self.connection.closed

    def stop(self) -> None:
        with contextlib.suppress(OSError, ValueError):
            self.connection.send(None)
        self.process.join(5)
        self.kill()

    def kill(self) -> None:
        if self.process.is_alive():
            self.process.kill()  # this worker only: we started it
        self.process.join(10)
        self.connection.close()


class Pool:
    """``workers`` worker processes running cases, ``timeout`` seconds per step. Each worker
    first runs ``baseline_cases`` (its warm-up, ``warmup_timeout`` seconds a step: numba loads
    or compiles its caches there; none with ``warmup=False``), and is replaced after
    ``recycle_after`` cases, a hang or a death. ``baseline``: the warm-up runs (which must all
    succeed)."""

    def __init__(self, root: Path, shared: Path, workers: int, timeout: float,
                 warmup_timeout: float = 900.0, recycle_after: int = 250,
                 warmup: bool = True):  # fmt: skip
        self.root = root
        self.shared = shared
        self.count = workers
        self.timeout = timeout
        self.warmup_timeout = warmup_timeout
        self.recycle_after = recycle_after
        self.warmup = warmup
        self.context = multiprocessing.get_context("spawn")
        self.scratch_cache = root / "scratch_cache"
        for directory in (self.scratch_cache, root / "cases", root / "logs"):
            directory.mkdir(parents=True, exist_ok=True)
        self.workers: list[Worker] = []
        self.baseline: list[Run] = []
        self.starts = 0

    def __enter__(self) -> Pool:
        self.workers = [self._start() for _ in range(self.count)]
        return self

    def __exit__(self, *exc) -> None:
        for worker in self.workers:
            worker.stop()

    def _start(self) -> Worker:
        self.starts += 1
        warmup = [
            (f"warmup{self.starts:03d}-{number:02d}", case)
            for number, case in enumerate(baseline_cases() if self.warmup else [])
        ]
        return Worker(self.context, WORKER_ENVIRONMENT, str(self.scratch_cache), warmup)

    def _prepare(self, case: Case, case_id: str) -> tuple[Run, list]:
        """The case's fresh directory with its files written; its run and expanded steps."""
        directory = self.root / "cases" / case_id
        directory.mkdir(parents=True)
        for name, data in case.files:
            path = directory / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        steps = [
            ([expand(arg, directory, self.shared) for arg in step.argv], step.scratch_cache)
            for step in case.steps
        ]
        return Run(case, case_id, directory, self.root / "logs" / case_id), steps

    def run_cases(self, cases: Iterable[tuple[str, Case]],
                  progress: Callable[[Run], None] | None = None) -> list[Run]:  # fmt: skip
        """Run every (case id, case); the runs in the order they finished."""
        queue = collections.deque(cases)
        finished: list[Run] = []
        while queue or any(worker.run or worker.warmup for worker in self.workers):
            for index, worker in enumerate(self.workers):
                if worker.run is not None:
                    continue
                if not worker.alive or (worker.cases >= self.recycle_after and queue):
                    worker.stop()
                    worker = self.workers[index] = self._start()
                if worker.warmup:
                    case_id, case = worker.warmup.popleft()
                    run, steps = self._prepare(case, case_id)
                    worker.begin(run, steps, self.warmup_timeout, warming=True)
                elif queue:
                    case_id, case = queue.popleft()
                    worker.begin(*self._prepare(case, case_id), self.timeout)
            busy = [worker for worker in self.workers if worker.run]
            if not busy:
                continue
            soonest = min(worker.deadline for worker in busy) - time.monotonic()
            wait(
                [w.connection for w in busy] + [w.process.sentinel for w in busy],
                min(max(0.0, soonest) + 0.05, 5.0),
            )
            for worker in busy:
                warming = worker.warming
                done = worker.poll()
                if done is None:
                    continue
                if warming:
                    self.baseline.append(done)
                    if done.ended:
                        raise RuntimeError(
                            f"warm-up case {done.case_id} ({done.case.verbs}): {done.ended}, "
                            f"{done.ended_detail}; see {done.logs}.*"
                        )
                    continue
                finished.append(done)
                if progress:
                    progress(done)
        return finished


def expand(arg: str, case: Path, shared: Path) -> str:
    return (
        arg.replace("{case}", str(case))
        .replace("{shared}", str(shared))
        .replace("{specs}", str(SPECS))
    )


# --- judging a case ---------------------------------------------------------------------------

FAILING = ("signal", "hang", "died", "traceback", "bad-exit", "nan", "missing", "leftover",
           "message")  # fmt: skip
PASSING = ("ok", "refused", "limit", "usage")
CLASSES = FAILING + PASSING

# Datasets an output must hold finite ("finite") or at least without NaN ("no-nan"), by contract
# (../shared/DESIGN.md's data contracts and README's "When a simulation blows up"): a script's
# trajectory stops at a non-finite state (exit 2), so t and state are finite; figure motion is
# what plots draw; a controller table's value is inf where unreachable (never NaN) and its
# torque there is 0; a composite's scores may be NaN (IEEE arithmetic in the script), its motion
# not.
FIGURE_MOTION = ("t", "endpoints", "com")
CONTRACTS: dict[str, tuple[tuple[str, str], ...]] = {
    "dynamics": (),
    "trajectory": (("t", "finite"), ("state", "finite"))
    + tuple((f"figure_motion/{name}", "finite?") for name in FIGURE_MOTION),
    "controller": (("axes/*", "finite"), ("torque", "finite"), ("value", "no-nan")),
    "bsr": (("learning_curve/best_fitness", "no-nan"), ("@best_fitness", "no-nan"))
    + tuple((f"best/figure_motion/{name}", "finite") for name in FIGURE_MOTION),
    "composite": tuple((f"figure_motion/{name}", "finite") for name in FIGURE_MOTION)
    + tuple((f"before/figure_motion/{name}", "finite") for name in FIGURE_MOTION),
    "start_grid": (("start", "finite"),),
    "plot": (),  # a PNG (its signature checked)
}

# What a verb may print on stderr before its one-line error: progress lines, its own warnings
# ("warning: script.anim:4: ... outside its domain") and Python's.
PROGRESS_LINE = re.compile(r"^(\S.*: (\d+/\d+ .*ETA .*|done, .*)|warning: .*)$")
WARNING_LINE = re.compile(r"^\S.*:\d+: \w*Warning: ")


@dataclass
class Outcome:
    case_id: str
    case: Case
    klass: str
    problems: list[str]
    seconds: float
    step: int  # the step the class is about
    stderr: str
    traceback: str = ""
    warned: bool = False

    @property
    def failing(self) -> bool:
        return self.klass in FAILING


def read_log(run: Run, step: int, stream: str = "err") -> str:
    path = Path(f"{run.logs}.{step}.{stream}")
    try:
        return path.read_bytes()[-20000:].decode("utf-8", "backslashreplace")
    except OSError:
        return ""


def _check_contract(path: Path, contract: str) -> list[str]:
    import h5py
    import numpy as np

    problems = []
    if path.suffix == ".png" and path.read_bytes()[:8] != b"\x89PNG\r\n\x1a\n":
        problems.append(f"missing: {path.name} is not a PNG")
    if path.suffix != ".h5":
        return problems
    try:
        with h5py.File(path, "r") as h5:
            for pattern, rule in CONTRACTS[contract]:
                optional = rule.endswith("?")
                rule = rule.rstrip("?")
                if pattern.startswith("@"):
                    value = h5.attrs.get(pattern[1:])
                    if value is not None and np.isnan(np.asarray(value, dtype=float)).any():
                        problems.append(f"nan: {path.name} attr {pattern[1:]} is NaN")
                    continue
                group, _, name = pattern.rpartition("/")
                if name == "*":
                    names = [f"{group}/{key}" for key in h5.get(group, {})]
                else:
                    names = [pattern]
                for dataset in names:
                    if dataset not in h5:
                        if not optional:
                            problems.append(f"missing: {path.name} has no {dataset}")
                        continue
                    data = np.asarray(h5[dataset][()], dtype=float)
                    bad = np.isnan(data) if rule == "no-nan" else ~np.isfinite(data)
                    if bad.any():
                        what = "NaN" if rule == "no-nan" else "non-finite"
                        problems.append(
                            f"nan: {path.name}:/{dataset} has {int(bad.sum())} {what} of "
                            f"{data.size}"
                        )
    except OSError as error:
        problems.append(f"missing: {path.name} does not open with h5py ({error})")
    return problems


def _files(directory: Path) -> set[str]:
    return {
        str(path.relative_to(directory))
        for path in directory.rglob("*")
        if path.is_file() and "__pycache__" not in path.parts
    }


def judge(run: Run) -> Outcome:
    """Sort a finished run into one class (the first of ``CLASSES`` that applies) and list every
    problem found."""
    case = run.case
    problems: list[str] = []
    inputs = {name for name, _ in case.files}
    allowed = set(inputs)
    step_index = len(run.results) - 1 if run.results else run.step
    tb = ""
    if run.ended:
        step_index = run.step
        problems.append(f"{run.ended}: {run.ended_detail} (step {step_index + 1}: "
                        f"{case.steps[step_index].verb})")  # fmt: skip
    for index, result in enumerate(run.results):
        step = case.steps[index]
        if result["error"]:
            tb = result["error"]["traceback"]
            problems.append(
                f"traceback: {result['error']['type']}: {result['error']['message'][:200]}"
            )
        elif result["exit"] not in (0, 2):
            problems.append(f"bad-exit: exit {result['exit']}")
        if result["exit"] == 0:
            for output in step.outputs:
                path = run.directory / output
                if not path.is_file():
                    problems.append(f"missing: exit 0 without {output}")
                else:
                    problems += _check_contract(path, step.contract)
            allowed |= set(step.outputs)
    stderr = read_log(run, step_index) if (run.results or run.ended) else ""
    left = sorted(_files(run.directory) - allowed)
    if left:
        problems.append(f"leftover: {', '.join(left[:5])}")
    final = run.results[-1] if run.results else None
    lines = [line for line in stderr.split("\n") if line.strip()]  # not at \r, \x0b, ...
    warned = any(WARNING_LINE.match(line) for line in lines)
    if final and final["exit"] == 2 and not final["error"]:
        if "Traceback" in stderr:
            problems.append("message: exit 2 with a traceback on stderr")
        usage = any(line.startswith("usage: mosys") for line in lines)
        message = [
            line
            for line in lines
            if not PROGRESS_LINE.match(line)
            and not WARNING_LINE.match(line)
            and not line.startswith(" ")
            and not line.startswith("usage: mosys")
        ]
        if len(message) != 1:
            problems.append(f"message: exit 2 with {len(message)} message lines on stderr")
    else:
        usage = False
    if run.ended == "signal" and "Fatal Python error" in stderr:
        tb = stderr[-6000:]
    if problems:
        klass = next(k for k in FAILING if any(p.startswith(k + ":") for p in problems))
    elif final and final["exit"] == 2:
        klass = "usage" if usage else "limit" if "MOSYS_MAX_" in stderr else "refused"
    else:
        klass = "ok"
    return Outcome(run.case_id, case, klass, problems, run.seconds, step_index, stderr, tb, warned)


# --- reports ----------------------------------------------------------------------------------


def counts_table(outcomes: list[Outcome]) -> str:
    """Cases per kind x class (and with warnings on stderr), as a fixed-width table."""
    counts = collections.Counter((o.case.kind, o.klass) for o in outcomes)
    warned = collections.Counter(o.case.kind for o in outcomes if o.warned)
    columns = CLASSES
    header = ["kind", *columns, "total", "warned"]
    rows = []
    for kind in KINDS:
        total = sum(v for (k, _), v in counts.items() if k == kind)
        if total:
            rows.append([kind, *(counts[kind, c] for c in columns), total, warned[kind]])
    rows.append(["all", *(sum(counts[k, c] for k in KINDS) for c in columns), len(outcomes),
                 sum(warned.values())])  # fmt: skip
    widths = [max(len(str(row[i])) for row in [header, *rows]) for i in range(len(header))]
    return "\n".join(
        "  ".join(str(cell).rjust(width) for cell, width in zip(row, widths, strict=True))
        for row in [header, *rows]
    )


def signature(outcome: Outcome) -> str:
    """What makes two failing outcomes the same finding: the class, the verb, and the innermost
    mosys frame of a traceback (or the exception type), the dataset of a NaN, the spec of a
    hang."""
    case = outcome.case
    step = case.steps[min(outcome.step, len(case.steps) - 1)]
    frame = ""
    for match in re.finditer(
        r'File "([^"]*src/mosys/[^"]*)", line (\d+), in (\w+)', outcome.traceback
    ):
        frame = f"{Path(match[1]).relative_to(ROOT / 'src')}:{match[3]}"
    if not frame:
        for match in re.finditer(
            r'File "([^"]*mosys[^"]*)", line (\d+) in (\w+)', outcome.traceback
        ):
            frame = f"{match[1].split('mosys/')[-1]}:{match[3]}"
            break
    first = outcome.problems[0] if outcome.problems else ""
    if outcome.klass == "traceback":
        kind = first.split(":")[1].strip()
        return f"traceback {step.verb} {kind} at {frame or '?'}"
    if outcome.klass == "signal":
        return f"signal {step.verb} {first.split(':')[1].split('(')[0].strip()} at {frame or '?'}"
    if outcome.klass == "nan":
        dataset = re.sub(r"\d+", "N", first.split(":/")[-1].split(" has")[0])
        return f"nan {step.verb} {case.kind} /{dataset}"
    if outcome.klass == "hang":
        return f"hang {step.verb} {case.kind} {case.source}".rstrip()
    return f"{outcome.klass} {step.verb} {case.kind}"


def shown_argv(step: Step) -> str:
    """A step's command line as a user would type it from the repository root."""
    words = []
    for arg in step.argv:
        arg = (
            arg.replace("{shared}/dynamics", "results/dynamics")
            .replace("{shared}/controllers", "results/controllers")
            .replace("{shared}/bsr", "results/bsr")
            .replace("{specs}", "specs")
            .replace("{case}/", "")
            .replace("{case}", ".")
        )
        words.append(arg if re.fullmatch(r"[\w./=:+-]+", arg) else repr(arg))
    return "mosys " + " ".join(words)


def spec_diff(case: Case, most_lines: int = 12, width: int = 160) -> str:
    if not case.files or not case.original:
        return ""
    name, data = case.files[0]
    old = case.original.decode("utf-8", "backslashreplace").splitlines()
    new = data.decode("utf-8", "backslashreplace").splitlines()
    lines = list(difflib.unified_diff(old, new, f"{case.source}", name, n=0, lineterm=""))
    cut = [
        line if len(line) <= width else f"{line[:width]}...({len(line)} chars)" for line in lines
    ]
    if len(cut) > most_lines:
        cut = cut[:most_lines] + [f"... ({len(cut) - most_lines} more diff lines)"]
    return "\n".join(cut)


def reproducer(outcome: Outcome) -> str:
    case = outcome.case
    parts = [f"case {outcome.case_id} ({case.kind}, {outcome.seconds:.1f} s): "
             f"{'; '.join(case.mutations)}"]  # fmt: skip
    if case.source:
        parts.append(f"files: {', '.join(name for name, _ in case.files)} from {case.source}")
    parts += [shown_argv(step) for step in case.steps]
    diff = spec_diff(case)
    if diff:
        parts += ["```diff", diff, "```"]
    parts.append("outcome: " + "; ".join(outcome.problems))
    if outcome.traceback:
        parts += ["```", *traceback_summary(outcome.traceback), "```"]
    elif outcome.stderr.strip():
        last = [line for line in outcome.stderr.split("\n") if line.strip()][-8:]
        parts += ["```", *(line[:300] for line in last), "```"]
    return "\n".join(parts)


def traceback_summary(text: str, most: int = 14) -> list[str]:
    """A traceback's (or faulthandler dump's) frames in mosys's source, each with its code line,
    and its last line (the exception)."""
    lines = [line for line in text.split("\n") if line.strip()]
    kept = []
    for number, line in enumerate(lines):
        if "src/mosys/" in line and line.lstrip().startswith("File "):
            kept.append(line[:300])
            following = lines[number + 1] if number + 1 < len(lines) else ""
            if following.startswith("    ") and not following.lstrip().startswith("File "):
                kept.append(following[:300])
    kept = kept[-(most - 1) :] if kept else lines[-(most - 1) : -1]
    return [*kept, lines[-1][:300]] if lines else []


def findings_markdown(outcomes: list[Outcome], title: str) -> str:
    """Every failing outcome grouped by ``signature``; each group with the smallest case's
    reproducer and how many cases share it."""
    groups: dict[str, list[Outcome]] = collections.defaultdict(list)
    for outcome in outcomes:
        if outcome.failing:
            groups[signature(outcome)].append(outcome)
    text = [f"# {title}", "", "```", counts_table(outcomes), "```", ""]
    for number, (key, members) in enumerate(sorted(groups.items()), start=1):
        smallest = min(members, key=lambda o: (o.case.size(), o.case_id))
        text += [f"## {number}. {key} ({len(members)} cases)", "", reproducer(smallest), ""]
        text += ["all cases:"] + [
            f"- {o.case_id} {o.case.source or o.case.verbs}: {'; '.join(o.case.mutations)}"[:300]
            for o in sorted(members, key=lambda o: o.case_id)[:12]
        ]
        text += [f"- ... and {len(members) - 12} more" if len(members) > 12 else "", ""]
    return "\n".join(text)


def clean(run: Run) -> None:
    shutil.rmtree(run.directory, ignore_errors=True)
    for path in run.logs.parent.glob(f"{run.logs.name}.*"):
        path.unlink(missing_ok=True)
