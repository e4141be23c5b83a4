# Config validation and the only helpers of the workflow: target lists, the package modules each
# stage depends on, and the light look-ups of spec lines that decide a rule's inputs.
import re
from pathlib import Path

from snakemake.utils import validate


validate(config, "../schemas/config.schema.yaml")

PACKAGE = Path("src/mosys")
STAGE_MODULES = {
    "parsing": ["parsing/tokens.py"],
    "dynamics": ["parsing/figure.py", "parsing/vehicle.py", "dynamics"],
    "ssc": ["parsing/controller.py", "kernels/dp.py", "kernels/integrate.py",
            "kernels/figure_state.py", "kernels/interpolate.py", "kernels/geometry.py",
            "ssc/generate.py", "ssc/grid.py", "ssc/obstacles.py", "io/controller_table.py",
            "dynamics/load.py"],
    "scripts": ["parsing/script.py", "animation.py", "pipeline.py", "ssc/controller.py",
                "ssc/parking.py", "kernels/simulate.py", "kernels/motion.py",
                "io/trajectory.py", "io/start_grid.py", "dynamics/motion.py"],
    "plots": ["plots"],
    "tables": ["tables", "ssc/quality.py"],
}


def package_sources(*stages):
    """The package files a stage's output depends on (editing one rebuilds that stage)."""
    files = []
    for stage in ("parsing",) + stages:
        for entry in STAGE_MODULES[stage]:
            path = PACKAGE / entry
            files += sorted(str(p) for p in path.rglob("*.py")) if path.is_dir() else [str(path)]
    return files


def spec_words(path, keyword):
    """Every line of a spec that starts with keyword, as its list of words (comments removed);
    a missing file gives none, and mosys itself reports the error."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return []
    lines = (line.split("#", 1)[0].split() for line in text.splitlines())
    return [words for words in lines if words and words[0] == keyword]


def controller_dynamics(wildcards):
    """The generated dynamics a controller spec names in its 'dyn' line."""
    spec = f"specs/controllers/{wildcards.group}/{wildcards.name}.ssc"
    return [f"results/dynamics/{words[1]}.py" for words in spec_words(spec, "dyn")[:1]
            if len(words) > 1 and re.fullmatch(r"\w+", words[1])]


def table_controller(reference):
    """The controller a 'swapcon' table reference names: conX.ctab -> X, X -> X."""
    match = re.fullmatch(r"con(\w+)\.ctab", reference)
    return match.group(1) if match else reference


def script_group(script):
    """The controller directory a script draws on: the configured one for the pendulum script
    and the car's scripts, else the script's own name."""
    if script == config["pendulum"]["script"]:
        return config["pendulum"]["group"]
    if script in config["car"]["scripts"]:
        return config["car"]["group"]
    return script


def script_inputs(wildcards):
    """The tables and dynamics a script needs (from its 'swapcon' lines)."""
    group = script_group(wildcards.script)
    words = spec_words(f"specs/scripts/{wildcards.script}.anim", "swapcon")
    names = dict.fromkeys(table_controller(w[2]) for w in words if len(w) > 2)
    tables = [f"results/controllers/{group}/{name}.h5" for name in names
              if re.fullmatch(r"\w+", name)]
    figures = set()
    for name in names:
        for words in spec_words(f"specs/controllers/{group}/{name}.ssc", "dyn")[:1]:
            if len(words) > 1:
                figures.add(f"results/dynamics/{words[1]}.py")
    return tables + sorted(figures)


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
        + [f"results/plots/{group}/{script}_path.png", f"results/plots/{group}/{script}.gif"]
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
           "results/plots/car/start_map.png"]
        + car_table_targets()
    )
