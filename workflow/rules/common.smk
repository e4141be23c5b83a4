# Config validation and the only helpers of the workflow: target lists, the package modules each
# rule's verb runs, and the specs (read by mosys's own parsers) that decide a rule's inputs.
import ast
import contextlib
import functools
import importlib.util
import json
import math
import os
import re
import shutil
import subprocess
import tempfile
import threading
import time
from importlib.machinery import PathFinder
from pathlib import Path

import yaml
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate


NUMBER = r"[+-]?([0-9]+[.]?[0-9]*|[.][0-9]+)([eE][+-]?[0-9]+)?"  # a number as YAML writes one


def typed_overrides(value, schema):
    """``value`` with the strings the schema wants as numbers, booleans or null made so:
    Snakemake's ``--config`` passes nested values as strings, and bsr='{generations: 100}'
    was refused ('100' is not of type 'integer'). A string that is none is left, for the
    validation to refuse; a number where the schema wants an integer or a number is made one
    (a fraction where it wants an integer stays a float, for the validation to refuse). A whole
    float where the schema wants an integer (``seeds: 2.0``, ``1e300``), which the schema
    passes, is made an int: ``seeds: 1e300`` raised in a slice."""
    if isinstance(value, dict):
        properties, others = schema.get("properties", {}), schema.get("additionalProperties")
        others = others if isinstance(others, dict) else {}  # the schema of keys not listed
        return {key: typed_overrides(item, properties.get(key, others)) for key, item in value.items()}
    if isinstance(value, list):
        prefix, rest = schema.get("prefixItems", []), schema.get("items", {})
        return [typed_overrides(item, prefix[k] if k < len(prefix) else rest)
                for k, item in enumerate(value)]
    kinds = schema.get("type", [])
    kinds = [kinds] if isinstance(kinds, str) else kinds
    if isinstance(value, float) and "integer" in kinds and value.is_integer():
        return int(value)  # the schema takes 3.0 as an integer, and Python's slices did not
    if not isinstance(value, str):
        return value
    text = value.strip()
    if "null" in kinds and text in ("null", "~"):
        return None
    if "boolean" in kinds and text.lower() in ("true", "false"):
        return text.lower() == "true"
    if "integer" in kinds and re.fullmatch(r"[+-]?[0-9]+", text):
        return int(text)  # exactly, however long
    number = yaml_number(text)
    if number is None:
        return value
    if "integer" in kinds and number.is_integer():
        return int(number)  # as from a YAML file: seeds: 2.0 is 2
    return number if "number" in kinds or "integer" in kinds else value


def yaml_number(text):
    """The float a YAML file reads ``text`` as (``2.0``, ``1e300``, ``.inf``, ``-.Inf``,
    ``.nan``), or None: on the command line they came as strings, and ``seeds: 2.0`` was
    refused as one while a YAML file's was taken, and ``.inf`` missed the finite-number check."""
    if re.fullmatch(NUMBER, text):
        return float(text)
    sign, core = (-1.0, text[1:]) if text[:1] == "-" else (1.0, text.removeprefix("+"))
    if core in (".inf", ".Inf", ".INF"):
        return sign * math.inf
    if text in (".nan", ".NaN", ".NAN"):
        return math.nan
    return None


CONFIG_SCHEMA = Path(workflow.current_basedir) / "../schemas/config.schema.yaml"
config.update(typed_overrides(dict(config), yaml.safe_load(CONFIG_SCHEMA.read_text())))
validate(config, str(CONFIG_SCHEMA))  # --config's strings typed first


def non_finite_keys(value, key=""):
    """(key, value) of every config number that is NaN or infinite (a YAML .nan or .inf): the
    schema's bounds let NaN through, since every comparison with it is false, and an infinity
    through a lower bound alone (a step of .inf); each failed only in the job that read it. No
    key takes an infinity for "no limit" (``limits`` takes null)."""
    if isinstance(value, dict):
        return [
            k for name, item in value.items() for k in non_finite_keys(item, f"{key}.{name}".lstrip("."))
        ]
    if isinstance(value, list):
        return [k for index, item in enumerate(value) for k in non_finite_keys(item, f"{key}[{index}]")]
    return [(key, value)] if isinstance(value, float) and not math.isfinite(value) else []


for _key, _value in non_finite_keys(config):
    raise WorkflowError(f"config {_key}: expected a finite number, found {_value}")


def variability_searches():
    """The searches Figure 8 draws (config bsr3d.variability: a kind set to null is left out)."""
    return [name for name in config["bsr3d"]["variability"].values() if name]


def configured_searches():
    """(config key, search names) for every list of searches the config names."""
    bsr3d, composite = config["bsr3d"], config["composite"]
    searches = [
        ("bsr.searches", config["bsr"]["searches"]),
        ("bsr.full_budget", config["bsr"]["full_budget"]),
        ("bsr3d.searches", bsr3d["searches"]),
        ("bsr3d.full_budget", bsr3d["full_budget"]),
        ("bsr3d.kinds", list(bsr3d["kinds"].values())),
        ("bsr3d.variability", variability_searches()),
        ("composite.robustness", [*composite["robustness"], *composite["robustness"].values()]),
    ]
    searches += [(f"bsr3d.motions.{motion}", chain) for motion, chain in bsr3d["motions"].items()]
    for part, value in bsr3d["targets"].items():
        searches.append((f"bsr3d.targets.{part}", value if isinstance(value, list) else [value]))
    return searches


def configured_specs():
    """(config key, spec file) for every spec the config names."""
    pendulum, car, luxo = config["pendulum"], config["car"], config["luxo"]
    composite = config["composite"]
    named = [
        ("pendulum.figure", f"specs/figures/{pendulum['figure']}.fig"),
        ("car.figure", f"specs/figures/{car['figure']}.fig"),
        ("luxo.figure", f"specs/figures/{luxo['figure']}.fig"),
        ("car.controller", f"specs/controllers/{car['group']}/{car['controller']}.ssc"),
        ("luxo.controller", f"specs/controllers/{luxo['group']}/{luxo['controller']}.ssc"),
        ("pendulum.script", f"specs/scripts/{pendulum['script']}.anim"),
        ("car.gif_script", f"specs/scripts/{car['gif_script']}.anim"),
        ("luxo.script", f"specs/scripts/{luxo['script']}.anim"),
    ]
    named += [
        ("pendulum.controllers", f"specs/controllers/{pendulum['group']}/{name}.ssc")
        for name in pendulum["controllers"]
    ]
    for key, names in (
        ("pendulum.scripts", pendulum["scripts"]),
        ("pendulum.compare_controls", pendulum["compare_controls"]),
        ("car.scripts", car["scripts"]),
    ):
        named += [(key, f"specs/scripts/{name}.anim") for name in names]
    for key, names in configured_searches():
        named += [(key, f"specs/bsr/{name}.bsr") for name in names]
    named += [("composite.scripts", f"specs/composite/{name}.comp") for name in composite["scripts"]]
    return named


# A name in the config with no spec stops the run here, naming the key (it used to surface as
# a rule's InputFunctionException with a traceback, naming only the spec path).
for _key, _spec in configured_specs():
    if not Path(_spec).is_file():
        raise WorkflowError(f"config {_key}: {Path(_spec).stem!r} names no spec ({_spec} does not exist)")
# A camera for a name that is neither a motion nor a search spec would be ignored without a word.
for _motion in config["bsr3d"]["cameras"]:
    if _motion not in config["bsr3d"]["motions"] and not Path(f"specs/bsr/{_motion}.bsr").is_file():
        raise WorkflowError(
            f"config bsr3d.cameras: {_motion!r} names no motion of bsr3d.motions"
            f" ({', '.join(config['bsr3d']['motions'])}) and no search spec"
            f" (specs/bsr/{_motion}.bsr does not exist)"
        )
if not variability_searches():
    raise WorkflowError("config bsr3d.variability: a search of at least one kind (sense or time), found none")

# The limits on one job's memory and steps (README, "Limits"), for every job this run starts.
for _key, _variable in (("memory_gib", "MOSYS_MAX_MEMORY_GIB"), ("steps", "MOSYS_MAX_STEPS")):
    if config["limits"].get(_key) is not None:
        os.environ[_variable] = str(config["limits"][_key])

# The job server (README, "The job server"): one process that has imported mosys's libraries
# forks each job's mosys command, saving every job 0.7-1.4 s of imports. Started when a run
# starts jobs (not for a dry run), stopped when it ends; the jobs find it in MOSYS_JOB_SERVER.
# Without it (job_server: false, or it fails to start) every job is its own process as before.
JOB_SERVER = {}
JOB_SERVER_LOG = Path(".snakemake/log/mosys_job_server.log")
JOB_SERVER_LOG_BYTES = 1 << 20  # beyond this the log is moved aside (.1) when a server starts
JOB_SERVER_VARIABLE = "MOSYS_JOB_SERVER"  # a name, so that --lint sees no user setting


def start_job_server():
    if not config["job_server"] or os.environ.get(JOB_SERVER_VARIABLE):
        return  # off, or a run inside another's: the outer run's server serves it
    if workflow.non_local_exec or workflow.remote_exec:
        return  # SLURM: the jobs run on the cluster's nodes, each in its own process
    directory = Path(tempfile.mkdtemp(prefix="mosys-jobs-"))
    socket_path = directory / "socket"
    JOB_SERVER_LOG.parent.mkdir(parents=True, exist_ok=True)
    # appended to, not truncated: two runs at once (on other targets) each have a server, and
    # one truncating the log the other writes left it full of NUL bytes
    with contextlib.suppress(OSError):
        if JOB_SERVER_LOG.stat().st_size > JOB_SERVER_LOG_BYTES:
            JOB_SERVER_LOG.replace(JOB_SERVER_LOG.with_suffix(".log.1"))
    try:
        with open(JOB_SERVER_LOG, "a") as log:
            process = subprocess.Popen(
                ["mosys", "job-server", str(socket_path)],
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
            )
    except OSError as error:
        print(f"mosys job server not started ({error}): each job runs as its own process")
        shutil.rmtree(directory, ignore_errors=True)
        return
    deadline = time.monotonic() + 10.0
    while not socket_path.exists() and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    if not socket_path.exists():
        process.kill()
        print(f"mosys job server not started (see {JOB_SERVER_LOG}): each job runs on its own")
        shutil.rmtree(directory, ignore_errors=True)
        return
    JOB_SERVER.update(process=process, directory=directory)
    os.environ[JOB_SERVER_VARIABLE] = str(socket_path)


def stop_job_server():
    process = JOB_SERVER.pop("process", None)
    if process is None:
        return
    del os.environ[JOB_SERVER_VARIABLE]
    process.terminate()
    try:
        process.wait(timeout=10.0)
    except subprocess.TimeoutExpired:
        process.kill()
    shutil.rmtree(JOB_SERVER.pop("directory"), ignore_errors=True)


def cancel_rescheduling_timers():
    """Snakemake's job rate limiter (--max-jobs-per-timespan, 100/1s by default) leaves a
    threading.Timer that wakes its scheduler a second after each scheduling round; Python waits
    for the last one before it exits, up to 1 s after the last job. Once the run is over there
    is nothing left to wake."""
    for thread in threading.enumerate():
        if isinstance(thread, threading.Timer):
            thread.cancel()


onstart:
    start_job_server()


onsuccess:
    stop_job_server()
    cancel_rescheduling_timers()


onerror:
    stop_job_server()
    cancel_rescheduling_timers()


# What the CLI's main imports for every verb (its error types).
CLI_MODULES = ("mosys.errors", "mosys.parsing.tokens")
# What every verb family's module builds its arguments with (shared options such as --budget).
CLI_VERBS = "mosys.cli.verb"


@functools.cache
def package_directory():
    """The mosys package the workflow's code inputs name: the checkout beside the Snakefile
    (it, or one of its directories, holds mosys/), else the installed package."""
    here = Path(workflow.basedir)
    roots = [here] + sorted(p for p in here.iterdir() if p.is_dir() and not p.name.startswith("."))
    spec = PathFinder.find_spec("mosys", [str(root) for root in roots])
    if spec is None or not spec.submodule_search_locations:
        spec = importlib.util.find_spec("mosys")
    if spec is None or not spec.submodule_search_locations:
        raise WorkflowError("cannot find the mosys package: install it (pip install -e .)")
    return Path(list(spec.submodule_search_locations)[0])


@functools.cache
def module_file(name):
    """The source file of the package module name (mosys.a.b), or None if there is none."""
    parts = name.split(".")
    if parts[0] != "mosys":
        return None
    path = package_directory().joinpath(*parts[1:])
    for candidate in (path / "__init__.py", path.with_suffix(".py")):
        if candidate.is_file():
            return candidate
    return None


# The import statements found in each package file, kept between runs while the file is
# unchanged (its size and mtime): parsing every module the rules' code inputs name took as long
# as the rest of the workflow's set-up (Snakemake's own import aside).
IMPORT_STATEMENTS_CACHE = Path(".snakemake/mosys_import_statements.json")
unsaved_import_statements = set()  # files parsed since the cache was last written


@functools.cache
def import_statements_cache():
    try:
        cached = json.loads(IMPORT_STATEMENTS_CACHE.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return cached if isinstance(cached, dict) else {}


def save_import_statements_cache():
    """Write the cache if files were parsed (atomically: other Snakemake runs may read it);
    nothing if unwritable."""
    if not unsaved_import_statements:
        return
    unsaved_import_statements.clear()
    try:
        IMPORT_STATEMENTS_CACHE.parent.mkdir(parents=True, exist_ok=True)
        handle, partial = tempfile.mkstemp(dir=IMPORT_STATEMENTS_CACHE.parent, suffix=".partial")
    except OSError:
        return
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as stream:
            json.dump(import_statements_cache(), stream)
        os.replace(partial, IMPORT_STATEMENTS_CACHE)
    except OSError:
        Path(partial).unlink(missing_ok=True)


def statements(body):
    """Every statement in body and in the statements nested in it (function and class bodies,
    branches, handlers, match cases): where an import statement can be."""
    todo = list(body)
    while todo:
        node = todo.pop()
        yield node
        for field in ("body", "orelse", "finalbody", "handlers", "cases"):
            todo += [child for child in getattr(node, field, ()) if isinstance(child, ast.AST)]


def import_statements(path):
    """[line, level, module, names] of every import statement in the file at path (function
    bodies too; module None for ``import a.b``, whose names are the dotted modules), read with
    ast, nothing imported; from the cache while the file is unchanged."""
    stat = path.stat()
    stamp = [stat.st_size, stat.st_mtime_ns]
    cache = import_statements_cache()
    entry = cache.get(str(path))
    if entry is not None and entry.get("stamp") == stamp:
        return entry["imports"]
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    imports = []
    for node in statements(tree.body):
        if isinstance(node, ast.Import):
            imports.append([node.lineno, 0, None, [alias.name for alias in node.names]])
        elif isinstance(node, ast.ImportFrom):
            imports.append([node.lineno, node.level, node.module, [a.name for a in node.names]])
    imports.sort(key=lambda statement: statement[0])
    cache[str(path)] = {"stamp": stamp, "imports": imports}
    unsaved_import_statements.add(str(path))
    return imports


@functools.cache
def imported_modules(name):
    """The package modules that module name imports anywhere (function bodies too), with the
    packages along each dotted path."""
    path = module_file(name)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []  # (line, dotted name)
    for line, level, module, names in import_statements(path):
        if module is None and not level:  # import a.b
            found += [(line, dotted) for dotted in names]
            continue
        source = module or ""
        if level:  # from . import x, from ..a import b
            parts = package.split(".")[: len(package.split(".")) - level + 1]
            source = ".".join(parts + ([source] if source else []))
        found.append((line, source))
        # from mosys.plots import bsr names a submodule; from mosys.io.atomic import f, not
        found += [(line, f"{source}.{alias}") for alias in names
                  if module_file(f"{source}.{alias}") is not None]
    modules = set()
    for line, dotted in found:
        parts = dotted.split(".")
        if parts[0] != "mosys":
            continue
        if module_file(dotted) is None:
            raise WorkflowError(f"{path}:{line}: imports {dotted}, which has no source file")
        modules.update(".".join(parts[:n]) for n in range(1, len(parts) + 1))
    return frozenset(modules)


@functools.cache
def import_closure(name):
    """Module name and every package module it imports, directly or not."""
    if module_file(name) is None:
        raise WorkflowError(f"code_inputs: no package module {name}")
    parts = name.split(".")
    todo = [".".join(parts[:n]) for n in range(1, len(parts) + 1)]
    closure = set()
    while todo:
        dotted = todo.pop()
        if dotted not in closure:
            closure.add(dotted)
            todo += imported_modules(dotted)
    return frozenset(closure)


def code_inputs(*entries):
    """The package files a rule's output depends on (editing one reruns the rule): the import
    closure of the entry modules its verb calls and of the CLI's own imports, sorted; paths
    relative to the working directory when the package lies below it. An entry in mosys.cli
    (the module of the verb's family) counts as its own file and the verb declarations it builds
    on (CLI_VERBS) only: the CLI package imports every family, so following its imports would
    make every rule depend on all the code."""
    cwd = Path.cwd()
    files = set()
    for entry in CLI_MODULES + entries:
        if module_file(entry) is None:
            raise WorkflowError(f"code_inputs: no package module {entry}")
        cli = entry.startswith("mosys.cli.")
        modules = [entry, CLI_VERBS] if cli else import_closure(entry)
        for dotted in modules:
            path = module_file(dotted)
            files.add(str(path.relative_to(cwd)) if path.is_relative_to(cwd) else str(path))
    save_import_statements_cache()
    return sorted(files)


# The parser of each kind of spec, by file suffix: the one the spec's job runs (mosys.parsing).
SPEC_PARSERS = {
    ".ssc": ("mosys.parsing.controller", "parse_controller_spec"),
    ".anim": ("mosys.parsing.script", "parse_script"),
    ".bsr": ("mosys.parsing.bsr", "parse_bsr_spec"),
    ".comp": ("mosys.parsing.composite", "parse_composite_script"),
}


@functools.cache
def parsed_spec(path):
    """The spec at path, parsed by mosys's own parser: a missing or malformed spec stops the
    DAG, before any job runs, with the parser's file:line:column message."""
    from mosys.parsing.tokens import SpecError

    parser_module, function = SPEC_PARSERS[Path(path).suffix]
    parse = getattr(importlib.import_module(parser_module), function)
    try:
        return parse(path)
    except SpecError as error:
        raise WorkflowError(str(error)) from None


def controller_dynamics(wildcards):
    """The generated dynamics a controller spec names in its 'dyn' line."""
    spec = parsed_spec(f"specs/controllers/{wildcards.group}/{wildcards.name}.ssc")
    return [f"results/dynamics/{spec.figure}.py"]


def plotted_controller_dynamics(wildcards):
    """``controller_dynamics`` for a controller's plots; without the spec, the spec itself (a
    missing input), since the file asked for may be another's to make (slew_torque.png is
    compared_controls', not the torque plot of a controller 'slew', whose missing spec
    printed a traceback in every dry run of all)."""
    path = f"specs/controllers/{wildcards.group}/{wildcards.name}.ssc"
    return controller_dynamics(wildcards) if Path(path).is_file() else [path]


def script_figure(script):
    """The figure a script's 'object' line names (figure=NAME), or None."""
    declared = parsed_spec(f"specs/scripts/{script}.anim").declared_figure
    return None if declared is None else declared.figure


def drives_car(script):
    """Whether a script is the car's: in car.scripts, car.gif_script, or its object line names
    the car's figure (a GIF script left out of car.scripts drew on controllers of its own name)."""
    car = config["car"]
    return (script in car["scripts"] or script == car["gif_script"]
            or script_figure(script) == car["figure"])


def script_group_and_reason(script):
    """The controller directory a script draws on, and why (for a message): the configured one
    for the pendulum's scripts, the car's and Luxo's (by their figure), else the script's own
    name."""
    if script == config["pendulum"]["script"] or script in config["pendulum"]["scripts"]:
        return (config["pendulum"]["group"],
                "config pendulum.group: the script is the pendulum's, or in pendulum.scripts")
    if drives_car(script):
        return (config["car"]["group"],
                "config car.group: the script is in car.scripts or car.gif_script, or drives"
                " the car's figure")
    if script_figure(script) == config["luxo"]["figure"]:
        return config["luxo"]["group"], "config luxo.group: the script animates Luxo's figure"
    return script, "the script's own name, as for any script not configured otherwise"


def script_group(script):
    """The controller directory a script draws on (``script_group_and_reason``)."""
    return script_group_and_reason(script)[0]


def script_dt(script):
    """The simulator step of a script, s: Luxo's own (stiff contacts), the car's own for the
    car's scripts, else the default."""
    if script_figure(script) == config["luxo"]["figure"]:
        return config["luxo"]["dt"]
    if drives_car(script):
        return config["car"]["dt"]
    return config["simulation"]["dt"]


def script_inputs(wildcards):
    """The tables, dynamics and motor programs a script needs (its 'swapcon', 'when', 'object'
    and 'motor' lines), and the controller specs they are made from. A controller without a
    spec in the script's group stops the DAG naming the script's line and the group's reason
    (it named only the missing spec, at '1:1')."""
    path = f"specs/scripts/{wildcards.script}.anim"
    script = parsed_spec(path)
    group, reason = script_group_and_reason(wildcards.script)
    names = script.controllers()
    for command in script.commands:
        name = getattr(command, "controller", None)
        spec = f"specs/controllers/{group}/{name}.ssc"
        if name is not None and not Path(spec).is_file():
            raise WorkflowError(
                f"{path}:{command.token.line}: {command.table_token.text} names controller "
                f"{name}, whose spec {spec} does not exist: the script's controllers come from "
                f"specs/controllers/{group}/ ({reason})"
            )
    figures = {f"results/dynamics/{parsed_spec(f'specs/controllers/{group}/{name}.ssc').figure}.py"
               for name in names}
    figure = script_figure(wildcards.script)
    programs = []
    if figure is not None:
        figures.add(f"results/dynamics/{figure}.py")
        from mosys.parsing.tokens import SpecError

        try:  # mosys run's message, before its job would fail
            files = script.motor_program_files("specs/motor", figure)
        except SpecError as error:
            raise WorkflowError(str(error)) from None
        programs = [str(path) for path in files.values()]
    return [f"results/controllers/{group}/{name}.h5" for name in names] + sorted(figures) + programs


def pendulum_controller_tables():
    group = config["pendulum"]["group"]
    return [f"results/controllers/{group}/{name}.h5" for name in config["pendulum"]["controllers"]]


def pendulum_targets():
    group = config["pendulum"]["group"]
    script = config["pendulum"]["script"]
    names = config["pendulum"]["controllers"]
    return (
        pendulum_controller_tables()
        + [f"results/trajectories/{script}.h5"]
        + [f"results/plots/{group}/{name}_portrait.png" for name in names]
        + [f"results/plots/{group}/{name}_torque.png" for name in names]
        + [f"results/trajectories/{name}.h5" for name in config["pendulum"]["scripts"]]
        + [f"results/plots/{group}/{name}_path.png"
           for name in [script] + config["pendulum"]["scripts"]]
        + [f"results/plots/{group}/{name}.gif"
           for name in [script] + config["pendulum"]["scripts"]]
        + [f"results/plots/{group}/slew_torque.png", f"results/plots/{group}/free_swing.png"]
        + paper_table_targets()
    )


def paper_table_targets():
    return ["results/tables/pendulum_controllers.csv", "results/tables/pendulum_controllers.md"]


def car_table():
    return f"results/controllers/{config['car']['group']}/{config['car']['controller']}.h5"


def car_trajectories():
    return [f"results/trajectories/{script}.h5" for script in config["car"]["scripts"]]


def car_table_targets():
    return ["results/tables/car_controller.csv", "results/tables/car_controller.md"]


def car_targets():
    return (
        [car_table(), "results/car/start_grid.h5"]
        + car_trajectories()
        + ["results/plots/car/figure19_frames.png", "results/plots/car/manoeuvre.gif",
           "results/plots/car/start_map.png", "results/plots/car/consistency.png"]
        + car_table_targets()
    )


def luxo_script():
    return config["luxo"]["script"]


def luxo_strip_motion(wildcards):
    """'--motion NAME' for the strip of a Luxo script: config luxo.strip_motion if the script
    runs it, else nothing (its first motion): a script of your own without a backflip failed."""
    name = config["luxo"]["strip_motion"]
    programs = parsed_spec(f"specs/scripts/{wildcards.script}.anim").motor_programs()
    return f"--motion {name}" if name in programs else ""


def luxo_table_targets():
    return ["results/tables/luxo_motions.csv", "results/tables/luxo_motions.md"]


def luxo_targets():
    group = config["luxo"]["group"]
    script = luxo_script()
    return (
        [f"results/controllers/{group}/{config['luxo']['controller']}.h5",
         f"results/trajectories/{script}.h5",
         f"results/plots/luxo/{script}_strip.png",
         f"results/plots/luxo/{script}.gif",
         f"results/plots/luxo/{script}_forces.png"]
        + luxo_table_targets()
    )


def bsr_settings(name):
    """The config section of a search's budget: bsr3d for the 3-D searches (those config
    bsr3d.searches lists, and a search of a 3-D figure the config does not list: a user's own,
    asked for by its file), else bsr."""
    if name in config["bsr3d"]["searches"] or search_dimensions(name) == 3:
        return config["bsr3d"]
    return config["bsr"]


def bsr_seeds(name):
    """The seeds of a search: its spec's 'seeds' line, the first config bsr.seeds (bsr3d.seeds
    for a 3-D search) of them if that is set (a reduced budget)."""
    seeds = list(parsed_spec(f"specs/bsr/{name}.bsr").seeds)
    limit = bsr_settings(name)["seeds"]
    return seeds if limit is None else seeds[:limit]


def bsr_chain(name):
    """The search a 3-D search continues (its 'chain' line), or None. A chain line naming no
    spec stops the DAG at that line (not at the missing file's line 1)."""
    from mosys.parsing.tokens import location

    spec = parsed_spec(f"specs/bsr/{name}.bsr")
    if not spec.chain:
        return None
    if not Path(f"specs/bsr/{spec.chain}.bsr").is_file():
        raise WorkflowError(
            f"{location(spec.path, spec.tokens['chain'])}: expected the name of a search in"
            f" specs/bsr/ to continue, found {spec.chain!r} (specs/bsr/{spec.chain}.bsr does"
            " not exist)"
        )
    return spec.chain


def check_chains_in_order():
    """A chain of searches in the config (bsr3d.motions, bsr3d.targets.chain) lists each search
    after the one it continues (its spec's chain line): the plot and the targets table refuse
    it otherwise, but only once every search of it has run (half an hour at the paper's
    budgets)."""
    chains = [(f"bsr3d.motions.{motion}", chain) for motion, chain in config["bsr3d"]["motions"].items()]
    chains.append(("bsr3d.targets.chain", config["bsr3d"]["targets"]["chain"]))
    for key, chain in chains:
        for before, search in zip(chain, chain[1:]):
            continued = bsr_chain(search)
            if continued != before:
                continues = (f"continues {continued} (its spec's chain line)" if continued
                             else "continues no search (its spec has no chain line)")
                raise WorkflowError(
                    f"config {key}: {search} {continues}, so it cannot follow {before}: list a"
                    " chain's searches in order, each after the one it continues"
                )


check_chains_in_order()


@functools.cache
def search_dimensions(name):
    """2 or 3, the dimensions of a search's figure; None where its figure spec is missing, does
    not parse or is a vehicle (the search's own job says why)."""
    from mosys.parsing.figure import parse_figure_spec
    from mosys.parsing.tokens import SpecError

    figure = parsed_spec(f"specs/bsr/{name}.bsr").figure
    try:
        return getattr(parse_figure_spec(f"specs/figures/{figure}.fig"), "dimensions", None)
    except (SpecError, OSError):
        return None


# The dimensions of the searches a config key (or a key of the map under it) lists; the budgets'
# lists and Figures 7 and 8 (bsr3d.kinds, bsr3d.variability: learning curves, 2-D too) take either.
SEARCH_DIMENSIONS = {"bsr.searches": 2, "composite.robustness": 2, "bsr3d.searches": 3,
                     "bsr3d.motions": 3, "bsr3d.targets": 3}


def check_dimensions():
    """The config's lists of 2-D searches hold 2-D ones and those of 3-D searches 3-D ones: the
    2-D table, plots and composite refuse a 3-D result and the 3-D ones a 2-D result, but only
    once the search has run."""
    for key, names in configured_searches():
        wanted = SEARCH_DIMENSIONS.get(".".join(key.split(".")[:2]))  # bsr3d.motions.rex: 3
        if wanted is None:
            continue
        for name in names:
            found = search_dimensions(name)
            if found is not None and found != wanted:
                figure = parsed_spec(f"specs/bsr/{name}.bsr").figure
                raise WorkflowError(
                    f"config {key}: {name} is a search of the {found}-D figure {figure}"
                    f" (specs/bsr/{name}.bsr); {key} takes searches of {wanted}-D figures"
                )


check_dimensions()


def bsr_chain_results(wildcards):
    """The result files of the search this one continues: its job waits for them, and editing
    that search's spec reruns this one too."""
    chained = bsr_chain(wildcards.name)
    return [] if chained is None else [f"results/bsr/{chained}/seed{seed}.h5"
                                       for seed in bsr_seeds(chained)]


def bsr_chain_option(wildcards, input):
    """'--chain FILES' for a search that continues another, else nothing."""
    return "--chain " + " ".join(input.chain) if input.chain else ""


def bsr_seed_results(wildcards):
    return [f"results/bsr/{wildcards.name}/seed{seed}.h5" for seed in bsr_seeds(wildcards.name)]


def bsr_all_results():
    return [f"results/bsr/{name}/seed{seed}.h5"
            for name in config["bsr"]["searches"] for seed in bsr_seeds(name)]


def bsr_figure_spec(wildcards):
    """The figure spec a search names in its 'figure' line."""
    return [f"specs/figures/{parsed_spec(f'specs/bsr/{wildcards.name}.bsr').figure}.fig"]


def bsr_full_budget(name):
    """Whether a search runs at its spec's own G: no cap is set, or the config exempts it."""
    settings = bsr_settings(name)
    return settings["generations"] is None or name in settings["full_budget"]


def bsr_generations_option(wildcards):
    """'--generations G' when the config caps this search's generations, else nothing."""
    if bsr_full_budget(wildcards.name):
        return ""
    return f"--generations {bsr_settings(wildcards.name)['generations']}"


def bsr_budget(wildcards):
    """The budget a search's result is labelled with: the config's, or 'paper' for a search
    the config exempts from its cap; 'custom' for one capped under the config's name 'paper'
    (config.yaml's, with generations given by --config or a --configfile that names no budget
    of its own), as mosys bsr-search labels a --generations without --budget: a G of 20 is not
    the paper's."""
    exempt = (bsr_settings(wildcards.name)["generations"] is not None
              and bsr_full_budget(wildcards.name))
    if exempt:
        return "paper"
    if not bsr_full_budget(wildcards.name) and config["budget"] == "paper":
        return "custom"
    return config["budget"]


def bsr_table_targets():
    return ["results/tables/bsr_runs.csv", "results/tables/bsr_runs.md"]


def bsr_targets():
    plots = [f"results/plots/bsr/{name}/{plot}" for name in config["bsr"]["searches"]
             for plot in ("learning.png", "filmstrip.png", "motion.gif")]
    return bsr_all_results() + plots + ["results/plots/bsr/learning_curves.png"] + bsr_table_targets()


def bsr3d_results(*names):
    """Every seed's result file of the given 3-D searches (all of them if none given)."""
    return [f"results/bsr/{name}/seed{seed}.h5"
            for name in (names or config["bsr3d"]["searches"]) for seed in bsr_seeds(name)]


def bsr3d_motion_searches(motion):
    """The chain of searches a 3-D motion draws, in order: a motion of config bsr3d.motions, or
    else a search of its own (specs/bsr/MOTION.bsr) with the searches its 'chain' lines
    continue, so that a user's spec needs no registering."""
    motions = config["bsr3d"]["motions"]
    if motion in motions:
        return motions[motion]
    if not Path(f"specs/bsr/{motion}.bsr").is_file():
        raise WorkflowError(
            f"results/plots/bsr3d/{motion}/: expected a motion of config bsr3d.motions"
            f" ({', '.join(motions)}) or a search spec, found {motion!r}"
            f" (specs/bsr/{motion}.bsr does not exist)"
        )
    chain = [motion]
    while (continued := bsr_chain(chain[0])) is not None:
        if continued in chain:
            raise WorkflowError(
                f"specs/bsr/{chain[0]}.bsr: its chain lines loop ({' -> '.join([continued, *chain])})"
            )
        chain.insert(0, continued)
    return chain


def bsr3d_view(wildcards):
    """A 3-D motion's filmstrip and GIF camera as `mosys plot bsr3d` takes it (config
    bsr3d.cameras; '' where none is set: the plot chooses), its options in a fixed order."""
    camera = config["bsr3d"]["cameras"].get(wildcards.motion) or {}
    return "".join(f" --{name} {camera[name]}" for name in sorted(camera) if camera[name] is not None)


def bsr3d_motion_results(wildcards):
    """The result files of a 3-D motion's chain of searches, in order."""
    return bsr3d_results(*bsr3d_motion_searches(wildcards.motion))


def bsr3d_table_targets():
    return ["results/tables/bsr3d_runs.csv", "results/tables/bsr3d_runs.md",
            "results/tables/bsr3d_targets.csv", "results/tables/bsr3d_targets.md"]


def bsr3d_target_roles(wildcards):
    """The bsr3d-targets options: which search plays which part (config bsr3d.targets)."""
    roles = config["bsr3d"]["targets"]
    return (f"--bound {roles['bound']} --chain {' '.join(roles['chain'])}"
            f" --walk {roles['walk']} --time-walk {roles['time_walk']}")


def bsr3d_targets():
    plots = [f"results/plots/bsr3d/{motion}/{plot}" for motion in config["bsr3d"]["motions"]
             for plot in ("filmstrip.png", "motion.gif", "rest.png")]
    learning = [f"results/plots/bsr3d/{name}/learning.png" for name in config["bsr3d"]["searches"]]
    figures = ["results/plots/bsr3d/learning_kinds.png", "results/plots/bsr3d/seeds.png"]
    return bsr3d_results() + plots + learning + figures + bsr3d_table_targets()


def composite_searches(name):
    """The BSR searches a composite script's phases name (controller=SEARCH), in order."""
    phases = parsed_spec(f"specs/composite/{name}.comp").phases
    return list(dict.fromkeys(phase.controller for phase in phases))


def composite_inputs(wildcards):
    """A composite search's inputs: the script, its figure, its phases' search specs (the first
    one's start pose starts the motion) and their seed files. A phase whose search has no spec,
    or one of another figure, stops the DAG with mosys's message, before any search runs."""
    from mosys.composite.phase_searches import check_phase_searches
    from mosys.parsing.tokens import SpecError

    script = parsed_spec(f"specs/composite/{wildcards.name}.comp")
    try:
        check_phase_searches(script, "specs/bsr")
    except SpecError as error:
        raise WorkflowError(str(error)) from None
    searches = composite_searches(wildcards.name)
    figure = script.figure
    return {
        "script": f"specs/composite/{wildcards.name}.comp",
        "figure": [f"specs/figures/{figure}.fig"],
        "specs": [f"specs/bsr/{search}.bsr" for search in searches],
        "controllers": [f"results/bsr/{search}/seed{seed}.h5"
                        for search in searches for seed in bsr_seeds(search)],
    }


def composite_search_options(wildcards):
    """'--q Q --g G --h H' for the sizes the config sets (null: the script's own)."""
    return " ".join(f"--{key} {config['composite'][key]}" for key in ("q", "g", "h")
                    if config["composite"][key] is not None)


def robustness_pairs():
    return list(config["composite"]["robustness"].items())


def robustness_results():
    return [f"results/bsr/{search}/seed{seed}.h5"
            for pair in robustness_pairs() for search in pair for seed in bsr_seeds(search)]


def composite_table_targets():
    return [f"results/tables/{table}.{ext}" for table in ("composite", "composite_robustness")
            for ext in ("csv", "md")]


def composite_targets():
    scripts = config["composite"]["scripts"]
    plots = [f"results/plots/composite/{name}/{plot}" for name in scripts
             for plot in ("filmstrips.png", "search.png", "motion.gif")]
    return ([f"results/composite/{name}.h5" for name in scripts] + plots
            + composite_table_targets())
