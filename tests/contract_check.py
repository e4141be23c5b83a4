"""An independent reading of DESIGN.md's data contracts, for the files the pipeline builds.

Other tools read results/ by the contracts alone, so this module reads the files as such a
tool would: with h5py and numpy, none of mosys's own readers, and checks what DESIGN.md
promises of each kind (controller tables, trajectories, the ``figure_motion`` group, BSR and
composite results, generated dynamics modules): the datasets, their shapes and types, the
root attributes, and the numbers that the contract defines in terms of others (a destination
node's cost-to-go 0, a figure's centre of mass from its rods, a search's terms measured on its
best motion, a chained search starting where the search it continues ends, a mass matrix times
qdd giving forcing). ``contract_problems`` returns one line per broken promise, naming the file.
"""

from __future__ import annotations

import ast
import hashlib
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

import h5py
import numpy as np

FLAT_FLOOR = [[-1000, 0], [1000, 0]]
SINK = 0.01  # m: no endpoint of a motion on the flat floor may be lower (the issues' 1 cm)
SAMPLE_SPACING = 0.010  # s: figure_motion holds every simulator step or at least every 10 ms
ROD_LENGTH = 1e-6  # m: a rod's drawn length against its attribute (rods are rigid)
CENTRE_OF_MASS = 1e-6  # m: com against the mass-weighted rod centres
TERM = 1e-6  # tolerance of a fitness term recomputed from best/figure_motion
HEADING = 1e-9  # rad: an unchained 3-D search starts facing +x
DYNAMICS = 1e-9  # relative: mass_matrix(q) @ qdd(q, qd, tau) against forcing(q, qd, tau)
DYNAMICS_IMPORTS = {"math", "numpy", "numba"}  # a generated module is importable on its own

CONTROLLER_ATTRS = [
    "format_version",
    "state_order",
    "control_names",
    "control_min",
    "control_max",
    "K",
    "dest",
    "figure",
    "spec_sha256",
    "generation_seconds",
    "iterations",
    "residual",
]
FIGURE_MOTION_ATTRS = [
    "rod_names",
    "rod_mass",
    "rod_length",
    "rod_com",
    "rod_inertia",
    "gravity",
    "terrain",
    "contact",
]
BSR_ATTRS = [
    "format_version",
    "figure",
    "controller_kind",
    "seed",
    "evaluations",
    "duration",
    "dt",
    "best_fitness",
    "fitness_weights",
    "fitness_terms",
    "spec_sha256",
    "wall_seconds",
]
COMPOSITE_ATTRS = [
    "format_version",
    "script",
    "phases",
    "phases_before",
    "score_before",
    "score_after",
    "simulations",
    "spec_sha256",
    "wall_seconds",
]
CAR_ORDER = ["x", "y", "heading", "steer", "speed"]
# attributes that list names (DESIGN.md's state_order, control_names, controllers and rod_names,
# and mosys's own lists): strings, also when the list is empty
NAME_LISTS = {
    "state_order",
    "control_names",
    "controllers",
    "rod_names",
    "rods",
    "joint_names",
    "sense_names",
    "controller_kinds",
    "switch_controllers",
    "domain_violation_controllers",
    "obstacle_names",
    "controller_files",
    "units",
}
NOT_NAMES = {"bsr result": {"controllers"}}  # a BSR result's root controllers is C, a count
# what reading a file that breaks its contract raises (a dataset missing, a wrong type, not HDF5)
UNREADABLE = (KeyError, ValueError, TypeError, IndexError, OSError)


def spec_hash_problems(attrs: h5py.AttributeManager, spec: Path | None) -> list[str]:
    """A file's ``spec_sha256`` against the sha256 of its spec (None: not checked)."""
    if spec is None or attrs["spec_sha256"] == hashlib.sha256(spec.read_bytes()).hexdigest():
        return []
    return [f"spec_sha256 is not the sha256 of {spec.name}"]


def missing(attrs: h5py.AttributeManager, names: list[str]) -> list[str]:
    return [name for name in names if name not in attrs]


def names(value) -> list[str]:
    """A list-of-str attribute as Python strings (h5py may give bytes)."""
    return [v.decode() if isinstance(v, bytes) else str(v) for v in np.atleast_1d(value)]


def name_list_problems(path: Path, names: set[str] = NAME_LISTS) -> list[str]:
    """Every attribute of ``names`` in the file that is not stored as strings (h5py writes an
    empty Python list as float64: a reader checking the type found numbers)."""
    problems = []
    with h5py.File(path, "r") as h5:

        def visit(_name: str, item: h5py.HLObject) -> None:
            for key in names & set(item.attrs):
                stored = item.attrs.get_id(key).dtype
                if h5py.check_string_dtype(stored) is None:
                    problems.append(f"{item.name} attr {key}: names stored as {stored}, not text")

        visit("/", h5)
        h5.visititems(visit)
    return problems


def destination_nodes(axes: list[np.ndarray], order: list[str], dest: dict) -> np.ndarray:
    """Boolean mask (state shape) of the nodes whose coordinates match ``dest`` (its unnamed
    dimensions free)."""
    mask = np.ones(tuple(len(axis) for axis in axes), dtype=bool)
    for k, (name, axis) in enumerate(zip(order, axes, strict=True)):
        if name in dest:
            on = np.isclose(axis, dest[name], rtol=0.0, atol=1e-9)
            shape = [1] * len(axes)
            shape[k] = len(axis)
            mask &= on.reshape(shape)
    return mask


def controller_table_problems(path: Path, spec: Path | None) -> list[str]:
    """results/controllers/F/C.h5 against DESIGN.md's controller table (spec: its .ssc, whose
    sha256 the table names, or None)."""
    out = []
    with h5py.File(path, "r") as table:
        attrs = table.attrs
        out += [f"lacks root attr {name}" for name in missing(attrs, CONTROLLER_ATTRS)]
        if out:
            return out
        order = names(attrs["state_order"])
        axes = []
        for name in order:
            axis = table[f"axes/{name}"]
            if axis.ndim != 1 or axis.dtype != np.float64:
                out.append(f"/axes/{name} is {axis.dtype} of shape {axis.shape}, not 1-D float64")
            if not isinstance(axis.attrs.get("unit"), str) or "wrap" not in axis.attrs:
                out.append(f"/axes/{name} lacks its unit (str) or wrap (bool)")
            axes.append(axis[()])
        shape = tuple(len(axis) for axis in axes)
        controls = len(names(attrs["control_names"]))
        value = table["value"][()]
        if value.shape != shape or value.dtype != np.float64:
            out.append(f"/value is {value.dtype} {value.shape}, not float64 {shape}")
        if table["torque"].shape != (*shape, controls) or table["torque"].dtype != np.float64:
            out.append(f"/torque is {table['torque'].dtype} {table['torque'].shape}")
        destinations = [json.loads(attrs["dest"])]
        if "destinations" in attrs:
            destinations = json.loads(attrs["destinations"])
            if destinations[0] != json.loads(attrs["dest"]):
                out.append("dest is not the first of destinations")
            index = table["destination_index"][()]
            if index.shape != shape or index.dtype != np.int64:
                out.append(f"/destination_index is {index.dtype} {index.shape}")
            elif np.any((index == -1) != np.isinf(value)):
                out.append("/destination_index is not -1 exactly where /value is inf")
        for dest in destinations:
            nodes = destination_nodes(axes, order, dest)
            if not nodes.any():
                out.append(f"no grid node matches the destination {dest}")
            elif np.any(value[nodes] != 0.0):
                out.append(f"a node of the destination {dest} has a cost-to-go other than 0")
        if np.any(value < 0) or np.isnan(value).any():
            out.append("/value holds a negative or NaN cost-to-go")
        if attrs["figure"] == "car":
            out += [
                f"the car's table lacks {name}"
                for name in missing(
                    attrs, ["wheelbase", "wheel_radius", "body_outline", "obstacles"]
                )
            ]
            if order != CAR_ORDER:
                out.append(f"the car's state_order is {order}, not {CAR_ORDER}")
            if names(attrs["control_names"]) != ["steer_rate", "wheel_accel"]:
                out.append("the car's controls are not steer_rate, wheel_accel")
        out += spec_hash_problems(attrs, spec)
    return out


def figure_motion_problems(group: h5py.Group) -> list[str]:
    """A figure_motion group against DESIGN.md (2-D or 3-D), and what rigid rods and a flat
    floor imply: rods keep their lengths, com is the rods' mass-weighted centre, no endpoint
    sinks more than 1 cm."""
    out = [f"lacks attr {name}" for name in missing(group.attrs, FIGURE_MOTION_ATTRS)]
    if out:
        return out
    dimensions = int(group.attrs.get("dimensions", 2))
    t, endpoints, com = group["t"][()], group["endpoints"][()], group["com"][()]
    rods = len(names(group.attrs["rod_names"]))
    if t.dtype != np.float64 or t.ndim != 1:
        return [f"t is {t.dtype} {t.shape}"]
    if np.any(np.diff(t) < 0):
        out.append("t decreases")
    if len(t) > 1 and np.diff(t).max() > SAMPLE_SPACING + 1e-9:
        out.append(f"samples {np.diff(t).max():.4f} s apart (at most 10 ms)")
    if endpoints.shape != (len(t), rods, 2, dimensions) or endpoints.dtype != np.float64:
        return [*out, f"endpoints is {endpoints.dtype} {endpoints.shape}"]
    if com.shape != (len(t), dimensions):
        return [*out, f"com is {com.shape}"]
    if not (np.isfinite(endpoints).all() and np.isfinite(com).all()):
        return [*out, "non-finite endpoints or com"]
    mass = np.asarray(group.attrs["rod_mass"], dtype=float)
    length = np.asarray(group.attrs["rod_length"], dtype=float)
    fraction = np.asarray(group.attrs["rod_com"], dtype=float)
    for name, values in (("rod_mass", mass), ("rod_length", length), ("rod_com", fraction)):
        if values.shape != (rods,):
            return [*out, f"{name} has {values.shape}, not one per rod"]
    proximal, distal = endpoints[:, :, 0], endpoints[:, :, 1]
    stretch = np.abs(np.linalg.norm(distal - proximal, axis=-1) - length).max()
    if stretch > ROD_LENGTH:
        out.append(f"a rod's drawn length differs from rod_length by {stretch:.2e} m")
    centres = proximal + fraction[None, :, None] * (distal - proximal)
    weighted = (mass[None, :, None] * centres).sum(axis=1) / mass.sum()
    if np.abs(weighted - com).max() > CENTRE_OF_MASS:
        out.append(f"com is {np.abs(weighted - com).max():.2e} m from the rods' centre of mass")
    terrain = json.loads(group.attrs["terrain"])
    if terrain == FLAT_FLOOR and endpoints[..., 1].min() < -SINK:
        out.append(f"an endpoint sinks {-endpoints[..., 1].min():.3f} m into the floor")
    if dimensions == 3:
        out += [
            f"lacks 3-D attr {name}"
            for name in missing(group.attrs, ["heading_rod", "heading_offset", "feet"])
        ]
        if terrain != FLAT_FLOOR:
            out.append("a 3-D motion's terrain is not the flat floor")
        if "feet" in group.attrs and not isinstance(json.loads(group.attrs["feet"]), list):
            out.append("feet is not a JSON list")
    return out


def trajectory_problems(path: Path) -> list[str]:
    """results/trajectories/S.h5 against DESIGN.md's trajectory."""
    with h5py.File(path, "r") as trajectory:
        out = [
            f"lacks root attr {n}"
            for n in missing(trajectory.attrs, ["state_order", "control_names", "controllers"])
        ]
        if out:
            return out
        n = trajectory["t"].shape[0]
        d = len(names(trajectory.attrs["state_order"]))
        m = len(names(trajectory.attrs["control_names"]))
        if trajectory["state"].shape != (n, d) or trajectory["control"].shape != (n, m):
            out.append("/state or /control does not have a row per sample and a column per name")
        controller = trajectory["controller"][()]
        if controller.shape != (n,):
            out.append(f"/controller is {controller.shape}, not one per sample")
        elif n and not (
            controller.min() >= 0 and controller.max() < len(names(trajectory.attrs["controllers"]))
        ):
            out.append("/controller indexes past the controllers attr")
        articulated = "figure_motion" in trajectory
        if articulated:
            motion = trajectory["figure_motion"]
            out += [f"figure_motion: {p}" for p in figure_motion_problems(motion)]
            if not np.array_equal(motion["t"][()], trajectory["t"][()]):
                out.append("figure_motion is not sampled at /t")
        car = names(trajectory.attrs["state_order"]) == CAR_ORDER
        if not car and not articulated:
            out.append("an articulated figure's trajectory without figure_motion")
    return out


def headings(motion: h5py.Group) -> np.ndarray:
    """The figure's heading at each sample, rad, unwrapped (DESIGN.md: the heading rod's
    horizontal projection, proximal to distal, plus heading_offset, counter-clockwise seen
    from above: +x is 0, -z is +90 degrees)."""
    rod = names(motion.attrs["rod_names"]).index(str(motion.attrs["heading_rod"]))
    along = motion["endpoints"][:, rod, 1] - motion["endpoints"][:, rod, 0]
    offset = np.radians(float(motion.attrs["heading_offset"]))
    return np.unwrap(np.arctan2(-along[:, 2], along[:, 0])) + offset


def bsr_result_problems(path: Path, spec: Path | None) -> list[str]:
    """results/bsr/NAME/seedK.h5 against DESIGN.md's BSR result, its terms measured again on
    its best motion."""
    with h5py.File(path, "r") as result:
        attrs = result.attrs
        out = [f"lacks root attr {name}" for name in missing(attrs, BSR_ATTRS)]
        if out:
            return out
        evaluations = result["learning_curve/evaluations"][()]
        best = result["learning_curve/best_fitness"][()]
        if evaluations.dtype != np.int64 or np.any(np.diff(evaluations) <= 0):
            out.append("learning_curve/evaluations is not increasing int64")
        if evaluations[-1] != attrs["evaluations"]:
            out.append(f"the learning curve ends at {evaluations[-1]}, not at the evaluations attr")
        if np.any(np.diff(best) < 0):
            out.append("learning_curve/best_fitness decreases")
        if best[-1] != attrs["best_fitness"]:
            out.append("the learning curve's last best fitness is not best_fitness")
        if "best/controller" not in result:
            out.append("lacks best/controller")
        motion = result["best/figure_motion"]
        out += [f"best/figure_motion: {p}" for p in figure_motion_problems(motion)]
        rule = result["best/active_rule"]
        if rule.shape != motion["t"].shape or rule.dtype != np.int64 or rule[()].min() < -1:
            out.append("best/active_rule is not an int64 rule (or -1) per sample")
        terms = json.loads(attrs["fitness_terms"])
        json.loads(attrs["fitness_weights"])
        com = motion["com"][()]
        if int(motion.attrs.get("dimensions", 2)) == 3:
            out += [f"lacks root attr {n}" for n in missing(attrs, ["chain", "chain_seed"])]
            required = ["distance", "sideways", "heading_change", "max_height"]
            turned = headings(motion)
            start = turned[0]
            if not attrs.get("chain", "") and abs(np.angle(np.exp(1j * start))) > HEADING:
                out.append(
                    f"an unchained search starts heading {np.degrees(start):.4f} deg, not +x"
                )
            along = np.array([np.cos(start), -np.sin(start)])  # (x, z) of the start heading
            across = np.array([np.sin(start), np.cos(start)])
            moved = com[-1, [0, 2]] - com[0, [0, 2]]
            measured = {
                "distance": moved @ along,
                "sideways": abs(moved @ across),
                "heading_change": np.degrees(turned[-1] - turned[0]),
            }
        else:
            required = ["distance", "max_height", "contact_distance", "rotations"]
            torso = motion["endpoints"][:, 0, 1] - motion["endpoints"][:, 0, 0]
            turned = np.unwrap(np.arctan2(torso[:, 1], torso[:, 0]))
            measured = {
                "distance": com[-1, 0] - com[0, 0],
                "rotations": abs(turned[-1] - turned[0]) / (2 * np.pi),
            }
        measured["max_height"] = com[:, 1].max()
        out += [f"fitness_terms lacks {name}" for name in required if name not in terms]
        for name, value in measured.items():
            if name in terms and abs(terms[name] - value) > TERM:
                out.append(
                    f"fitness_terms {name} {terms[name]!r}, measured on the motion {float(value)!r}"
                )
        out += spec_hash_problems(attrs, spec)
    return out


def chain_problems(results: Path) -> list[str]:
    """DESIGN.md's chained searches: a 3-D search with a chain continues the seed of that
    search with the highest best_fitness, and starts exactly where its best motion ends."""
    out = []
    for path in sorted(results.glob("bsr/*/seed*.h5")):
        with h5py.File(path, "r") as result:
            chain = str(result.attrs.get("chain", ""))
            if not chain:
                continue
            seeds = sorted((results / "bsr" / chain).glob("seed*.h5"))
            if not seeds:
                continue  # the continued search's files are not in this build
            fitness = {}
            for seed in seeds:
                with h5py.File(seed, "r") as before:
                    fitness[int(before.attrs["seed"])] = float(before.attrs["best_fitness"])
            chosen = max(fitness, key=lambda seed: (fitness[seed], -seed))
            where = f"results/{path.relative_to(results)}"
            if int(result.attrs["chain_seed"]) != chosen:
                out.append(f"{where}: chain_seed {result.attrs['chain_seed']}, best seed {chosen}")
            with h5py.File(results / "bsr" / chain / f"seed{chosen}.h5", "r") as before:
                end = before["best/figure_motion/endpoints"][-1]
            if not np.array_equal(result["best/figure_motion/endpoints"][0], end):
                out.append(f"{where}: does not start where {chain} seed {chosen} ends")
    return out


def composite_result_problems(path: Path, spec: Path | None) -> list[str]:
    """results/composite/NAME.h5 against DESIGN.md's composite result."""
    with h5py.File(path, "r") as result:
        out = [f"lacks root attr {name}" for name in missing(result.attrs, COMPOSITE_ATTRS)]
        if out:
            return out
        for name in ("figure_motion", "before/figure_motion"):
            out += [f"{name}: {p}" for p in figure_motion_problems(result[name])]
        for name in ("phases", "phases_before"):
            phases = json.loads(result.attrs[name])
            if any(
                not isinstance(phase, dict) or not {"controller", "start", "end"} <= set(phase)
                for phase in phases
            ):
                out.append(f"{name}: a phase without controller, start and end")
            elif any(p["end"] < p["start"] for p in phases) or any(
                later["start"] < earlier["end"] - 1e-9
                for earlier, later in zip(phases, phases[1:], strict=False)
            ):
                out.append(f"{name}: phases end before they start, or overlap")
        out += spec_hash_problems(result.attrs, spec)
    return out


def dynamics_module_problems(path: Path) -> list[str]:
    """results/dynamics/F.py against DESIGN.md's generated dynamics module, checked in a new
    interpreter (``module_problems_here``) with a numba cache of its own, so that nothing is
    written beside the file: a figure's module imports only math, numpy and numba, so it is
    importable on its own; it names its coordinates and rates (Q_NAMES, QD_NAMES); and at random
    states mass_matrix(q) is symmetric and positive definite, and mass_matrix(q) @ qdd(q, qd,
    tau) == forcing(q, qd, tau). A built-in vehicle's (MODEL_KIND "vehicle") is not an
    articulated figure and has no mass matrix: only its imports are checked."""
    code = (
        "import json, sys; sys.path.insert(0, sys.argv[1]); "
        "from contract_check import module_problems_here; "
        "print(json.dumps(module_problems_here(sys.argv[2])))"
    )
    with tempfile.TemporaryDirectory() as cache:
        done = subprocess.run(
            [sys.executable, "-c", code, str(Path(__file__).parent), str(path)],
            capture_output=True,
            text=True,
            env=dict(os.environ, NUMBA_CACHE_DIR=cache),
        )
    if done.returncode != 0:
        return [f"does not import and run on its own: {done.stderr.strip().splitlines()[-1:]}"]
    return json.loads(done.stdout)


def module_problems_here(path: str, seed: int = 0) -> list[str]:
    """``dynamics_module_problems`` in this interpreter."""
    path = Path(path)
    tree = ast.parse(path.read_text())
    imported = {
        alias.name.split(".")[0]
        for node in ast.walk(tree)
        if isinstance(node, ast.Import)
        for alias in node.names
    }
    imported |= {
        node.module.split(".")[0]
        for node in ast.walk(tree)
        if isinstance(node, ast.ImportFrom) and node.module
    }
    out = [
        f"imports {name}, not only math, numpy and numba"
        for name in sorted(imported - DYNAMICS_IMPORTS)
    ]
    name = f"contract_dynamics_{path.stem}"  # numba imports it by name to load its cache
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    if getattr(module, "MODEL_KIND", "figure") != "figure":
        return out
    q_names, qd_names = getattr(module, "Q_NAMES", None), getattr(module, "QD_NAMES", None)
    if not (
        isinstance(q_names, tuple) and isinstance(qd_names, tuple) and len(q_names) == len(qd_names)
    ):
        return [*out, "Q_NAMES and QD_NAMES are not tuples of one name per coordinate"]
    n = len(q_names)
    rng = np.random.default_rng(seed)
    for _ in range(5):
        q, qd, tau = rng.uniform(-1, 1, n), rng.uniform(-2, 2, n), rng.uniform(-5, 5, n)
        mass = module.mass_matrix(q)
        if mass.shape != (n, n) or not np.allclose(mass, mass.T, rtol=0, atol=1e-12):
            return [*out, f"mass_matrix(q) is not a symmetric {n} x {n} matrix"]
        if np.linalg.eigvalsh(mass).min() <= 0:
            out.append("mass_matrix(q) is not positive definite")
        forcing = module.forcing(q, qd, tau)
        residual = np.abs(mass @ module.qdd(q, qd, tau) - forcing).max()
        if residual > DYNAMICS * max(1.0, np.abs(forcing).max()):
            out.append(f"mass_matrix(q) @ qdd(q, qd, tau) differs from forcing by {residual:.2e}")
    return out


def spec_or_none(path: Path) -> Path | None:
    return path if path.is_file() else None


def contract_problems(work: Path) -> tuple[Counter, list[str]]:
    """Every contract file under work/results, checked: (how many of each kind, problems). A
    file that cannot be read as its contract says (a dataset or group missing, a wrong type)
    is one problem naming what failed, and the other files are still checked."""
    results = work / "results"
    counts: Counter = Counter()
    problems = []

    def check(kind: str, path: Path, problems_of, *arguments) -> None:
        counts[kind] += 1
        try:
            found = problems_of(path, *arguments)
            if path.suffix == ".h5":
                found += name_list_problems(path, NAME_LISTS - NOT_NAMES.get(kind, set()))
        except UNREADABLE as error:
            found = [f"cannot be read as the contract says ({type(error).__name__}: {error})"]
        problems.extend(f"{path.relative_to(work)}: {p}" for p in found)

    for path in sorted(results.glob("controllers/*/*.h5")):
        spec = spec_or_none(work / "specs/controllers" / path.parent.name / f"{path.stem}.ssc")
        check("controller table", path, controller_table_problems, spec)
    for path in sorted(results.glob("trajectories/*.h5")):
        check("trajectory", path, trajectory_problems)
    for path in sorted(results.glob("bsr/*/seed*.h5")):
        spec = spec_or_none(work / "specs/bsr" / f"{path.parent.name}.bsr")
        check("bsr result", path, bsr_result_problems, spec)
    try:
        problems += chain_problems(results)
    except UNREADABLE as error:
        problems.append(f"chained searches cannot be read ({type(error).__name__}: {error})")
    for path in sorted(results.glob("composite/*.h5")):
        spec = spec_or_none(work / "specs/composite" / f"{path.stem}.comp")
        check("composite result", path, composite_result_problems, spec)
    for path in sorted(results.glob("dynamics/*.py")):
        check("dynamics module", path, dynamics_module_problems)
    return counts, problems


def main(argv: list[str]) -> int:
    """``python tests/contract_check.py [WORKDIR]``: check every contract file under
    WORKDIR/results (default: the current directory), print what was checked and each problem;
    exit 1 where there is one, 0 where there is none."""
    work = Path(argv[0] if argv else ".")
    if not (work / "results").is_dir():
        print(f"contract_check: no results/ folder in {work}", file=sys.stderr)
        return 2
    counts, problems = contract_problems(work)
    checked = ", ".join(f"{count} {kind}" for kind, count in sorted(counts.items()))
    print(f"contract_check: {checked or 'no contract files'}; {len(problems)} problems")
    for problem in problems:
        print(problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
