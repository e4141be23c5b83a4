"""The motor program (``.mot``): a procedural function of joint torques over time, as van de
Panne, Fiume & Vranesic (1990) drive Luxo the lamp through its airborne motions. Two kinds: a
program of ``phase`` lines (servo targets and constant torques held phase after phase), or a
keyframed program of ``key`` lines (joint targets at times, interpolated smoothly between them:
the key-framing the paper concatenates with its controllers, section 3).

::

    # hop: a short hop forward
    figure luxo                               # the figure it drives: specs/figures/luxo.fig
    limit hip_torque=5 elbow_torque=5         # optional: |torque| cap per actuator, N m
    gains kp=6 kd=0.25                        # optional: servo gains, N m/rad and N m s/rad
    phase 0.35 hip=10 elbow=150               # 0.35 s: servo 'hip' towards 10 deg, 'elbow' 150
    phase 0.12 hip=-30 elbow=40 kp=40 kd=0.3  # gains for this phase only
    phase 0.30 hip_torque=-2 elbow_torque=1.5 # constant torques, N m
    phase 0.2 hip=0 elbow_torque=0.5          # mixed: hip servoed, elbow a constant torque

    # swing: a keyframed pendulum swing
    figure link1
    limit torque=10
    gains kp=200 kd=15
    key 0.0 angle=-90                         # at 0 s the target is -90 deg (hanging)
    key 0.6 angle=-30                         # ... -30 deg at 0.6 s
    key 1.4 angle=-150
    key 2.0 angle=-90                         # the program ends at its last key: 2 s

Grammar (one line each; ``#`` comments and blank lines are ignored)::

    figure NAME                     exactly once, before the first phase or key
    limit ACTUATOR=N_M ...          at most once, before the first phase or key; each value > 0
                                    (default: no cap)
    gains [kp=KP] [kd=KD]           at most once, before the first phase or key; at least one
                                    of the two, each >= 0, N m/rad and N m s/rad (default: 0
                                    and 0)
    phase SECONDS [NAME=VALUE ...]  SECONDS > 0. kp= and kd= (>= 0) override the gains for this
                                    phase; any other NAME is a joint coordinate (VALUE: its
                                    target angle, degrees) or an actuator (VALUE: a constant
                                    torque, N m), each NAME once per phase
    key TIME JOINT=DEGREES ...      TIME in s, finite: the first key's 0, each later one greater
                                    than the one before; at least one JOINT=DEGREES, each joint
                                    once per key, and every key names the same joints as the
                                    first (in any order). kp=/kd= are not allowed on a key.

A program has one or more ``phase`` lines or two or more ``key`` lines, never both.

The phases run one after another from time 0; an actuator that a phase does not mention is limp
(zero torque) for that phase. A keyframed program lasts until its last key; a joint it names is
servoed, with the program's gains, towards a C1 cubic through the keys (the rule is
``animation.motor_program.keyframe_curve``), and an actuator whose joint it does not name is limp
throughout. The parser does not know the figure, so it keeps each line's settings as written;
``bind_motor_program`` classifies them against the figure's coordinates and actuators and lays
the program out as arrays for a numeric kernel.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mosys.parsing.tokens import (
    END_OF_FILE,
    NAME,
    Line,
    SpecError,
    Token,
    parse_number,
    read_spec_text,
    record_once,
    tokenize,
    unknown_keyword,
    value_token,
)

KEYWORDS = ("figure", "limit", "gains", "phase", "key")
BODY = ("phase", "key")  # the lines that make the program; the others go before them
GAINS = ("kp", "kd")
DEFAULT_KP = 0.0  # N·m/rad
DEFAULT_KD = 0.0  # N·m·s/rad

LIMP = 0  # BoundProgram.mode: zero torque
TORQUE = 1  # a constant torque, N·m
SERVO = 2  # PD servo towards a target angle, rad


@dataclass(frozen=True)
class Setting:
    """One ``NAME=VALUE`` of a program: on the ``limit`` line, an actuator's torque limit (its
    torque is clipped to ``[-value, value]``, N·m, > 0); on a ``phase`` line (other than
    ``kp=``/``kd=``), a joint coordinate's target angle (degrees) or an actuator's constant torque
    (N·m), which of the two being settled by ``bind_motor_program``; on a ``key`` line, a joint
    coordinate's target angle (degrees). ``token`` is the whole ``name=value`` token."""

    name: str
    value: float
    token: Token

    @property
    def name_token(self) -> Token:
        """The name part of ``token``."""
        return Token(self.name, self.token.line, self.token.column)

    @property
    def value_token(self) -> Token:
        """The value part of ``token``."""
        return value_token(self.token, self.name)


@dataclass(frozen=True)
class Phase:
    """One ``phase`` line: for ``seconds`` (> 0, s) apply ``settings`` (file order). ``kp``
    (N·m/rad) and ``kd`` (N·m·s/rad) override the program's gains for this phase (None: not
    given). ``token`` is the keyword; ``seconds_token`` the duration."""

    seconds: float
    settings: tuple[Setting, ...]
    kp: float | None
    kd: float | None
    token: Token
    seconds_token: Token


@dataclass(frozen=True)
class Key:
    """One ``key`` line: at ``time`` (s from the program's start, >= 0) the named joints' target
    angles ``settings`` (degrees, file order). ``token`` is the keyword; ``time_token`` the
    time."""

    time: float
    settings: tuple[Setting, ...]
    token: Token
    time_token: Token


@dataclass(frozen=True)
class MotorProgram:
    """A parsed ``.mot`` file.

    ``figure`` names the figure it drives. ``limits`` (file order) cap actuators' torques, N·m.
    ``kp`` (N·m/rad) and ``kd`` (N·m·s/rad) are the default servo gains (0 unless a ``gains``
    line sets them). ``phases`` run in file order from time 0. ``keys`` (time order) are a
    keyframed program's keyframes; a program has phases or keys, the other being empty.
    ``spec_sha256`` is the hex SHA-256 of the file's bytes.
    """

    path: str
    figure: str
    figure_token: Token
    limits: tuple[Setting, ...]
    kp: float
    kd: float
    phases: tuple[Phase, ...]
    spec_sha256: str
    keys: tuple[Key, ...] = ()

    @property
    def keyframed(self) -> bool:
        """Whether the program is keyframed (``key`` lines) rather than phased."""
        return bool(self.keys)

    @property
    def name(self) -> str:
        """The program's name: the file's stem (``hop`` for ``hop.mot``)."""
        return Path(self.path).stem

    def duration(self) -> float:
        """The program's length, s: the total time of its phases, or its last key's time."""
        if self.keys:
            return self.keys[-1].time
        return sum(phase.seconds for phase in self.phases)

    def error(self, token: Token, expected: str) -> SpecError:
        """A SpecError at ``token`` of this program, found its text: for checks made after
        parsing (against the figure, say)."""
        return SpecError.at(self.path, token, expected)


@dataclass(frozen=True, eq=False)
class BoundProgram:
    """A motor program laid out against a figure, for a numeric kernel. With P phases and A
    actuators (the figure's actuated coordinates, in coordinate order):

    ``durations``: (P,) float64, s. ``mode``: (P, A) int64, ``LIMP`` (0: zero torque),
    ``TORQUE`` (1: constant torque) or ``SERVO`` (2: PD servo). ``value``: (P, A) float64, the
    torque (N·m) for ``TORQUE``, the target angle (rad) for ``SERVO``, 0 for ``LIMP``.
    ``kp``: (P, A) float64, N·m/rad and ``kd``: (P, A) float64, N·m·s/rad, the phase's gains
    (else the program's). ``limit``: (A,) float64, the torque cap, N·m (inf: none).
    ``coordinate``: (A,) int64, the index of each actuator's coordinate among the figure's.
    ``actuator_names``: (A,) the actuators' names.

    A keyframed program (K keys) has ``key_times``: (K,) float64, s, increasing from 0, and its
    rows are keys, not phases: ``mode``, ``value``, ``kp``, ``kd`` are (K, A), ``value`` the
    key's target angle (rad) where ``mode`` is ``SERVO`` (the same actuators in every row; the
    others ``LIMP``), and ``durations`` (K - 1,) the intervals between keys. ``key_times`` is
    None for a phase program.
    """

    durations: np.ndarray
    mode: np.ndarray
    value: np.ndarray
    kp: np.ndarray
    kd: np.ndarray
    limit: np.ndarray
    coordinate: np.ndarray
    actuator_names: tuple[str, ...]
    key_times: np.ndarray | None = None

    @property
    def keyframed(self) -> bool:
        """Whether the rows are keys (``key_times`` given) rather than phases."""
        return self.key_times is not None

    def duration(self) -> float:
        """The program's length, s: its phases' total, or its last key's time."""
        if self.key_times is not None:
            return float(self.key_times[-1])
        return float(self.durations.sum())


def parse_motor_program(path: str | Path) -> MotorProgram:
    """Parse a ``.mot`` file; any problem raises SpecError naming file, line and column."""
    text, digest = read_spec_text(path)
    return parse_motor_program_text(text, str(path), digest)


def parse_motor_program_text(
    text: str, path: str = "<text>", spec_sha256: str | None = None
) -> MotorProgram:
    """Parse ``.mot`` text; ``path`` names it in errors. ``spec_sha256`` defaults to the SHA-256
    of the text's UTF-8 encoding."""
    if spec_sha256 is None:
        spec_sha256 = hashlib.sha256(text.encode("utf-8")).hexdigest()
    return _Parser(path).parse(tokenize(text, path), spec_sha256)


class _Parser:
    def __init__(self, path: str):
        self.path = path
        self.figure: Token | None = None
        self.limits: tuple[Setting, ...] = ()
        self.gains: dict[str, float] = {}
        self.phases: list[Phase] = []
        self.keys: list[Key] = []
        self.first_line: dict[str, int] = {}  # once-only keyword -> its line number
        self.total = 0.0  # s, the phases so far

    def error(self, token: Token, expected: str, found: str | None) -> SpecError:
        return SpecError(self.path, token.line, token.column, expected, found)

    def parse(self, lines: list[Line], spec_sha256: str) -> MotorProgram:
        for line in lines:
            keyword = line.keyword
            if keyword.text not in KEYWORDS:
                raise unknown_keyword(line, KEYWORDS)
            body = self.body()
            if keyword.text in BODY:
                if self.figure is None:
                    raise self.error(
                        keyword, f"a 'figure' line before the first '{keyword.text}'", keyword.text
                    )
                if body is not None and body.text != keyword.text:
                    raise self.error(
                        keyword,
                        f"a '{body.text}' line (a program has 'phase' lines or 'key' lines, "
                        f"not both; the first '{body.text}' is line {body.line})",
                        keyword.text,
                    )
            else:
                record_once(line, self.first_line)
                if body is not None:
                    raise self.error(
                        keyword,
                        f"a '{body.text}' line ('{keyword.text}' goes before the first "
                        f"'{body.text}', line {body.line})",
                        keyword.text,
                    )
            getattr(self, f"line_{keyword.text}")(line)
        last = lines[-1].number + 1 if lines else 1
        if self.figure is None:
            raise SpecError(self.path, last, 1, "a 'figure' line", END_OF_FILE)
        if not self.phases and not self.keys:
            raise SpecError(self.path, last, 1, "a 'phase' or 'key' line", END_OF_FILE)
        if len(self.keys) == 1:
            raise SpecError(
                self.path,
                last,
                1,
                f"a second 'key' line (a keyframed program needs 2 or more; the first is line "
                f"{self.keys[0].token.line})",
                END_OF_FILE,
            )
        return MotorProgram(
            path=self.path,
            figure=self.figure.text,
            figure_token=self.figure,
            limits=self.limits,
            kp=self.gains.get("kp", DEFAULT_KP),
            kd=self.gains.get("kd", DEFAULT_KD),
            phases=tuple(self.phases),
            spec_sha256=spec_sha256,
            keys=tuple(self.keys),
        )

    def body(self) -> Token | None:
        """The keyword of the program's first 'phase' or 'key' line, None before it."""
        if self.phases:
            return self.phases[0].token
        if self.keys:
            return self.keys[0].token
        return None

    def assignment(self, token: Token, expected: str) -> tuple[str, Token]:
        """A ``name=value`` token: the name and the value part (its own column)."""
        name, sep, _ = token.text.partition("=")
        if not sep:
            raise self.error(token, expected, token.text)
        if NAME.fullmatch(name) is None:
            raise self.error(token, "a name before '='", name)
        return name, value_token(token, name)

    def number_at_least(self, token: Token, what: str, minimum: float, strict: bool) -> float:
        value = parse_number(token, self.path, what)
        if value < minimum or (strict and value == minimum):
            relation = ">" if strict else ">="
            raise self.error(token, f"a number {relation} {minimum:g} for {what}", token.text)
        return value

    def line_figure(self, line: Line) -> None:
        reader = line.reader()
        token = reader.peek()
        reader.name("the figure")
        reader.end()
        self.figure = token

    def line_limit(self, line: Line) -> None:
        expected = "a torque limit 'actuator=value' (N m)"
        if len(line.tokens) == 1:
            raise SpecError(self.path, line.number, line.end_column, expected, None)
        limits: dict[str, Setting] = {}
        for token in line.tokens[1:]:
            name, part = self.assignment(token, expected)
            if name in limits:
                raise self.error(token, f"'{name}=' only once", token.text)
            value = self.number_at_least(part, f"limit {name}", 0.0, strict=True)
            limits[name] = Setting(name, value, token)
        self.limits = tuple(limits.values())

    def line_gains(self, line: Line) -> None:
        expected = "one of 'kp=', 'kd='"
        if len(line.tokens) == 1:
            raise SpecError(self.path, line.number, line.end_column, expected, None)
        for token in line.tokens[1:]:
            self.gain(token, expected, self.gains)

    def gain(self, token: Token, expected: str, gains: dict[str, float]) -> None:
        """A ``kp=`` or ``kd=`` token (value >= 0) into ``gains``."""
        name, part = self.assignment(token, expected)
        if name not in GAINS:
            raise self.error(token, expected, token.text)
        if name in gains:
            raise self.error(token, f"'{name}=' only once", token.text)
        gains[name] = self.number_at_least(part, name, 0.0, strict=False)

    def line_phase(self, line: Line) -> None:
        reader = line.reader()
        seconds_token = reader.peek()
        seconds = reader.number("seconds")
        assert seconds_token is not None
        if not seconds > 0:
            raise self.error(seconds_token, "a number > 0 for seconds", seconds_token.text)
        if not math.isfinite(self.total + seconds):
            raise self.error(
                seconds_token, "seconds with a finite total duration", seconds_token.text
            )
        self.total += seconds
        expected = "a setting 'name=value' (joint=degrees, actuator=N m, kp= or kd=)"
        gains: dict[str, float] = {}
        settings: dict[str, Setting] = {}
        for token in reader.remaining():
            name, part = self.assignment(token, expected)
            if name in GAINS:
                self.gain(token, expected, gains)
                continue
            if name in settings:
                raise self.error(token, f"'{name}=' only once", token.text)
            value = parse_number(part, self.path, name)
            settings[name] = Setting(name, value, token)
        self.phases.append(
            Phase(
                seconds,
                tuple(settings.values()),
                gains.get("kp"),
                gains.get("kd"),
                line.keyword,
                seconds_token,
            )
        )

    def line_key(self, line: Line) -> None:
        reader = line.reader()
        time_token = reader.peek()
        time = reader.number("the key time")
        assert time_token is not None
        if time < 0:
            raise self.error(time_token, "a number >= 0 for the key time", time_token.text)
        if not self.keys and time != 0:
            raise self.error(
                time_token,
                "0 for the first key's time (a keyframed program starts at its first key)",
                time_token.text,
            )
        if self.keys and not time > self.keys[-1].time:
            previous = self.keys[-1]
            raise self.error(
                time_token,
                f"a time after {previous.time_token.text} s, the previous key's (line "
                f"{previous.token.line}; keyframes out of order)",
                time_token.text,
            )
        expected = "a joint target 'joint=degrees'"
        settings: dict[str, Setting] = {}
        for token in reader.remaining():
            name, part = self.assignment(token, expected)
            if name in GAINS:
                raise self.error(
                    token, f"{expected} (gains go on the 'gains' line, not on keys)", token.text
                )
            if name in settings:
                raise self.error(token, f"'{name}=' only once", token.text)
            if self.keys and name not in {setting.name for setting in self.keys[0].settings}:
                raise self.error(
                    token,
                    f"a joint the first key names (line {self.keys[0].token.line}: "
                    f"{_quoted(setting.name for setting in self.keys[0].settings)})",
                    token.text,
                )
            settings[name] = Setting(name, parse_number(part, self.path, name), token)
        if not settings:
            raise SpecError(self.path, line.number, line.end_column, expected, None)
        if self.keys:
            for setting in self.keys[0].settings:
                if setting.name not in settings:
                    raise SpecError(
                        self.path,
                        line.number,
                        line.end_column,
                        f"a target for '{setting.name}' (every key names the joints of the "
                        f"first, line {self.keys[0].token.line})",
                        None,
                    )
        self.keys.append(Key(time, tuple(settings.values()), line.keyword, time_token))


def _quoted(names) -> str:
    """``'a', 'b'`` for an error message."""
    return ", ".join(f"'{name}'" for name in names)


def render_motor_program(program: MotorProgram) -> str:
    """The ``.mot`` text of ``program`` (parsing it gives back the same values). ``limit`` and
    ``gains`` are written only when they say something."""

    def number(value: float) -> str:
        return repr(float(value))

    lines = [f"figure {program.figure}"]
    if program.limits:
        lines.append(
            "limit " + " ".join(f"{limit.name}={number(limit.value)}" for limit in program.limits)
        )
    if program.kp != DEFAULT_KP or program.kd != DEFAULT_KD:
        lines.append(f"gains kp={number(program.kp)} kd={number(program.kd)}")
    for phase in program.phases:
        words = [f"phase {number(phase.seconds)}"]
        words += [f"{setting.name}={number(setting.value)}" for setting in phase.settings]
        words += [
            f"{name}={number(gain)}"
            for name, gain in (("kp", phase.kp), ("kd", phase.kd))
            if gain is not None
        ]
        lines.append(" ".join(words))
    for key in program.keys:
        words = [f"key {number(key.time)}"]
        words += [f"{setting.name}={number(setting.value)}" for setting in key.settings]
        lines.append(" ".join(words))
    return "\n".join(lines) + "\n"


def _choices(names: Sequence[str]) -> str:
    """``one of: 'a', 'b'`` for an error message."""
    if not names:
        return "the figure has none"
    return "one of: " + ", ".join(f"'{name}'" for name in names)


def bind_motor_program(
    program: MotorProgram,
    coordinate_names: Sequence[str],
    actuator_names: Sequence[str],
) -> BoundProgram:
    """Classify each phase (or key) setting against a figure and lay the program out as arrays.

    ``coordinate_names``: (n,) the figure's coordinates (``Figure.q_names``);
    ``actuator_names``: (n,) aligned with them, the actuator of each, ``""`` where unactuated
    (``Figure.tau_names``). Luxo: ``('x', 'y', 'base', 'hip', 'elbow')`` and
    ``('', '', '', 'hip_torque', 'elbow_torque')``. A setting named after an actuated coordinate
    servos it (target degrees -> radians); one named after an actuator sets a constant torque
    (on a phase; a key sets joint targets only).

    A setting or ``limit`` naming nothing the figure can drive, a phase that drives one actuator
    twice (its joint's target and its torque), and a servo with kp = kd = 0 raise SpecError at
    the offending token. Mismatched argument lengths raise ValueError.
    """
    if len(coordinate_names) != len(actuator_names):
        raise ValueError(
            f"{len(coordinate_names)} coordinate names but {len(actuator_names)} actuator names"
        )
    actuated = [index for index, actuator in enumerate(actuator_names) if actuator]
    names = tuple(actuator_names[index] for index in actuated)
    joints = {coordinate_names[index]: a for a, index in enumerate(actuated)}
    actuators = {name: a for a, name in enumerate(names)}
    unactuated = {
        coordinate
        for coordinate, actuator in zip(coordinate_names, actuator_names, strict=True)
        if not actuator
    }
    figure = program.figure
    drivable = _choices([coordinate_names[index] for index in actuated] + list(names))

    limit = np.full(len(names), np.inf)
    for entry in program.limits:
        if entry.name not in actuators:
            raise program.error(
                entry.name_token, f"an actuator of figure '{figure}' ({_choices(names)})"
            )
        limit[actuators[entry.name]] = entry.value
    coordinate = np.array(actuated, dtype=np.int64)
    if program.keys:
        return _bind_keys(program, names, joints, unactuated, limit, coordinate)

    shape = (len(program.phases), len(names))
    mode = np.full(shape, LIMP, dtype=np.int64)
    value = np.zeros(shape)
    kp = np.zeros(shape)
    kd = np.zeros(shape)
    for p, phase in enumerate(program.phases):
        kp[p] = program.kp if phase.kp is None else phase.kp
        kd[p] = program.kd if phase.kd is None else phase.kd
        driven: dict[int, Setting] = {}  # actuator -> the setting that drives it
        for setting in phase.settings:
            if setting.name in joints:
                a, kind, amount = joints[setting.name], SERVO, math.radians(setting.value)
            elif setting.name in actuators:
                a, kind, amount = actuators[setting.name], TORQUE, setting.value
            elif setting.name in unactuated:
                raise program.error(
                    setting.name_token,
                    f"an actuated joint angle or an actuator of figure '{figure}' "
                    f"(coordinate '{setting.name}' has no actuator; {drivable})",
                )
            else:  # or a gain: 'Kp=' for 'kp=' read as a joint no figure has
                raise program.error(
                    setting.name_token,
                    f"a joint angle or an actuator of figure '{figure}' ({drivable}), or a "
                    "phase's gain kp= or kd=",
                )
            if a in driven:
                earlier = driven[a].token
                raise program.error(
                    setting.name_token,
                    f"one setting per actuator ('{earlier.text}' at column {earlier.column} "
                    f"already drives '{names[a]}' in this phase)",
                )
            if kind == SERVO and kp[p, a] == 0 and kd[p, a] == 0:
                raise program.error(
                    setting.token,
                    f"servo gains kp > 0 or kd > 0 to servo '{setting.name}' "
                    "(set 'gains' or kp= on the phase)",
                )
            driven[a] = setting
            mode[p, a] = kind
            value[p, a] = amount
    return BoundProgram(
        durations=np.array([phase.seconds for phase in program.phases], dtype=np.float64),
        mode=mode,
        value=value,
        kp=kp,
        kd=kd,
        limit=limit,
        coordinate=coordinate,
        actuator_names=names,
    )


def _bind_keys(
    program: MotorProgram,
    names: tuple[str, ...],
    joints: dict[str, int],
    unactuated: set[str],
    limit: np.ndarray,
    coordinate: np.ndarray,
) -> BoundProgram:
    """``bind_motor_program`` for a keyframed program: ``names`` (A,) the actuators, ``joints``
    each actuated coordinate's actuator index, ``unactuated`` the other coordinates; ``limit``
    and ``coordinate`` (A,) already bound."""
    figure = program.figure
    servoable = _choices(list(joints))
    shape = (len(program.keys), len(names))
    mode = np.full(shape, LIMP, dtype=np.int64)
    value = np.zeros(shape)
    for k, key in enumerate(program.keys):
        for setting in key.settings:
            if setting.name not in joints:
                if setting.name in names:
                    why = f"a key sets joint targets, not torques; {servoable}"
                elif setting.name in unactuated:
                    why = f"coordinate '{setting.name}' has no actuator; {servoable}"
                else:
                    why = servoable
                kind = "an actuated joint angle" if setting.name in unactuated else "a joint angle"
                raise program.error(setting.name_token, f"{kind} of figure '{figure}' ({why})")
            if program.kp == 0 and program.kd == 0:
                raise program.error(
                    setting.token,
                    f"servo gains kp > 0 or kd > 0 to servo '{setting.name}' (set 'gains')",
                )
            mode[k, joints[setting.name]] = SERVO
            value[k, joints[setting.name]] = math.radians(setting.value)
    times = np.array([key.time for key in program.keys], dtype=np.float64)
    return BoundProgram(
        durations=np.diff(times),
        mode=mode,
        value=value,
        kp=np.full(shape, program.kp),
        kd=np.full(shape, program.kd),
        limit=limit,
        coordinate=coordinate,
        actuator_names=names,
        key_times=times,
    )
