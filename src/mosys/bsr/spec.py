"""A parsed BSR search spec (``specs/bsr/NAME.bsr``): what ``parsing.bsr`` produces and the search
consumes. Units as the search uses them: seconds, metres, degrees for angles as written (the
binding to a figure converts to radians)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from mosys.parsing.tokens import Token

_NO_TOKEN = Token("", 0, 0)

CONTROLLER_KINDS = ("sense", "time")
# fitness terms: the primary term and Table 3's secondary terms, plus the fall penalty
FITNESS_TERMS = ("distance", "max_height", "contact_distance", "rotations", "fall")
ENDPOINT_ENDS = ("proximal", "distal")


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
    2 Δt). ``tokens`` keeps the token of each setting (keyed like
    ``figure``, ``start.NAME``, ``fitness.TERM``) so that binding to the figure can point at the
    offending word."""

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
    spec_sha256: str = field(default="", compare=False)
    tokens: dict[str, Token] = field(default_factory=dict, compare=False, repr=False)

    @property
    def name(self) -> str:
        """The search's name: the spec file's stem."""
        return Path(self.path).stem

    @property
    def steps(self) -> int:
        """Simulator steps per evaluation: round(T / Δt)."""
        return int(round(self.duration / self.dt))
