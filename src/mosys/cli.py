"""The ``mosys`` command line: argument parsing and exit codes, nothing else.

Exit codes: 0 success; 2 a bad spec or input (a ``file:line:column: expected ..., found ...``
message, no traceback, no output file); 1 any other failure.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def _compile(args: argparse.Namespace) -> None:
    from mosys.dynamics.compile import compile_figure

    compile_figure(args.spec, args.output)


def _dp(args: argparse.Namespace) -> None:
    from mosys.dynamics.load import figure_dynamics
    from mosys.parsing.controller import parse_controller_spec
    from mosys.ssc.generate import generate_controller

    spec = parse_controller_spec(args.spec)
    table = generate_controller(
        spec,
        figure_dynamics(spec.figure, args.dynamics_dir, spec.error, spec.figure_token),
        args.output,
        tolerance=args.tol,
        max_iterations=args.max_iterations,
        quiet=args.quiet,
    )
    attrs = table.attrs
    print(
        f"{args.output}: {table.value.size} nodes, {attrs['iterations']} sweeps, residual "
        f"{attrs['residual']:.3g} s, {attrs['unreachable_nodes']} unreachable, "
        f"{attrs['generation_seconds']:.3f} s"
    )


def _run(args: argparse.Namespace) -> None:
    from mosys.animation.trajectory_file import run_animation_script

    run_animation_script(
        args.script, args.controllers, args.dynamics_dir, args.output, args.dt, args.motor_dir
    )


def _plot_controller(args: argparse.Namespace) -> None:
    from mosys.plots.pendulum import plot_portrait, plot_torque

    if args.portrait:
        from mosys.dynamics.load import load_dynamics

        plot_portrait(args.table, load_dynamics(args.dynamics), args.portrait)
    if args.torque:
        plot_torque(args.table, args.torque)


def _plot_script(args: argparse.Namespace) -> None:
    from mosys.plots.pendulum import plot_script, write_script_gif

    if args.path:
        plot_script(args.trajectory, args.tables, args.path)
    if args.gif:
        write_script_gif(args.trajectory, args.gif)


def _table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.pendulum import write_pendulum_table

    write_pendulum_table(args.controllers, args.dynamics, args.csv, args.md, args.budget)


def _starts(args: argparse.Namespace) -> None:
    import itertools

    import numpy as np

    from mosys.dynamics.load import load_dynamics
    from mosys.io.start_grid import write_start_grid
    from mosys.ssc.controller import Controller
    from mosys.ssc.parking import evaluate_starts

    controller = Controller.load(args.table, load_dynamics(args.dynamics))
    axes = {
        "x": np.linspace(*args.x[:2], int(args.x[2])),
        "y": np.linspace(*args.y[:2], int(args.y[2])),
        "heading": np.array(args.heading),
        "steer": np.array(args.steer),
        "speed": np.array([0.0]),
    }
    order = controller.state_order
    starts = np.array(list(itertools.product(*(axes[name] for name in order))))
    write_start_grid(args.output, evaluate_starts(controller, starts, args.seconds, args.dt))


def _plot_car(args: argparse.Namespace) -> None:
    from mosys.plots.car import plot_parking_frames, plot_success_map, write_parking_gif

    if args.frames:
        plot_parking_frames(args.trajectories, args.frames)
    if args.gif:
        write_parking_gif(args.trajectories[0], args.gif)
    if args.map:
        plot_success_map(args.map[0], args.map[1])


def _car_table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.car import write_car_table

    write_car_table(args.table, args.starts, args.trajectories, args.csv, args.md, args.budget)


def _plot_luxo(args: argparse.Namespace) -> None:
    from mosys.plots.luxo import plot_motion_strip, plot_torques_and_forces, write_show_gif

    if args.strip:
        plot_motion_strip(args.trajectory, args.strip, args.motion)
    if args.forces:
        plot_torques_and_forces(args.trajectory, args.forces)
    if args.gif:
        write_show_gif(args.trajectory, args.gif)


def _plot_bsr(args: argparse.Namespace) -> None:
    from mosys.plots import bsr

    if args.learning:
        bsr.plot_learning(args.results, args.learning)
    if args.filmstrip or args.gif:
        best = bsr.best_result_path(args.results)  # highest best_fitness, ties to lowest seed
        if args.filmstrip:
            bsr.plot_filmstrip(best, args.filmstrip)
        if args.gif:
            bsr.write_motion_gif(best, args.gif)


def _plot_composite(args: argparse.Namespace) -> None:
    from mosys.plots import composite

    if args.filmstrips:
        composite.plot_filmstrips(args.result, args.filmstrips)
    if args.search:
        composite.plot_search(args.result, args.search)
    if args.gif:
        composite.write_composite_gif(args.result, args.gif)


def _plot_bsr_learning(args: argparse.Namespace) -> None:
    from mosys.plots import bsr

    bsr.plot_learning_comparison(bsr.group_by_search(args.results), args.output)


def _bsr_search(args: argparse.Namespace) -> None:
    from mosys.bsr.result_file import search_to_file

    outcome = search_to_file(
        args.spec,
        args.figures,
        args.seed,
        args.output,
        args.generations,
        args.budget,
        args.threads,
    )
    print(
        f"{args.output}: best fitness {outcome.fitness:.3f} after {outcome.evaluations[-1]} "
        f"evaluations in {outcome.wall_seconds:.1f} s ({outcome.steps_per_second:.3g} steps/s)"
    )


def _composite_controller_files(args: argparse.Namespace, script) -> dict:
    """The BSR result files the script may use: the ``--controllers`` given (grouped by their
    directory, the search's name), else every seed file under ``--bsr-results``."""
    from mosys.composite.session import files_by_search, find_controller_files

    if args.controllers is None:
        return find_controller_files(script, args.bsr_results)
    return files_by_search(args.controllers)


def _composite(args: argparse.Namespace) -> None:
    from mosys.composite.result_file import composite_to_file
    from mosys.parsing.composite import parse_composite_script

    script = parse_composite_script(args.script)
    sizes = {key: getattr(args, key) for key in ("q", "g", "h") if getattr(args, key)}
    found = composite_to_file(
        args.script,
        _composite_controller_files(args, script),
        args.output,
        args.figures,
        args.bsr_specs,
        sizes,
        args.budget,
    )
    print(
        f"{args.output}: total {found.guess_score:.3f} -> {found.score:.3f}, durations "
        f"{found.guess_durations.tolist()} -> {found.durations.tolist()} ticks, "
        f"{found.simulations} simulations"
    )


def _edit(args: argparse.Namespace) -> None:
    from mosys.editor.concatenation import run_editor

    run_editor(args.script, args.bsr_results, args.figures, args.bsr_specs)


def _composite_table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.composite import write_composite_table

    write_composite_table(args.results, args.csv, args.md)


def _robustness_table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.robustness import write_robustness_table

    write_robustness_table(
        [tuple(pair) for pair in args.pair],
        args.results,
        args.csv,
        args.md,
        args.bsr_specs,
        args.figures,
    )


def _bsr_table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.bsr import write_bsr_table

    write_bsr_table(args.results, args.csv, args.md)


def _luxo_table(args: argparse.Namespace) -> None:
    from mosys.paper_tables.luxo import write_luxo_table

    write_luxo_table(args.trajectory, args.landing, args.csv, args.md, args.budget)


def _index(args: argparse.Namespace) -> None:
    from mosys.io.atomic import write_text_atomically

    missing = [path for path in args.inputs if not Path(path).exists()]
    if missing:
        raise FileNotFoundError(f"cannot index missing files: {', '.join(missing)}")
    write_text_atomically(args.output, "".join(f"{path}\n" for path in args.inputs))


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="mosys", description=__doc__.splitlines()[0])
    verbs = parser.add_subparsers(dest="verb", required=True)

    compile_ = verbs.add_parser("compile", help="figure spec (.fig) -> generated dynamics module")
    compile_.add_argument("spec")
    compile_.add_argument("-o", "--output", required=True)
    compile_.set_defaults(handler=_compile)

    dp = verbs.add_parser("dp", help="controller spec (.ssc) -> controller table (.h5)")
    dp.add_argument("spec")
    dp.add_argument("--dynamics-dir", default="results/dynamics", help="generated dynamics")
    dp.add_argument("-o", "--output", required=True)
    dp.add_argument("--tol", type=float, default=None, help="override the spec's tolerance, s")
    dp.add_argument("--max-iterations", type=int, default=None)
    dp.add_argument("--quiet", action="store_true")
    dp.set_defaults(handler=_dp)

    run = verbs.add_parser("run", help="animation script (.anim) -> trajectory (.h5)")
    run.add_argument("script")
    run.add_argument("--controllers", required=True, help="directory of controller tables")
    run.add_argument("--dynamics-dir", default="results/dynamics", help="generated dynamics")
    run.add_argument(
        "--motor-dir", default="specs/motor", help="motor programs: DIR/FIGURE/NAME.mot"
    )
    run.add_argument("--dt", type=float, default=0.001, help="simulator step, s")
    run.add_argument("-o", "--output", required=True)
    run.set_defaults(handler=_run)

    plot = verbs.add_parser("plot", help="plots of controllers and motions").add_subparsers(
        dest="kind", required=True
    )
    controller = plot.add_parser("controller", help="a controller's portrait and torque map")
    controller.add_argument("table", help="controller table (.h5)")
    controller.add_argument("--dynamics", help="generated dynamics module (for --portrait)")
    controller.add_argument("--portrait", help="state-space portrait PNG (Figure 14 style)")
    controller.add_argument("--torque", help="torque-table heat map PNG")
    controller.set_defaults(handler=_plot_controller)
    script = plot.add_parser("script", help="a script's path (Figure 16 style) and its GIF")
    script.add_argument("trajectory")
    script.add_argument("tables", nargs="*", help="the controller tables (their destinations)")
    script.add_argument("--path", help="state-space path PNG")
    script.add_argument("--gif", help="animated GIF of the trajectory's figure_motion")
    script.set_defaults(handler=_plot_script)

    table = verbs.add_parser("table", help="the Figure 13 table of the pendulum controllers")
    table.add_argument("controllers", nargs="+")
    table.add_argument("--dynamics", required=True)
    table.add_argument("--csv", required=True)
    table.add_argument("--md", required=True)
    table.add_argument("--budget", default="paper", help="name of the config that built it")
    table.set_defaults(handler=_table)

    starts = verbs.add_parser("starts", help="a car controller from a grid of start states")
    starts.add_argument("table", help="controller table (.h5)")
    starts.add_argument("--dynamics", required=True, help="generated dynamics module")
    for axis, unit in (("x", "m"), ("y", "m")):
        starts.add_argument(
            f"--{axis}",
            nargs=3,
            type=float,
            required=True,
            metavar=("MIN", "MAX", "COUNT"),
            help=f"start {axis} values, {unit}",
        )
    starts.add_argument("--heading", nargs="+", type=float, default=[0.0], help="deg")
    starts.add_argument("--steer", nargs="+", type=float, default=[0.0], help="deg")
    starts.add_argument("--seconds", type=float, default=20.0, help="simulated time per start")
    starts.add_argument("--dt", type=float, default=0.01, help="simulator step, s")
    starts.add_argument("-o", "--output", required=True)
    starts.set_defaults(handler=_starts)

    car = plot.add_parser("car", help="car frames (Figure 19 style), a GIF, the success map")
    car.add_argument("trajectories", nargs="*", help="car trajectories (.h5)")
    car.add_argument("--frames", help="PNG: one panel per trajectory, the car every 0.3 s")
    car.add_argument("--gif", help="animated GIF of the first trajectory")
    car.add_argument("--map", nargs=2, metavar=("START_GRID", "PNG"), help="success map")
    car.set_defaults(handler=_plot_car)

    car_table = verbs.add_parser("car-table", help="the car controller's table")
    car_table.add_argument("table", help="controller table (.h5)")
    car_table.add_argument("--starts", required=True, help="start grid (.h5, mosys starts)")
    car_table.add_argument(
        "--trajectories", nargs="+", required=True, help="the Figure 19 trajectories (.h5)"
    )
    car_table.add_argument("--csv", required=True)
    car_table.add_argument("--md", required=True)
    car_table.add_argument("--budget", default="paper", help="name of the config that built it")
    car_table.set_defaults(handler=_car_table)

    luxo = plot.add_parser("luxo", help="Luxo: a motion's strip (Figure 22), forces, a GIF")
    luxo.add_argument("trajectory", help="a trajectory of Luxo's figure (.h5)")
    luxo.add_argument("--strip", help="PNG: the lamp every few frames of one motion")
    luxo.add_argument("--motion", default="backflip", help="the motion the strip draws")
    luxo.add_argument("--forces", help="PNG: joint torques and contact forces over time")
    luxo.add_argument("--gif", help="animated GIF of the whole trajectory, terrain drawn")
    luxo.set_defaults(handler=_plot_luxo)

    bsr_plot = plot.add_parser("bsr", help="a BSR search: learning curves, filmstrip, GIF")
    bsr_plot.add_argument("results", nargs="+", help="all seed files of one search (.h5)")
    bsr_plot.add_argument("--learning", help="PNG: best fitness per seed (Figure 8 style)")
    bsr_plot.add_argument("--filmstrip", help="PNG: the best seed's motion (Figures 9-12 style)")
    bsr_plot.add_argument("--gif", help="animated GIF of the best seed's motion")
    bsr_plot.set_defaults(handler=_plot_bsr)
    bsr_learning = plot.add_parser(
        "bsr-learning", help="learning curves of BSR searches compared (Figure 7 style)"
    )
    bsr_learning.add_argument(
        "results", nargs="+", help="seed files (.h5) of one or more searches, grouped by name"
    )
    bsr_learning.add_argument("-o", "--output", required=True, help="PNG")
    bsr_learning.set_defaults(handler=_plot_bsr_learning)

    composite_plot = plot.add_parser(
        "composite", help="a composite motion: filmstrips before/after, the search, a GIF"
    )
    composite_plot.add_argument("result", help="results/composite/NAME.h5")
    composite_plot.add_argument("--filmstrips", help="PNG: before and after (Figures 13-14 style)")
    composite_plot.add_argument("--search", help="PNG: the best total after each generation")
    composite_plot.add_argument("--gif", help="animated GIF of the refined motion")
    composite_plot.set_defaults(handler=_plot_composite)

    search = verbs.add_parser("bsr-search", help="BSR search spec (.bsr) -> result (.h5)")
    search.add_argument("spec", help="the search spec (.bsr)")
    search.add_argument("--seed", type=int, required=True, help="one of the spec's seeds")
    search.add_argument("--figures", default="specs/figures", help="where NAME.fig lives")
    search.add_argument("--generations", type=int, help="override the spec's G (a budget)")
    search.add_argument("--budget", default="paper", help="name of the config that built it")
    search.add_argument("--threads", type=int, help="threads that run the population")
    search.add_argument("-o", "--output", required=True)
    search.set_defaults(handler=_bsr_search)

    composite = verbs.add_parser(
        "composite", help="composite script (.comp) -> refined transition points (.h5)"
    )
    composite.add_argument("script", help="the composite-motion script (.comp)")
    composite.add_argument(
        "--controllers",
        nargs="*",
        help="BSR result files (SEARCH/seedK.h5) the phases may use (the pipeline lists them)",
    )
    composite.add_argument(
        "--bsr-results", default="results/bsr", help="where SEARCH/seedK.h5 live (no --controllers)"
    )
    composite.add_argument("--figures", default="specs/figures", help="where NAME.fig lives")
    composite.add_argument("--bsr-specs", default="specs/bsr", help="where SEARCH.bsr lives")
    for key, what in (("q", "Q arrays"), ("g", "G generations"), ("h", "H mutations")):
        composite.add_argument(f"--{key}", type=int, help=f"override the script's {what}")
    composite.add_argument("--budget", default="paper", help="name of the config that built it")
    composite.add_argument("-o", "--output", required=True)
    composite.set_defaults(handler=_composite)

    edit = verbs.add_parser(
        "edit", help="the concatenation editor: a slider per phase of a script (.comp)"
    )
    edit.add_argument("script", help="the composite-motion script (.comp); Save rewrites it")
    edit.add_argument("--bsr-results", default="results/bsr", help="where SEARCH/seedK.h5 live")
    edit.add_argument("--figures", default="specs/figures", help="where NAME.fig lives")
    edit.add_argument("--bsr-specs", default="specs/bsr", help="where SEARCH.bsr lives")
    edit.set_defaults(handler=_edit)

    composite_table = verbs.add_parser("composite-table", help="the composite-motion table")
    composite_table.add_argument("results", nargs="+", help="composite results (.h5)")
    composite_table.add_argument("--csv", required=True)
    composite_table.add_argument("--md", required=True)
    composite_table.set_defaults(handler=_composite_table)

    robustness = verbs.add_parser(
        "robustness-table", help="robust BSR searches against their plain twins"
    )
    robustness.add_argument("results", nargs="+", help="seed files (SEARCH/seedK.h5) of both")
    robustness.add_argument(
        "--pair",
        nargs=2,
        action="append",
        required=True,
        metavar=("ROBUST", "PLAIN"),
        help="a robust search and its plain twin (search names); repeat for more",
    )
    robustness.add_argument("--bsr-specs", default="specs/bsr", help="where SEARCH.bsr lives")
    robustness.add_argument("--figures", default="specs/figures", help="where NAME.fig lives")
    robustness.add_argument("--csv", required=True)
    robustness.add_argument("--md", required=True)
    robustness.set_defaults(handler=_robustness_table)

    bsr_table = verbs.add_parser("bsr-table", help="the BSR runs table")
    bsr_table.add_argument("results", nargs="+", help="seed files (.h5) of the searches")
    bsr_table.add_argument("--csv", required=True)
    bsr_table.add_argument("--md", required=True)
    bsr_table.set_defaults(handler=_bsr_table)

    luxo_table = verbs.add_parser("luxo-table", help="Luxo's motions table")
    luxo_table.add_argument("trajectory", help="a trajectory of Luxo's show (.h5)")
    luxo_table.add_argument(
        "--landing", required=True, help="the landing controller's table (its dest: standing)"
    )
    luxo_table.add_argument("--csv", required=True)
    luxo_table.add_argument("--md", required=True)
    luxo_table.add_argument("--budget", default="paper", help="name of the config that built it")
    luxo_table.set_defaults(handler=_luxo_table)

    index = verbs.add_parser("index", help="write an aggregate target: the list of its files")
    index.add_argument("inputs", nargs="*")
    index.add_argument("-o", "--output", required=True)
    index.set_defaults(handler=_index)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.verb == "plot" and args.kind == "controller":
        if not (args.portrait or args.torque):
            parser.error("plot controller: give --portrait and/or --torque")
        if args.portrait and not args.dynamics:
            parser.error("plot controller: --portrait needs --dynamics")
    if args.verb == "plot" and args.kind == "script" and not (args.path or args.gif):
        parser.error("plot script: give --path and/or --gif")
    if args.verb == "plot" and args.kind == "car":
        if not (args.frames or args.gif or args.map):
            parser.error("plot car: give --frames, --gif and/or --map")
        if (args.frames or args.gif) and not args.trajectories:
            parser.error("plot car: --frames and --gif need trajectories")
    if (
        args.verb == "plot"
        and args.kind == "bsr"
        and not (args.learning or args.filmstrip or args.gif)
    ):
        parser.error("plot bsr: give --learning, --filmstrip and/or --gif")
    if (
        args.verb == "plot"
        and args.kind == "composite"
        and not (args.filmstrips or args.search or args.gif)
    ):
        parser.error("plot composite: give --filmstrips, --search and/or --gif")
    from mosys.errors import InputError
    from mosys.parsing.tokens import SpecError

    try:
        args.handler(args)
    except SpecError as error:
        print(error, file=sys.stderr)  # file:line:column: first, as compilers do
        return 2
    except (OSError, InputError) as error:  # a missing, unreadable or corrupt input file
        print(f"mosys: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
