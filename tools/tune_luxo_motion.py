"""Search a Luxo motor program (``specs/motor/luxo/NAME.mot``) for one motion of the show.

How the five programs in ``specs/motor/luxo/`` were made. A program here has three phases:
crouch (T1 s, servo to hip h1, elbow e1), push off (T2 s, servo to h2, e2 with gain kp2) and
in the air (T3 s, servo to h3, e3); then the landing controller takes over, as in the show.
A candidate is run on the real figure (``results/dynamics/luxo.py``, its terrain included) from
the standing state at each start x, then landed by the real landing controller
(``results/controllers/luxo/land.h5``) for LAND_SECONDS, and scored (``cost``: lower is
better) against the motion's targets: net base rotation, distance, ground level at the end,
least airtime; it must touch down on its base (rotation at touch-down near the target), land
and settle in the standing pose, never touch the ground with the head, and never touch ground
below the level it should end on (the ditch). Random sampling of the box LOW..HIGH, then a
local search (Gaussian steps, shrinking) from the best few, scoring the worst over all starts
and small perturbations of them (PERTURB: robustness to where a landing leaves Luxo).

Run from the repository root after ``snakemake results/luxo_all`` has built the dynamics and
the controller::

    python tools/tune_luxo_motion.py hop --distance=-0.2 --starts=0,-0.2,-0.4 \
        --write specs/motor/luxo/hop.mot

It prints the chosen parameters, the measures from every start, and with ``--write`` writes
the program (its comment names the command). The show's programs were searched in order, each
from where the previous ones leave Luxo (``--starts``, the front edge's x).
"""

from __future__ import annotations

import argparse
import json
import math
import shlex
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mosys.animation.motion_measures import ground_height, longest_flight
from mosys.animation.motor_program import BoundMotorProgram, load_motor_program
from mosys.dynamics.load import load_dynamics
from mosys.io.progress import Progress
from mosys.parsing.motor import parse_motor_program
from mosys.ssc.controller import Controller

DT = 0.0005  # s, the show's step (config/config.yaml luxo: dt)
LAND_SECONDS = 2.5  # s of landing controller after the program
SAMPLE_EVERY = 4  # steps between the samples the measures look at
TOUCH = 0.002  # m: a contact point this close to the ground touches it
STANDING = {"hip": 0.0, "elbow": 120.0}  # deg, the landing controller's destination
# parameters: T1 h1 e1 | T2 h2 e2 kp2 | T3 h3 e3 (s, deg, N m/rad)
NAMES = ("T1", "h1", "e1", "T2", "h2", "e2", "kp2", "T3", "h3", "e3")
LOW = np.array([0.25, -40.0, 40.0, 0.05, -75.0, 15.0, 5.0, 0.05, -75.0, 15.0])
HIGH = np.array([0.60, 40.0, 165.0, 0.25, 75.0, 165.0, 60.0, 0.70, 75.0, 165.0])
HEAD_CLEARANCE = 0.01  # m, wanted between the head and the ground throughout
PERTURB = (("hip", 0.3), ("elbow", 0.4), ("x", 0.01))  # robustness: +- these (deg, m)


@dataclass(frozen=True)
class Targets:
    rotation: float  # deg, net base rotation (a backflip: -360)
    distance: float  # m, the front edge's x displacement
    ground: float  # m, the ground level Luxo ends on
    airtime: float  # s, at least


def program_text(name: str, p: np.ndarray, command: str) -> str:
    t1, h1, e1, t2, h2, e2, kp2, t3, h3, e3 = (float(v) for v in p)
    return (
        f"# {name}: searched by tools/tune_luxo_motion.py:\n"
        f"#   {command}\n"
        "# From Luxo's standing pose (the landing controller's destination); the landing\n"
        "# controller takes over when the program ends. Servo targets in degrees, gains in\n"
        "# N m/rad and N m s/rad.\n"
        "figure luxo\n"
        "limit hip_torque=20 elbow_torque=20\n"
        "gains kp=6 kd=0.25\n"
        f"phase {t1:.3f} hip={h1:.3f} elbow={e1:.3f}    # crouch\n"
        f"phase {t2:.3f} hip={h2:.3f} elbow={e2:.3f} kp={kp2:.3f} kd=0.3    # push off\n"
        f"phase {t3:.3f} hip={h3:.3f} elbow={e3:.3f}    # in the air\n"
    )


class Evaluator:
    """Runs candidates on the real figure and landing controller."""

    def __init__(self, dynamics_path: str, controller_path: str):
        self.dynamics = load_dynamics(dynamics_path)
        self.controller = Controller.load(controller_path, self.dynamics)
        self.terrain = json.loads(self.dynamics.TERRAIN_JSON)
        self.names = self.dynamics.Q_NAMES
        self.workdir = Path(tempfile.mkdtemp(prefix="tune_luxo_"))

    def standing(self, x: float, perturb: dict[str, float] | None = None) -> np.ndarray:
        """The standing state with the front edge at x, settled by the landing controller."""
        state = np.zeros(2 * len(self.names))
        state[0] = x
        for name, value in STANDING.items():
            state[self.names.index(name)] = math.radians(value)
        state = self.controller.simulate(state, 1.0, DT).states[-1]
        for name, value in (perturb or {}).items():
            k = self.names.index(name)
            state[k] += value if name == "x" else math.radians(value)
        return state

    def program(self, p: np.ndarray) -> BoundMotorProgram:
        path = self.workdir / "candidate.mot"
        path.write_text(program_text("candidate", p, ""))
        return load_motor_program(path, "luxo", self.dynamics)

    def measure(self, p: np.ndarray, start: np.ndarray) -> dict[str, float]:
        run = self.program(p).run(start, DT)
        landing = self.controller.simulate(run.states[-1], LAND_SECONDS, DT)
        states = np.concatenate([run.states[:-1], landing.states])[::SAMPLE_EVERY]
        n = len(self.names)
        points = np.array(
            [self.dynamics.contact_points(np.ascontiguousarray(s[:n])) for s in states]
        )
        surface = ground_height(self.terrain, points[..., 0])
        height = points[..., 1] - surface
        touching = (height < TOUCH).any(axis=1)
        takeoff, touchdown = longest_flight(touching)
        base = np.degrees(states[:, 2] - start[2])
        end = states[-1]
        ground_end = float(ground_height(self.terrain, np.array([end[0] + 0.08]))[0])
        pushing = slice(0, takeoff if takeoff is not None else len(states))
        return {
            "rotation": float(base[-1]),
            "distance": float(end[0] - start[0]),
            "ground": ground_end,
            "y": float(end[1]),
            "airtime": 0.0
            if touchdown is None or takeoff is None
            else (touchdown - takeoff) * SAMPLE_EVERY * DT,
            "touchdown_base": float(base[touchdown]) if touchdown is not None else math.nan,
            "tilt": float(np.abs(base[pushing]).max()),
            "head": float(height[:, 2].min()),
            "hip": math.degrees(end[3]),
            "elbow": math.degrees(end[4]),
            "speed": float(np.abs(end[n : n + 2]).max()),
            "rate": math.degrees(float(np.abs(end[n + 2 :]).max())),
            "penetration": float(max(0.0, -height.min())),
            "lowest": float(surface[height < TOUCH].min()),
        }


def cost(m: dict[str, float], targets: Targets) -> float:
    """Lower is better; about 1 per 10 deg of rotation or 5 cm of distance off."""
    c = ((m["rotation"] - targets.rotation) / 10.0) ** 2
    c += ((m["distance"] - targets.distance) / 0.05) ** 2
    c += 10.0 * ((m["ground"] - targets.ground) / 0.15) ** 2 + (abs(m["y"] - targets.ground) / 0.01)
    c += (max(0.0, targets.airtime - m["airtime"]) / 0.03) ** 2
    touchdown = m["touchdown_base"] if math.isfinite(m["touchdown_base"]) else 180.0
    c += (max(0.0, abs(touchdown - targets.rotation) - 20.0) / 5.0) ** 2
    c += (max(0.0, m["tilt"] - 25.0) / 5.0) ** 2
    c += 20.0 if m["head"] < TOUCH else 0.0
    c += (max(0.0, HEAD_CLEARANCE - m["head"]) / 0.005) ** 2
    c += (m["hip"] - STANDING["hip"]) ** 2 / 9.0 + (m["elbow"] - STANDING["elbow"]) ** 2 / 9.0
    c += 20.0 * m["speed"] + m["rate"] / 5.0
    c += (max(0.0, m["penetration"] - 0.01) / 0.005) ** 2
    c += 20.0 if m["lowest"] < targets.ground - 0.01 else 0.0  # into the ditch
    return float(c)


def program_parameters(path: str) -> np.ndarray:
    """The parameters (NAMES) of a three-phase program written by ``program_text``."""
    phases = parse_motor_program(path).phases
    angle = [{s.name: s.value for s in phase.settings} for phase in phases]
    return np.array(
        [phases[0].seconds, angle[0]["hip"], angle[0]["elbow"]]
        + [phases[1].seconds, angle[1]["hip"], angle[1]["elbow"], phases[1].kp]
        + [phases[2].seconds, angle[2]["hip"], angle[2]["elbow"]]
    )


def search(
    evaluator: Evaluator,
    targets: Targets,
    xs: list[float],
    samples: int,
    local: int,
    seed: int,
    initial: np.ndarray | None = None,
) -> tuple[float, np.ndarray]:
    rng = np.random.default_rng(seed)
    starts = [evaluator.standing(x) for x in xs]
    robust = starts + [
        evaluator.standing(x, {name: sign * size})
        for x in xs[:1]
        for name, size in PERTURB
        for sign in (1.0, -1.0)
    ]

    def worst(p: np.ndarray, over: list[np.ndarray]) -> float:
        return max(cost(evaluator.measure(p, s), targets) for s in over)

    progress = Progress("random samples", samples, "candidates")
    sampled = []
    for k in range(samples):
        p = LOW + rng.random(len(LOW)) * (HIGH - LOW)
        sampled.append((worst(p, starts[:1]), p))
        progress.update(k + 1)
    progress.finish()
    sampled.sort(key=lambda item: item[0])
    if initial is not None:
        sampled.insert(0, (0.0, np.clip(initial, LOW, HIGH)))
    best_cost, best = min(((worst(p, robust), p) for _, p in sampled[:10]), key=lambda i: i[0])
    step = (HIGH - LOW) * 0.05
    progress = Progress("local search", local, "candidates")
    for it in range(local):
        candidate = np.clip(best + rng.normal(0.0, 1.0, len(LOW)) * step, LOW, HIGH)
        candidate_cost = worst(candidate, robust)
        if candidate_cost < best_cost:
            best_cost, best = candidate_cost, candidate
        if it % 100 == 99:
            step *= 0.6
        progress.update(it + 1, f"cost {best_cost:.3f}")
    progress.finish()
    return best_cost, best


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("name")
    parser.add_argument("--rotation", type=float, default=0.0, help="deg (backflip: -360)")
    parser.add_argument("--distance", type=float, required=True, help="m (forward: negative)")
    parser.add_argument("--ground", type=float, default=0.0, help="m, where it ends")
    parser.add_argument("--airtime", type=float, default=0.1, help="s, at least")
    parser.add_argument("--starts", default="0", help="front-edge x of each start, m")
    parser.add_argument("--samples", type=int, default=600)
    parser.add_argument("--local", type=int, default=300)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--initial", help="a program this tool wrote: also start from it")
    parser.add_argument("--dynamics", default="results/dynamics/luxo.py")
    parser.add_argument("--controller", default="results/controllers/luxo/land.h5")
    parser.add_argument("--write", help="write the program here")
    args = parser.parse_args(argv)
    targets = Targets(args.rotation, args.distance, args.ground, args.airtime)
    xs = [float(x) for x in args.starts.split(",")]
    evaluator = Evaluator(args.dynamics, args.controller)
    began = time.perf_counter()
    initial = program_parameters(args.initial) if args.initial else None
    best_cost, best = search(evaluator, targets, xs, args.samples, args.local, args.seed, initial)
    print(f"cost {best_cost:.3f} in {time.perf_counter() - began:.0f} s")
    print(" ".join(f"{n}={v:.3f}" for n, v in zip(NAMES, best, strict=True)))
    for x in xs:
        m = evaluator.measure(best, evaluator.standing(x))
        print(f"x={x:+.2f}", " ".join(f"{k}={v:.3f}" for k, v in m.items()))
    if args.write:
        command = "python tools/tune_luxo_motion.py " + shlex.join(argv)
        Path(args.write).write_text(program_text(args.name, best, command))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
