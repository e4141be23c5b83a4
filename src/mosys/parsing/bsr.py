"""The BSR search spec (``.bsr``) and its parser: what a search for banked stimulus-response
controllers runs on (Auslander et al. 1995): the figure, the kind and size of controller, the
simulation, the genetic search's sizes, the random seeds, the start pose and its perturbation, and
the fitness. The grammar is the README's "The search spec (`.bsr`)"; ``specs/bsr/`` holds examples.

The parser does not know the figure: start names and fall rods are checked when the spec is bound
to it, at the tokens kept in ``BsrSpec.tokens``.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path

from mosys.parsing.tokens import (
    MAX_INT64,
    MAX_WHOLE,
    NAME,
    Line,
    LineReader,
    SpecError,
    Token,
    figure_line,
    format_number,
    missing_line,
    parse_endpoint,
    parse_int,
    parse_number,
    read_spec_text,
    record_once,
    tokenize,
    unknown_keyword,
    value_token,
)

_NO_TOKEN = Token("", 0, 0)

CONTROLLER_KINDS = ("sense", "time")
# fitness terms: the primary term and Table 3's secondary terms, plus the fall penalty
FITNESS_TERMS = ("distance", "max_height", "contact_distance", "rotations", "fall")
# the fitness terms of a 3-D figure (§4), in the order of the 3-D kernel's terms_out columns
FITNESS_TERMS_3D = (
    "distance",
    "sideways",
    "heading_change",
    "max_height",
    "fall",
    "heading_deviation",
    "feet_distance",
    "foot_steps",
    "min_height",
    "heading_sine",
    "final_spin",
    "net_rotation",
)
DEFAULT_FALL_BELOW = 0.5  # 3-D: fallen below this fraction of the standing com height
DEFAULT_SENSE_FILTER = 0.05  # s: 3-D sense-based: the physical senses' low-pass time constant


@dataclass(frozen=True)
class Perturbation:
    """Half-widths of the uniform random perturbation of the start state drawn at every
    evaluation (the enhanced controllers of the 1995 paper's section 3): ``angle`` deg on the root
    angle, ``joints`` deg on each joint angle, ``speed`` m/s on each component of the centre of
    mass's velocity, ``spin`` deg/s on the angular velocity. All 0: no perturbation."""

    angle: float = 0.0
    joints: float = 0.0
    speed: float = 0.0
    spin: float = 0.0

    @property
    def any(self) -> bool:
        return any(value != 0.0 for value in (self.angle, self.joints, self.speed, self.spin))


@dataclass(frozen=True)
class Endpoint:
    """A rod endpoint named in the spec as ``ROD.END`` (END: proximal or distal)."""

    rod: str
    end: str
    token: Token = field(default=_NO_TOKEN, compare=False, repr=False)


@dataclass(frozen=True)
class BsrSpec:
    """One ``.bsr`` file.

    ``kind``: ``sense`` or ``time``; ``rules``: R; ``period``: t_per in s (time-based only; None
    means the duration T, i.e. aperiodic); ``duration``: T, s; ``dt``: Δt, s; ``controllers``: C;
    ``generations``: G; ``reseed``: the reseed period (the paper's R of Figure 3);
    ``reinitialize``: the probability that a mutation re-initialises one rule rather than creeping
    it; ``seeds``: the random seeds, one search each; ``start``: the nominal start pose, figure
    coordinate name -> value as written (angles in degrees, ``x`` in m); ``perturbation``: random
    start perturbation; ``weights``: fitness term -> weight; ``fall``: the endpoints whose ground
    contact the ``fall`` term measures; ``tau_min``: the smallest time constant, s (None: Table 2's
    2 Δt). 3-D figures only: ``fall_below`` the fraction of the standing centre-of-mass height
    below which the figure counts as fallen; ``sense_filter`` s, the low-pass time constant of a
    sense-based controller's physical senses; ``chain`` the search whose final state this one
    starts from (``""``: none; then the spec has no ``start`` line). ``tokens`` keeps the token
    of each setting (keyed like ``figure``, ``start.NAME``, ``fitness.TERM``) so that binding to
    the figure can point at the offending word; ``simulate_token`` the ``simulate`` line's
    keyword, where a run whose state blows up points (line 0 if the spec was not parsed)."""

    path: str
    figure: str
    kind: str
    rules: int
    period: float | None
    duration: float
    dt: float
    controllers: int
    generations: int
    reseed: int
    reinitialize: float
    seeds: tuple[int, ...]
    start: dict[str, float]
    perturbation: Perturbation
    weights: dict[str, float]
    fall: tuple[Endpoint, ...]
    tau_min: float | None = None
    fall_below: float = DEFAULT_FALL_BELOW
    sense_filter: float = DEFAULT_SENSE_FILTER
    chain: str = ""
    spec_sha256: str = field(default="", compare=False)
    tokens: dict[str, Token] = field(default_factory=dict, compare=False, repr=False)
    simulate_token: Token = field(default=_NO_TOKEN, compare=False, repr=False)

    @property
    def name(self) -> str:
        """The search's name: the spec file's stem."""
        return Path(self.path).stem

    @property
    def steps(self) -> int:
        """Simulator steps per evaluation: round(T / Δt)."""
        return int(round(self.duration / self.dt))


KEYWORDS = (
    *("figure", "controller", "simulate", "search", "seeds"),
    *("start", "perturb", "fitness", "fall", "chain"),
)
REQUIRED = ("figure", "controller", "simulate", "search", "seeds", "fitness")
DEFAULT_REINITIALIZE = 0.5
# rounding allowed in duration / dt being a whole number of steps, relative
STEPS_TOLERANCE = 1e-9
# simulator steps per evaluation (T / dt), a count the kernels index too (the paper's take 400);
# how many one run may really take is the user's limit, checked before a search (mosys.limits)
MAX_STEPS = MAX_WHOLE

# key -> (minimum, what) for whole numbers; (check, what) for numbers, check one of
# '>0', '>=0', '0..1', None
_CONTROLLER_KEYS = {
    "rules": (1, "rules="),
    "period": (">0", "period= (s)"),
    "filter": (">=0", "filter= (s)"),
}
_SIMULATE_KEYS = {
    "duration": (">0", "duration= (s)"),
    "dt": (">0", "dt= (s)"),
    "tau_min": (">0", "tau_min= (s)"),
}
_SEARCH_KEYS = {
    "controllers": (2, "controllers="),
    "generations": (1, "generations="),
    "reseed": (1, "reseed="),
    "reinitialize": ("0..1", "reinitialize="),
}
_PERTURB_KEYS = {
    "angle": (">=0", "angle= (deg)"),
    "joints": (">=0", "joints= (deg)"),
    "speed": (">=0", "speed= (m/s)"),
    "spin": (">=0", "spin= (deg/s)"),
}
MAX_WEIGHT = 1e6  # |a fitness weight|: its terms are metres, degrees, counts and fractions,
# so a fitness stays far from overflowing (a weight of 1.7e308 gave fitness inf, or finite
# learning curves whose span overflowed every plot's axis)
_FITNESS_KEYS = {
    term: ("weight", f"{term}= (weight)")
    for term in dict.fromkeys(FITNESS_TERMS + FITNESS_TERMS_3D)
}

# what an unknown fitness term should have been: the figure is not read yet, so both lists
_FITNESS_CHOICES = (
    f"TERM=WEIGHT, TERM a 2-D figure's fitness term ({', '.join(FITNESS_TERMS)}) or a 3-D "
    f"figure's ({', '.join(FITNESS_TERMS_3D)})"
)


def _expected(check: int | str | None, what: str) -> str:
    """What a value of ``check`` (a minimum whole number or a number check) is, for errors."""
    if isinstance(check, int):
        return f"a whole number >= {check} for {what}"
    return {
        ">0": f"a number > 0 for {what}",
        ">=0": f"a number >= 0 for {what}",
        "0..1": f"a number from 0 to 1 for {what}",
        "weight": f"a number from {-MAX_WEIGHT:g} to {MAX_WEIGHT:g} for {what}",
        None: f"a number for {what}",
    }[check]


def parse_bsr_spec(path: str | Path) -> BsrSpec:
    """Parse a ``.bsr`` file; any problem (a missing or unreadable file too, at 1:1) raises
    SpecError naming file, line and column. ``spec_sha256`` is the SHA-256 of the file's bytes."""
    text, digest = read_spec_text(path)
    return parse_bsr_text(text, str(path), digest)


def parse_bsr_text(text: str, path: str = "<text>", spec_sha256: str | None = None) -> BsrSpec:
    """Parse ``.bsr`` text; ``path`` names it in errors and becomes ``BsrSpec.path``.
    ``spec_sha256`` defaults to the SHA-256 of the text's UTF-8 encoding."""
    if spec_sha256 is None:
        spec_sha256 = hashlib.sha256(text.encode("utf-8")).hexdigest()
    return _Parser(str(path)).parse(tokenize(text, str(path)), spec_sha256)


class _Parser:
    def __init__(self, path: str):
        self.path = path
        self.first_line: dict[str, int] = {}  # keyword -> the line number of its line
        self.tokens: dict[str, Token] = {}
        self.figure = ""
        self.kind = ""
        self.rules = 0
        self.period: float | None = None
        self.duration = 0.0
        self.dt = 0.0
        self.tau_min: float | None = None
        self.simulate_token = _NO_TOKEN
        self.search: dict[str, int | float] = {}
        self.seeds: tuple[int, ...] = ()
        self.start: dict[str, float] = {}
        self.perturbation = Perturbation()
        self.weights: dict[str, float] = {}
        self.fall: tuple[Endpoint, ...] = ()
        self.fall_below = DEFAULT_FALL_BELOW
        self.sense_filter = DEFAULT_SENSE_FILTER
        self.chain = ""
        self.fall_weight: Token | None = None  # the fitness line's 'fall=' token

    def error(self, token: Token, expected: str) -> SpecError:
        return SpecError.at(self.path, token, expected)

    def parse(self, lines: list[Line], spec_sha256: str) -> BsrSpec:
        for line in lines:
            keyword = line.keyword
            if keyword.text not in KEYWORDS:
                raise unknown_keyword(line, KEYWORDS)
            record_once(line, self.first_line)
            getattr(self, f"line_{keyword.text}")(line)
        for keyword in REQUIRED:
            if keyword not in self.first_line:
                raise missing_line(self.path, lines, keyword)
        if self.chain and "start" in self.first_line:  # at its keyword ('found end of line')
            start = next(line.keyword for line in lines if line.keyword.text == "start")
            raise self.error(
                start,
                f"no 'start' line in a search that continues '{self.chain}' (it starts where "
                "that search's best motion ends)",
            )
        if self.fall_weight is not None and "fall" not in self.first_line:
            raise self.error(
                self.fall_weight,
                "a 'fall' line naming the endpoints whose ground contact the fall term "
                "measures (e.g. 'fall upper.distal')",
            )
        return BsrSpec(
            path=self.path,
            figure=self.figure,
            kind=self.kind,
            rules=self.rules,
            period=self.period,
            duration=self.duration,
            dt=self.dt,
            controllers=int(self.search["controllers"]),
            generations=int(self.search["generations"]),
            reseed=int(self.search["reseed"]),
            reinitialize=float(self.search.get("reinitialize", DEFAULT_REINITIALIZE)),
            seeds=self.seeds,
            start=self.start,
            perturbation=self.perturbation,
            weights=self.weights,
            fall=self.fall,
            tau_min=self.tau_min,
            fall_below=self.fall_below,
            sense_filter=self.sense_filter,
            chain=self.chain,
            spec_sha256=spec_sha256,
            tokens=self.tokens,
            simulate_token=self.simulate_token,
        )

    # --- values ---------------------------------------------------------------------------

    def settings(
        self,
        line: Line,
        reader: LineReader,
        keys: dict[str, tuple],
        required: tuple[str, ...],
        unknown: str | None = None,
    ) -> dict[str, Token]:
        """The ``key=value`` tokens of the rest of the line (``keys`` as ``_SEARCH_KEYS``),
        key -> the whole token. Unknown or repeated keys, an empty value and a missing
        ``required`` key are errors; ``unknown`` says what an unknown key should have been."""
        allowed = {key: _expected(check, what) for key, (check, what) in keys.items()}
        found = {key: token for key, (token, _) in reader.key_values(allowed, unknown).items()}
        for key in required:
            if key not in found:
                raise SpecError(
                    self.path, line.number, line.end_column, f"'{key}=' ({allowed[key]})", None
                )
        return found

    def value(self, token: Token, key: str, check: int | str | None, what: str) -> int | float:
        """The value of a ``key=value`` token: a whole number (``check`` an int: the minimum)
        or a number passing ``check``; errors point at the value."""
        part = value_token(token, key)
        if isinstance(check, int):
            whole = parse_int(part, self.path, what, check)
            if whole > MAX_WHOLE:
                raise self.error(part, f"a whole number from {check} to {MAX_WHOLE} for {what}")
            return whole
        value = parse_number(part, self.path, what)
        bad = {
            ">0": value <= 0,
            ">=0": value < 0,
            "0..1": not 0 <= value <= 1,
            "weight": not abs(value) <= MAX_WEIGHT,
            None: False,
        }[check]
        if bad:
            raise self.error(part, _expected(check, what))
        return value

    def values(self, found: dict[str, Token], keys: dict[str, tuple]) -> dict[str, int | float]:
        """Each found key's value, checked in the order of ``keys``."""
        return {key: self.value(found[key], key, *keys[key]) for key in keys if key in found}

    def at_least_one(self, line: Line, keys: dict[str, tuple], expected: str | None = None) -> None:
        """Fail on a line with nothing after its keyword, expecting one of ``keys`` (or what
        ``expected`` says)."""
        if len(line.tokens) == 1:
            if expected is None:
                expected = "one of " + ", ".join(f"'{key}='" for key in keys)
            raise SpecError(self.path, line.number, line.end_column, expected, None)

    # --- lines ----------------------------------------------------------------------------

    def line_figure(self, line: Line) -> None:
        token = figure_line(line)
        self.figure = token.text
        self.tokens["figure"] = token

    def line_controller(self, line: Line) -> None:
        reader = line.reader()
        expected = "a controller kind 'sense' or 'time'"
        kind = reader.word(expected)
        if kind.text not in CONTROLLER_KINDS:
            raise self.error(kind, expected)
        found = self.settings(line, reader, _CONTROLLER_KEYS, ("rules",))
        if kind.text == "sense" and "period" in found:
            raise self.error(
                found["period"], "end of line (period= is for a 'time' controller only)"
            )
        if kind.text == "time" and "filter" in found:
            raise self.error(
                found["filter"], "end of line (filter= is for a 'sense' controller only)"
            )
        values = self.values(found, _CONTROLLER_KEYS)
        self.kind = kind.text
        if "filter" in values:
            self.sense_filter = float(values["filter"])
            self.tokens["filter"] = found["filter"]
        self.rules = int(values["rules"])
        self.period = float(values["period"]) if "period" in values else None

    def line_simulate(self, line: Line) -> None:
        found = self.settings(line, line.reader(), _SIMULATE_KEYS, ("duration", "dt"))
        values = self.values(found, _SIMULATE_KEYS)
        duration, dt = float(values["duration"]), float(values["dt"])
        part = value_token(found["dt"], "dt")
        steps = duration / dt
        if not math.isfinite(steps) or abs(steps - round(steps)) > STEPS_TOLERANCE * steps:
            shown = f"{steps:.6g}" if math.isfinite(steps) else "not finite"
            raise self.error(
                part,
                f"a dt= (s) that divides duration={format_number(duration)} into whole steps "
                f"({format_number(duration)} / {part.text} = {shown})",
            )
        if steps > MAX_STEPS:
            raise self.error(
                part,
                f"a dt= (s) of at least duration / {MAX_STEPS} = "
                f"{format_number(duration / MAX_STEPS)} (at most {MAX_STEPS} steps per run)",
            )
        if not 2 * dt < duration / 4:
            raise self.error(
                part,
                f"a number < {format_number(duration / 8)} for dt= (s), so that Table 2's "
                "time-constant range [2 dt, T/4] is not empty",
            )
        self.duration, self.dt = duration, dt
        self.simulate_token = line.keyword
        if "tau_min" in values:
            tau_min = float(values["tau_min"])
            if not 2 * dt <= tau_min < duration / 4:
                raise self.error(
                    value_token(found["tau_min"], "tau_min"),
                    f"a number from 2 dt ({format_number(2 * dt)}) to below T/4 "
                    f"({format_number(duration / 4)}) for tau_min= (s)",
                )
            self.tau_min = tau_min

    def line_search(self, line: Line) -> None:
        required = ("controllers", "generations", "reseed")
        found = self.settings(line, line.reader(), _SEARCH_KEYS, required)
        self.search = self.values(found, _SEARCH_KEYS)

    def line_seeds(self, line: Line) -> None:
        self.tokens["seeds"] = line.keyword
        reader = line.reader()
        what = "a seed"
        seeds: dict[int, Token] = {}
        while True:
            token = reader.word(f"a whole number >= 0 for {what}")
            seed = parse_int(token, self.path, what, 0, MAX_INT64)  # stored as int64
            if seed in seeds:
                raise self.error(
                    token, f"distinct seeds ({seed} is already at column {seeds[seed].column})"
                )
            seeds[seed] = token
            if reader.at_end():
                break
        self.seeds = tuple(seeds)

    def line_start(self, line: Line) -> None:
        expected = "a start coordinate 'name=value' (m for x and y, degrees for angles)"
        if len(line.tokens) == 1:
            raise SpecError(self.path, line.number, line.end_column, expected, None)
        for token in line.tokens[1:]:
            name, sep, _ = token.text.partition("=")
            if not sep:
                raise self.error(token, expected)
            if NAME.fullmatch(name) is None:
                raise SpecError(
                    self.path, token.line, token.column, "a coordinate name before '='", name
                )
            if name in self.start:
                raise self.error(token, f"'{name}=' only once")
            self.start[name] = float(self.value(token, name, None, f"start {name}="))
            self.tokens[f"start.{name}"] = token

    def line_perturb(self, line: Line) -> None:
        self.at_least_one(line, _PERTURB_KEYS)
        found = self.settings(line, line.reader(), _PERTURB_KEYS, ())
        values = self.values(found, _PERTURB_KEYS)
        self.tokens["perturb"] = line.keyword
        self.perturbation = Perturbation(**{key: float(value) for key, value in values.items()})

    def line_fitness(self, line: Line) -> None:
        self.at_least_one(line, _FITNESS_KEYS, _FITNESS_CHOICES)
        found = self.settings(line, line.reader(), _FITNESS_KEYS, (), _FITNESS_CHOICES)
        for term, token in found.items():  # file order
            self.weights[term] = float(self.value(token, term, *_FITNESS_KEYS[term]))
            self.tokens[f"fitness.{term}"] = token
        self.fall_weight = found.get("fall")

    def line_chain(self, line: Line) -> None:
        reader = line.reader()
        token = reader.word("the name of the search this one continues (its .bsr stem)")
        if NAME.fullmatch(token.text) is None:
            raise self.error(token, "a search name (letters, digits, '_')")
        reader.end()
        self.chain = token.text
        self.tokens["chain"] = token

    def line_fall(self, line: Line) -> None:
        expected = "an endpoint 'rod.proximal' or 'rod.distal' (or below=FRACTION, 3-D)"
        if len(line.tokens) == 1:
            raise SpecError(self.path, line.number, line.end_column, expected, None)
        endpoints: list[Endpoint] = []
        for token in line.tokens[1:]:
            if token.text.startswith("below="):
                if "fall.below" in self.tokens:
                    raise self.error(token, "'below=' only once")
                self.fall_below = float(
                    self.value(token, "below", "0..1", "below= (a fraction of the standing height)")
                )
                self.tokens["fall.below"] = token
                continue
            rod, end = parse_endpoint(token, self.path, expected)
            endpoint = Endpoint(rod, end, token)
            if endpoint in endpoints:
                first = endpoints[endpoints.index(endpoint)].token
                raise self.error(
                    token, f"each endpoint once ('{first.text}' is at column {first.column})"
                )
            self.tokens[f"fall.{len(endpoints)}"] = token
            endpoints.append(endpoint)
        self.fall = tuple(endpoints)


def render_bsr_spec(spec: BsrSpec) -> str:
    """The ``.bsr`` text of ``spec``: parsing it gives back an equal BsrSpec (numbers in their
    shortest form). Optional lines and ``reinitialize=`` are written only when they say
    something."""
    number = format_number
    controller = f"controller {spec.kind} rules={spec.rules}"
    if spec.period is not None:
        controller += f" period={number(spec.period)}"
    if spec.sense_filter != DEFAULT_SENSE_FILTER:
        controller += f" filter={number(spec.sense_filter)}"
    search = (
        f"search controllers={spec.controllers} generations={spec.generations} reseed={spec.reseed}"
    )
    if spec.reinitialize != DEFAULT_REINITIALIZE:
        search += f" reinitialize={number(spec.reinitialize)}"
    simulate = f"simulate duration={number(spec.duration)} dt={number(spec.dt)}"
    if spec.tau_min is not None:
        simulate += f" tau_min={number(spec.tau_min)}"
    lines = [
        f"figure {spec.figure}",
        controller,
        simulate,
        search,
        "seeds " + " ".join(str(seed) for seed in spec.seeds),
    ]
    if spec.start:
        lines.append(
            "start " + " ".join(f"{name}={number(value)}" for name, value in spec.start.items())
        )
    perturbation = spec.perturbation
    perturb = [
        f"{key}={number(getattr(perturbation, key))}"
        for key in _PERTURB_KEYS
        if getattr(perturbation, key) != 0.0
    ]
    if perturb:
        lines.append("perturb " + " ".join(perturb))
    lines.append(
        "fitness " + " ".join(f"{term}={number(weight)}" for term, weight in spec.weights.items())
    )
    fall = [f"{point.rod}.{point.end}" for point in spec.fall]
    if spec.fall_below != DEFAULT_FALL_BELOW:
        fall.append(f"below={number(spec.fall_below)}")
    if fall:
        lines.append("fall " + " ".join(fall))
    if spec.chain:
        lines.append(f"chain {spec.chain}")
    return "\n".join(lines) + "\n"
