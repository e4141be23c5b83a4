"""The controller spec (``.ssc``): the 1990 paper's Figure 12, plus a few optional settings.

::

    dyn link1                          # the figure: specs/figures/link1.fig
    ssd omega -500.0 500.0 21          # state dimension: name min max samples
    ssd angle -180 170 36 wrap         # 'wrap': periodic dimension (period samples * step);
                                       # or a line 'wrap angle' after it, as the paper writes it
    torq torque -10.0 10.0 11 0.1      # control: name min max samples K
    dest angle=0 omega=0               # destination state (grid nodes); may be repeated
    tol 1e-6                           # optional: convergence tolerance, s (default 1e-6)
    maxiter 1000                       # optional: iteration cap (default 1000)
    dt 0.05                            # optional: longest DP step, s (default 0.05; >= 1e-5)
    known_weight 0.8                   # optional: share of an exit's weight on known corners
    obstacle curb -20,-1 20,-1 20,0 -20,0   # optional: a polygon the body must not overlap, m
    domain -4,0.5 8,0.5 8,4 -4,4       # optional: a polygon the reference point stays in, m
    hold                               # optional: the destination nodes hold the figure at rest
    policy lookahead x=0.1 y=0.1 heading=4  # optional: the runtime (default 'interpolate')

Several ``dest`` lines make a "conditional" goal (the paper's §3: "given more than one
destination state, perform the easiest motion"): the DP drives each state to whichever
destination is cheapest from it. Each line is checked as a single one is; two lines naming the
same dimensions at the same nodes are an error at the second one's keyword. ``hold`` then holds
the figure at the nodes of every destination; ``policy lookahead`` (a vehicle braking at one
destination) takes a single ``dest`` line.

``obstacle`` and ``domain`` are for figures with a body outline (the car): their vertices are in
metres in the frame of the figure's ``x``/``y`` state variables. ``hold`` is for a destination at
rest: its nodes store the torques that keep the figure still there (``ssc.generate``), instead of
the DP's best control sample. ``known_weight`` (in (0, 1]; default: any share) is the share
of an exit's interpolation weight that must rest on corners whose cost-to-go is known for the
exit to count, in the DP and in the lookahead runtime alike. ``policy`` says how the table
runs: ``interpolate`` (the paper's n-linear interpolation of the controls) or, for a vehicle,
``lookahead`` (``kernels.lookahead``) with the arrival tolerance of some ``dest`` dimensions,
where the vehicle brakes and holds.

Values are in spec units: degrees for angles, deg/s for angular rates, metres and m/s otherwise
(the figure says which). The full grammar is in the README, "Controller spec (``.ssc``)".
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from mosys.parsing.tokens import (
    Line,
    LineReader,
    SpecError,
    Token,
    missing_line,
    parse_number,
    read_spec_text,
    record_once,
    tokenize,
    unknown_keyword,
    value_token,
)

KEYWORDS = (
    "dyn",
    "ssd",
    "wrap",
    "torq",
    "dest",
    "tol",
    "maxiter",
    "dt",
    "known_weight",
    "obstacle",
    "domain",
    "hold",
    "policy",
)
POLICIES = ("interpolate", "lookahead")
ARRIVAL_VALUE = "arrival_value"  # the policy line's flag: keep the cost-to-go to the whole box
DEFAULT_TOLERANCE = (
    1e-6  # s: largest change of the cost-to-go in one sweep that counts as converged
)
DEFAULT_MAX_ITERATIONS = 1000
DEFAULT_DT = 0.05  # s: the longest step of the DP's integrator (kernels.dp_exits)
MIN_DT = 1e-5  # s: below this a segment that stays in its cell (2 s) would take 200,000 steps
MAX_NODES = 100_000_000  # state grid nodes (product of the ssd samples): 0.8 GB per table
MAX_CONTROLS = 1_000_000  # control samples (product of the torq samples) tried at each node
GRID_TOLERANCE = 1e-9  # a destination lies on a node if within GRID_TOLERANCE * step of it


@dataclass(frozen=True)
class StateDimension:
    """One ``ssd`` line: a uniformly sampled state variable of the figure.

    ``minimum``/``maximum`` are the first and last grid nodes, in spec units (degrees, deg/s,
    metres, m/s). ``samples`` >= 2 nodes, so ``step = (maximum - minimum) / (samples - 1)``.
    A ``wrap`` dimension is periodic with period ``samples * step`` (node ``samples`` would be
    node 0 again: ``-180 170 36 wrap`` covers the whole circle). ``token`` is the name's token.
    """

    name: str
    minimum: float
    maximum: float
    samples: int
    wrap: bool
    token: Token

    @property
    def step(self) -> float:
        """Distance between neighbouring nodes, spec units."""
        return (self.maximum - self.minimum) / (self.samples - 1)

    @property
    def period(self) -> float | None:
        """``samples * step`` for a wrap dimension (spec units), else None."""
        return self.samples * self.step if self.wrap else None

    def node(self, index: int) -> float:
        """The coordinate of node ``index`` (0 .. samples-1), spec units."""
        return self.minimum + index * self.step

    def nodes(self) -> tuple[float, ...]:
        """All node coordinates, spec units; the last is exactly ``maximum``."""
        return tuple(self.node(k) for k in range(self.samples - 1)) + (self.maximum,)


@dataclass(frozen=True)
class ControlDimension:
    """One ``torq`` line: a control (torque or force) sampled at ``samples`` values.

    The DP tries ``samples`` evenly spaced values from ``minimum`` to ``maximum`` (N·m for a
    torque, N for a force); one sample means the constant ``minimum`` (== ``maximum``).
    ``effort_weight`` is the paper's K >= 0, in 1/(N·m): the cost ``f = t + ∫ K·|T| dt`` (s).
    ``token`` is the name's token.
    """

    name: str
    minimum: float
    maximum: float
    samples: int
    effort_weight: float
    token: Token

    def values(self) -> tuple[float, ...]:
        """The sampled control values, from ``minimum`` to ``maximum`` inclusive."""
        if self.samples == 1:
            return (self.minimum,)
        step = (self.maximum - self.minimum) / (self.samples - 1)
        inner = tuple(self.minimum + k * step for k in range(self.samples - 1))
        return inner + (self.maximum,)


@dataclass(frozen=True)
class Destination:
    """One ``name=value`` of a ``dest`` line: the destination of one state dimension.

    ``value`` is the number as written (spec units); ``index`` is the grid node it lies on
    (after wrapping, for a wrap dimension). ``token`` is the whole ``name=value`` token;
    ``value_token`` its value part.
    """

    name: str
    value: float
    index: int
    token: Token

    @property
    def value_token(self) -> Token:
        return value_token(self.token, self.name)


@dataclass(frozen=True)
class Policy:
    """The ``policy`` line: how the table runs. ``kind`` is one of POLICIES; ``arrival`` the
    ``name=tolerance`` pairs (spec units, > 0, names from ``dest``) of ``lookahead``: where the
    vehicle's braking point lies within them of the destination, it brakes to rest and holds.
    ``aim`` (in (0, 1], from ``aim=``): the DP's segments end in the arrival box scaled by it
    about the destination. ``arrival_value`` (the bare word): the table also keeps the
    cost-to-go to the whole arrival box (a second DP where the aim is below 1). ``token`` is the
    kind's token."""

    kind: str
    arrival: tuple[tuple[str, float], ...]
    token: Token
    aim: float = 1.0
    arrival_value: bool = False


@dataclass(frozen=True)
class Polygon:
    """An ``obstacle`` or the ``domain`` line: a simple polygon, ``vertices`` (x, y) in metres in
    the frame of the figure's ``x``/``y`` state variables. ``name`` is the obstacle's name
    (``"domain"`` for the domain); ``token`` the name's token (the keyword's, for the domain)."""

    name: str
    vertices: tuple[tuple[float, float], ...]
    token: Token


@dataclass(frozen=True)
class ControllerSpec:
    """A parsed ``.ssc`` file.

    ``state`` is in file order; the controller's state order (its table's axes) is the figure's
    state order restricted to these dimensions: see ``ordered_state``. ``destination`` is the
    first ``dest`` line, in its order; dimensions it does not name are free.
    ``further_destinations`` holds the ``dest`` lines after the first, in file order (empty for
    the usual single destination): ``destinations`` lists them all. ``tolerance`` (s) stops
    the DP when no cost-to-go changes by more than it in one sweep; ``max_iterations`` caps
    the sweeps; ``dt`` (s) is the longest step of the DP's integrator. ``known_weight``: the
    share of an exit's interpolation weight on corners with a known cost-to-go below which the
    exit does not count (0: any share above 0, the paper's rule). ``spec_sha256`` is the hex
    SHA-256 of the file's bytes. ``obstacles`` and ``domain`` (None: no such line) restrict a
    figure with a body outline: states whose body overlaps an obstacle or whose reference point
    lies outside the domain are removed from the table. ``hold`` (the keyword's token, None
    without a ``hold`` line) asks for holding torques at the destination nodes. ``policy``
    (None: the paper's interpolation) says how the table runs.
    """

    path: str
    figure: str
    figure_token: Token
    state: tuple[StateDimension, ...]
    controls: tuple[ControlDimension, ...]
    destination: tuple[Destination, ...]
    tolerance: float
    max_iterations: int
    dt: float
    spec_sha256: str
    obstacles: tuple[Polygon, ...] = ()
    domain: Polygon | None = None
    hold: Token | None = None
    policy: Policy | None = None
    known_weight: float = 0.0
    further_destinations: tuple[tuple[Destination, ...], ...] = ()

    @property
    def destinations(self) -> tuple[tuple[Destination, ...], ...]:
        """Every ``dest`` line in file order, the first being ``destination``."""
        return (self.destination, *self.further_destinations)

    @property
    def name(self) -> str:
        """The controller's name: the spec file's stem (``A`` for ``A.ssc``)."""
        return Path(self.path).stem

    def dimension(self, name: str) -> StateDimension:
        """The ``ssd`` dimension called ``name`` (KeyError if there is none)."""
        for dimension in self.state:
            if dimension.name == name:
                return dimension
        raise KeyError(name)

    def destination_values(self) -> dict[str, float]:
        """The first ``dest`` line as {name: value}, spec units, as written."""
        return {entry.name: entry.value for entry in self.destination}

    def all_destination_values(self) -> list[dict[str, float]]:
        """Every ``dest`` line as {name: value}, spec units, as written, in file order."""
        return [{entry.name: entry.value for entry in line} for line in self.destinations]

    def error(self, token: Token, expected: str) -> SpecError:
        """A SpecError at ``token`` of this spec, found its text: for checks made after
        parsing (against the figure, say)."""
        return SpecError.at(self.path, token, expected)

    def ordered_state(self, figure_state: Sequence[str]) -> tuple[StateDimension, ...]:
        """The ``ssd`` dimensions in the figure's state order (``figure_state``: the figure's
        coordinate names, then its rate names). An ``ssd`` name that is not in
        ``figure_state`` raises SpecError at that name."""
        known = set(figure_state)
        choices = ", ".join(f"'{name}'" for name in figure_state)
        for dimension in self.state:
            if dimension.name not in known:
                raise self.error(
                    dimension.token,
                    f"a state variable of figure '{self.figure}' (one of {choices})",
                )
        rank = {name: position for position, name in enumerate(figure_state)}
        return tuple(sorted(self.state, key=lambda dimension: rank[dimension.name]))


def parse_controller_spec(path: str | Path) -> ControllerSpec:
    """Parse a ``.ssc`` file; any problem raises SpecError naming file, line and column."""
    text, digest = read_spec_text(path)
    return parse_controller_text(text, str(path), digest)


def parse_controller_text(
    text: str, path: str = "<text>", spec_sha256: str | None = None
) -> ControllerSpec:
    """Parse ``.ssc`` text; ``path`` names it in errors. ``spec_sha256`` defaults to the
    SHA-256 of the text's UTF-8 encoding."""
    if spec_sha256 is None:
        spec_sha256 = hashlib.sha256(text.encode("utf-8")).hexdigest()
    return _Parser(path).parse(tokenize(text, path), spec_sha256)


def _fmt(value: float) -> str:
    """A number for an error message: ``-500``, ``0.1``."""
    return f"{value:.12g}"


class _Parser:
    def __init__(self, path: str):
        self.path = path
        self.figure: Token | None = None
        self.state: list[StateDimension] = []
        self.controls: list[ControlDimension] = []
        self.dest_lines: list[Line] = []
        self.options: dict[str, float | int] = {}
        self.first_line: dict[str, int] = {}  # once-only keyword -> its line number
        self.names: dict[str, int] = {}  # ssd/torq name -> its line number
        self.obstacles: list[Polygon] = []
        self.domain: Polygon | None = None
        self.hold: Token | None = None
        self.policy_line: Line | None = None

    def error(self, token: Token, expected: str, found: str | None) -> SpecError:
        return SpecError(self.path, token.line, token.column, expected, found)

    def parse(self, lines: list[Line], spec_sha256: str) -> ControllerSpec:
        for line in lines:
            keyword = line.keyword.text
            if keyword not in KEYWORDS:
                raise unknown_keyword(line, KEYWORDS)
            if keyword in (
                "dyn",
                "tol",
                "maxiter",
                "dt",
                "known_weight",
                "domain",
                "hold",
                "policy",
            ):
                record_once(line, self.first_line)
            getattr(self, f"line_{keyword}")(line)
        for keyword, given in (
            ("dyn", self.figure),
            ("ssd", self.state),
            ("torq", self.controls),
            ("dest", self.dest_lines),
        ):
            if not given:
                raise missing_line(self.path, lines, keyword)
        assert self.figure is not None
        destinations = self.destinations()
        destination = destinations[0]
        return ControllerSpec(
            path=self.path,
            figure=self.figure.text,
            figure_token=self.figure,
            state=tuple(self.state),
            controls=tuple(self.controls),
            destination=destination,
            tolerance=float(self.options.get("tol", DEFAULT_TOLERANCE)),
            max_iterations=int(self.options.get("maxiter", DEFAULT_MAX_ITERATIONS)),
            dt=float(self.options.get("dt", DEFAULT_DT)),
            known_weight=float(self.options.get("known_weight", 0.0)),
            spec_sha256=spec_sha256,
            obstacles=tuple(self.obstacles),
            domain=self.domain,
            hold=self.hold,
            policy=None if self.policy_line is None else self.policy(self.policy_line, destination),
            further_destinations=destinations[1:],
        )

    def new_name(self, reader: LineReader, what: str) -> Token:
        """A name for an ssd or torq line, unused by any other ssd or torq line."""
        token = reader.peek()
        reader.name(what)
        assert token is not None
        if token.text in self.names:
            raise self.error(
                token,
                f"a name for {what} not used by another ssd or torq line "
                f"(line {self.names[token.text]})",
                token.text,
            )
        self.names[token.text] = token.line
        return token

    def number_token(self, reader: LineReader, what: str) -> tuple[float, Token]:
        token = reader.peek()
        value = reader.number(what)
        assert token is not None
        return value, token

    def finite_range(self, minimum: float, maximum: float, token: Token) -> None:
        if not math.isfinite(maximum - minimum):
            raise self.error(token, "a max with a finite max - min", token.text)

    def line_dyn(self, line: Line) -> None:
        reader = line.reader()
        token = reader.peek()
        reader.name("the figure")
        reader.end()
        self.figure = token

    def line_ssd(self, line: Line) -> None:
        reader = line.reader()
        name = self.new_name(reader, "the state dimension")
        minimum = reader.number("min")
        maximum, maximum_token = self.number_token(reader, "max")
        if not maximum > minimum:
            raise self.error(
                maximum_token, f"a number > min ({_fmt(minimum)}) for max", maximum_token.text
            )
        self.finite_range(minimum, maximum, maximum_token)
        samples_token = reader.peek()
        samples = reader.integer("samples", minimum=2)
        assert samples_token is not None
        self.grid_size(samples, samples_token, self.state, MAX_NODES, "state grid nodes")
        if not (maximum - minimum) / (samples - 1) > 0:
            raise self.error(
                samples_token,
                "fewer samples (the step (max - min) / (samples - 1) is 0)",
                samples_token.text,
            )
        wrap = False
        token = reader.peek()
        if token is not None:
            if token.text != "wrap":
                raise self.error(token, "'wrap' or end of line", token.text)
            wrap = True
            reader.word("'wrap'")
            reader.end()
        self.state.append(StateDimension(name.text, minimum, maximum, samples, wrap, name))

    def line_wrap(self, line: Line) -> None:
        """``wrap NAME``: the state dimension an earlier ssd line declared is periodic, as the
        word ``wrap`` at the end of that line says (the paper's Figure 12 writes it so)."""
        reader = line.reader()
        token = reader.peek()
        reader.name("the periodic state dimension")
        reader.end()
        assert token is not None
        for k, dimension in enumerate(self.state):
            if dimension.name == token.text:
                self.state[k] = dataclasses.replace(dimension, wrap=True)
                return
        declared = ", ".join(f"'{d.name}'" for d in self.state) or "none yet"
        expected = f"the name of a state dimension an earlier ssd line declares ({declared})"
        raise self.error(token, expected, token.text)

    def line_torq(self, line: Line) -> None:
        reader = line.reader()
        name = self.new_name(reader, "the control")
        minimum = reader.number("min")
        maximum, maximum_token = self.number_token(reader, "max")
        if not maximum >= minimum:
            raise self.error(
                maximum_token, f"a number >= min ({_fmt(minimum)}) for max", maximum_token.text
            )
        self.finite_range(minimum, maximum, maximum_token)
        samples_token = reader.peek()
        samples = reader.integer("samples", minimum=1)
        assert samples_token is not None
        self.grid_size(samples, samples_token, self.controls, MAX_CONTROLS, "control samples")
        if samples == 1 and maximum != minimum:
            raise self.error(
                samples_token,
                f"samples >= 2 for a range from {_fmt(minimum)} to {_fmt(maximum)} "
                "(1 sample needs max equal to min)",
                samples_token.text,
            )
        weight, weight_token = self.number_token(reader, "K")
        if weight < 0:
            raise self.error(weight_token, "a number >= 0 for K", weight_token.text)
        reader.end()
        self.controls.append(ControlDimension(name.text, minimum, maximum, samples, weight, name))

    def grid_size(self, samples: int, token: Token, before: list, limit: int, what: str) -> None:
        """Fail at ``token`` if ``samples`` times the samples of the lines ``before`` (ssd or
        torq lines read so far) exceeds ``limit``."""
        total = math.prod(dimension.samples for dimension in before) * samples
        if total > limit:
            made = f"{total:.3g}" if total < 1e300 else "more than 1e+300"  # ints past floats
            raise self.error(
                token,
                f"fewer samples (at most {limit:,} {what} in all; these lines make {made})",
                token.text,
            )

    def line_dest(self, line: Line) -> None:
        if len(line.tokens) == 1:
            raise SpecError(
                self.path, line.number, line.end_column, "a 'name=value' destination", None
            )
        self.dest_lines.append(line)  # checked against the ssd lines once all are read

    def destinations(self) -> tuple[tuple[Destination, ...], ...]:
        """Every ``dest`` line, in file order; a line that names the same dimensions at the
        same grid nodes as an earlier one (``angle=-180`` and ``angle=180`` on a wrap axis of
        period 360 are the same node) is an error at its keyword."""
        parsed: list[tuple[Destination, ...]] = []
        seen: dict[frozenset[tuple[str, int]], int] = {}
        for line in self.dest_lines:
            entries = self.destination(line)
            nodes = frozenset((entry.name, entry.index) for entry in entries)
            if nodes in seen:
                raise self.error(
                    line.keyword,
                    f"a destination different from line {seen[nodes]}'s",
                    line.keyword.text,
                )
            seen[nodes] = line.number
            parsed.append(entries)
        return tuple(parsed)

    def destination(self, line: Line) -> tuple[Destination, ...]:
        dimensions = {dimension.name: dimension for dimension in self.state}
        entries: list[Destination] = []
        for name, part, token in self.named_pairs(
            line.tokens[1:], tuple(dimensions), "a 'name=value' destination", "an ssd name"
        ):
            value = parse_number(part, self.path, f"dest {name}")
            index = self.node_index(dimensions[name], value, part)
            entries.append(Destination(name, value, index, token))
        return tuple(entries)

    def named_pairs(
        self, tokens: Sequence[Token], names: tuple[str, ...], pair: str, kind: str
    ) -> list[tuple[str, Token, Token]]:
        """(name, value part, whole token) of ``name=value`` tokens, each name one of ``names``
        and at most once; ``pair`` and ``kind`` word the errors ("a 'name=value' destination",
        "an ssd name")."""
        choices = ", ".join(f"'{name}'" for name in names)
        pairs: list[tuple[str, Token, Token]] = []
        for token in tokens:
            name, sep, _ = token.text.partition("=")
            if not sep:
                raise self.error(token, pair, token.text)
            if name not in names:
                raise self.error(token, f"{kind} (one of {choices}) before '='", name)
            if any(name == seen for seen, _, _ in pairs):
                raise self.error(token, f"'{name}=' only once", token.text)
            pairs.append((name, value_token(token, name), token))
        return pairs

    def node_index(self, dimension: StateDimension, value: float, token: Token) -> int:
        """The node ``value`` lies on, within GRID_TOLERANCE * step (wrapped first if periodic)."""
        offset = value - dimension.minimum
        if dimension.wrap and math.isfinite(offset):
            offset %= dimension.samples * dimension.step
        position = offset / dimension.step  # in steps from the first node
        last = dimension.samples - 1
        if not dimension.wrap and not -GRID_TOLERANCE <= position <= last + GRID_TOLERANCE:
            raise self.error(
                token,
                f"a value from {_fmt(dimension.minimum)} to {_fmt(dimension.maximum)} "
                f"(ssd {dimension.name}) for dest {dimension.name}",
                token.text,
            )
        if not math.isfinite(position) or abs(position - round(position)) > GRID_TOLERANCE:
            raise self.error(
                token,
                f"a grid node of ssd {dimension.name} ({_fmt(dimension.minimum)} + k * "
                f"{_fmt(dimension.step)}) for dest {dimension.name}",
                token.text,
            )
        return round(position) % dimension.samples

    def line_obstacle(self, line: Line) -> None:
        reader = line.reader()
        name = reader.peek()
        reader.name("the obstacle")
        assert name is not None
        for other in self.obstacles:
            if other.name == name.text:
                raise self.error(
                    name,
                    f"a name not used by another obstacle (line {other.token.line})",
                    name.text,
                )
        self.obstacles.append(Polygon(name.text, self.polygon(line, reader), name))

    def line_domain(self, line: Line) -> None:
        reader = line.reader()
        self.domain = Polygon("domain", self.polygon(line, reader), line.keyword)

    def polygon(self, line: Line, reader: LineReader) -> tuple[tuple[float, float], ...]:
        """The rest of the line as the vertices 'x,y' (metres) of a simple polygon."""
        vertices: list[tuple[float, float]] = []
        tokens: list[Token] = []
        for token in reader.remaining():
            x_text, comma, y_text = token.text.partition(",")
            if not comma or "," in y_text:
                raise self.error(token, "a vertex 'x,y' in metres", token.text)
            x = parse_number(Token(x_text, token.line, token.column), self.path, "vertex x")
            y_token = Token(y_text, token.line, token.column + len(x_text) + 1)
            y = parse_number(y_token, self.path, "vertex y")
            if not (math.isfinite(x) and math.isfinite(y)) or max(abs(x), abs(y)) > 1e6:
                raise self.error(token, "a vertex within 1e6 m of the origin", token.text)
            vertices.append((x, y))
            tokens.append(token)
        if len(vertices) < 3:
            raise SpecError(
                self.path,
                line.number,
                line.end_column,
                f"a vertex 'x,y' (a polygon has at least 3; {len(vertices)} given)",
                None,
            )
        for k in range(1, len(vertices)):
            if vertices[k] == vertices[k - 1]:
                raise self.error(tokens[k], "a vertex other than the one before it", tokens[k].text)
        if vertices[-1] == vertices[0]:
            expected = "a vertex other than the first (a polygon closes itself)"
            raise self.error(tokens[-1], expected, tokens[-1].text)
        crossing = first_self_crossing(vertices)
        if crossing is not None:
            token = tokens[crossing]
            expected = "a simple polygon (its edges cross or touch here)"
            raise self.error(token, expected, token.text)
        if abs(polygon_area(vertices)) < 1e-12:
            raise self.error(tokens[0], "vertices enclosing a non-zero area", tokens[0].text)
        return tuple(vertices)

    def line_tol(self, line: Line) -> None:
        self.options["tol"] = self.positive(line, "tol (s)")

    def line_dt(self, line: Line) -> None:
        value = self.positive(line, "dt (s)")
        if value < MIN_DT:
            token = line.tokens[1]
            raise self.error(token, f"a dt of at least {MIN_DT:g} s", token.text)
        self.options["dt"] = value

    def line_known_weight(self, line: Line) -> None:
        value = self.positive(line, "known_weight (a share of the weight)")
        if value > 1.0:
            token = line.tokens[1]
            raise self.error(token, "a known_weight in (0, 1]", token.text)
        self.options["known_weight"] = value

    def line_hold(self, line: Line) -> None:
        line.reader().end()
        self.hold = line.keyword

    def line_policy(self, line: Line) -> None:
        if len(line.tokens) == 1:
            choices = ", ".join(f"'{kind}'" for kind in POLICIES)
            raise SpecError(self.path, line.number, line.end_column, f"one of {choices}", None)
        self.policy_line = line  # its tolerances are checked against the dest line

    def policy(self, line: Line, destination: tuple[Destination, ...]) -> Policy:
        kind = line.tokens[1]
        if kind.text not in POLICIES:
            choices = ", ".join(f"'{k}'" for k in POLICIES)
            raise self.error(kind, f"one of {choices}", kind.text)
        if kind.text == "lookahead" and len(self.dest_lines) > 1:
            numbers = ", ".join(str(dest.number) for dest in self.dest_lines)
            raise self.error(
                kind,
                f"'interpolate' with several dest lines (lines {numbers}): lookahead brakes "
                "to rest at one destination",
                kind.text,
            )
        if kind.text == "interpolate" and len(line.tokens) > 2:
            raise self.error(
                line.tokens[2], "the end of the line after 'interpolate'", line.tokens[2].text
            )
        arrival: list[tuple[str, float]] = []
        flags = [token for token in line.tokens[2:] if token.text == ARRIVAL_VALUE]
        if len(flags) > 1:
            raise self.error(flags[1], f"'{ARRIVAL_VALUE}' only once", flags[1].text)
        aim = 1.0
        pairs = [t for t in line.tokens[2:] if t.text[:4] != "aim=" and t.text != ARRIVAL_VALUE]
        for number, token in enumerate(t for t in line.tokens[2:] if t.text[:4] == "aim="):
            if number:
                raise self.error(token, "'aim=' only once", token.text)
            part = value_token(token, "aim")
            aim = parse_number(part, self.path, "aim")
            if not 0 < aim <= 1:
                raise self.error(part, "an aim above 0 and at most 1", part.text)
        for name, part, _ in self.named_pairs(
            pairs,
            tuple(entry.name for entry in destination),
            "a 'name=tolerance' arrival tolerance",
            "a dest name",
        ):
            tolerance = parse_number(part, self.path, f"arrival tolerance of {name}")
            if not tolerance > 0:
                raise self.error(part, f"a number > 0 for the tolerance of {name}", part.text)
            arrival.append((name, tolerance))
        if kind.text == "lookahead" and not arrival:
            raise SpecError(
                self.path,
                line.number,
                line.end_column,
                "a 'name=tolerance' arrival tolerance of a dest dimension after 'lookahead'",
                None,
            )
        return Policy(kind.text, tuple(arrival), kind, aim, bool(flags))

    def line_maxiter(self, line: Line) -> None:
        reader = line.reader()
        self.options["maxiter"] = reader.integer("maxiter", minimum=1)
        reader.end()

    def positive(self, line: Line, what: str) -> float:
        reader = line.reader()
        value, token = self.number_token(reader, what)
        if not value > 0:
            raise self.error(token, f"a number > 0 for {what}", token.text)
        reader.end()
        return value


def polygon_area(vertices: Sequence[tuple[float, float]]) -> float:
    """Signed area (m², positive counter-clockwise) of a polygon (shoelace formula)."""
    total = 0.0
    for (x0, y0), (x1, y1) in zip(vertices, [*vertices[1:], vertices[0]], strict=True):
        total += x0 * y1 - x1 * y0
    return total / 2.0


def _segments_meet(
    a: tuple[float, float], b: tuple[float, float], c: tuple[float, float], d: tuple[float, float]
) -> bool:
    """True when segments ab and cd (m) share a point: they cross, an end of one lies on the
    other, or they overlap along a line, as ``kernels.geometry.segments_cross`` decides (which
    the parser may not import). The order of each segment's ends does not matter: a side of 0
    had counted as negative, so a vertex lying on another edge was refused in one direction
    and not in the other."""

    def side(p, q, r) -> float:
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    def opposite(u: float, v: float) -> bool:  # opposite signs, or either 0
        return (u <= 0.0 <= v) or (v <= 0.0 <= u)

    d1, d2, d3, d4 = side(c, d, a), side(c, d, b), side(a, b, c), side(a, b, d)
    if d1 == 0.0 and d2 == 0.0:  # on one line: do their extents overlap?
        return all(
            max(min(a[k], b[k]), min(c[k], d[k])) <= min(max(a[k], b[k]), max(c[k], d[k]))
            for k in (0, 1)
        )
    return opposite(d1, d2) and opposite(d3, d4)


def first_self_crossing(vertices: Sequence[tuple[float, float]]) -> int | None:
    """The index of the vertex that starts the first edge crossing or touching an earlier
    non-adjacent edge, or None for a simple polygon (whichever way round its vertices go)."""
    n = len(vertices)
    edges = [(vertices[i], vertices[(i + 1) % n]) for i in range(n)]
    for j in range(n):
        for i in range(j - 1):
            if i == 0 and j == n - 1:
                continue  # the first and last edges share vertex 0
            if _segments_meet(*edges[i], *edges[j]):
                return j
    return None


def render_controller_spec(spec: ControllerSpec) -> str:
    """The ``.ssc`` text of ``spec`` (parsing it gives back the same values). Optional settings
    are written only when they differ from the defaults."""

    def number(value: float) -> str:
        return repr(float(value))

    lines = [f"dyn {spec.figure}"]
    for dimension in spec.state:
        wrap = " wrap" if dimension.wrap else ""
        lines.append(
            f"ssd {dimension.name} {number(dimension.minimum)} {number(dimension.maximum)} "
            f"{dimension.samples}{wrap}"
        )
    for control in spec.controls:
        lines.append(
            f"torq {control.name} {number(control.minimum)} {number(control.maximum)} "
            f"{control.samples} {number(control.effort_weight)}"
        )
    for destination in spec.destinations:
        lines.append(
            "dest " + " ".join(f"{entry.name}={number(entry.value)}" for entry in destination)
        )
    if spec.tolerance != DEFAULT_TOLERANCE:
        lines.append(f"tol {number(spec.tolerance)}")
    if spec.max_iterations != DEFAULT_MAX_ITERATIONS:
        lines.append(f"maxiter {spec.max_iterations}")
    if spec.dt != DEFAULT_DT:
        lines.append(f"dt {number(spec.dt)}")
    if spec.known_weight:
        lines.append(f"known_weight {number(spec.known_weight)}")

    def vertices(polygon: Polygon) -> str:
        return " ".join(f"{number(x)},{number(y)}" for x, y in polygon.vertices)

    for obstacle in spec.obstacles:
        lines.append(f"obstacle {obstacle.name} {vertices(obstacle)}")
    if spec.domain is not None:
        lines.append(f"domain {vertices(spec.domain)}")
    if spec.hold is not None:
        lines.append("hold")
    if spec.policy is not None:
        arrival = "".join(f" {name}={number(value)}" for name, value in spec.policy.arrival)
        aim = f" aim={number(spec.policy.aim)}" if spec.policy.aim != 1.0 else ""
        flag = f" {ARRIVAL_VALUE}" if spec.policy.arrival_value else ""
        lines.append(f"policy {spec.policy.kind}{arrival}{aim}{flag}")
    return "\n".join(lines) + "\n"
