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
    from mosys.pipeline import run_animation_script

    run_animation_script(args.script, args.controllers, args.dynamics_dir, args.output, args.dt)


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
    from mosys.tables.pendulum import write_pendulum_table

    write_pendulum_table(args.controllers, args.dynamics, args.csv, args.md, args.budget)


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
    run.add_argument("--dt", type=float, default=0.001, help="simulator step, s")
    run.add_argument("-o", "--output", required=True)
    run.set_defaults(handler=_run)

    plot = verbs.add_parser("plot", help="pendulum plots").add_subparsers(
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
