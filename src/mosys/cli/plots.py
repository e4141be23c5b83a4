"""``mosys plot KIND``: the drawings of controllers and motions, one kind per figure family."""

from __future__ import annotations

import argparse

from mosys.cli.verb import GIF, PLOT, Family, InputThenOutput, OutputPath, Verb


def _controller_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("table", help="controller table (.h5)")
    parser.add_argument("--dynamics", help="generated dynamics module (for --portrait)")
    parser.add_argument(
        "--portrait", type=OutputPath(*PLOT), help="state-space portrait PNG (Figure 14 style)"
    )
    parser.add_argument("--torque", type=OutputPath(*PLOT), help="torque-table heat map PNG")


def _controller_check(args: argparse.Namespace) -> str | None:
    if not (args.portrait or args.torque):
        return "give --portrait and/or --torque"
    if args.portrait and not args.dynamics:
        return "--portrait needs --dynamics"
    return None


def _controller(args: argparse.Namespace) -> None:
    from mosys.plots.controller import plot_portrait, plot_torque

    if args.portrait:
        from mosys.dynamics.load import load_dynamics

        plot_portrait(args.table, load_dynamics(args.dynamics), args.portrait)
    if args.torque:
        plot_torque(args.table, args.torque)


def _script_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("trajectory", help="trajectory (.h5)")
    parser.add_argument("tables", nargs="*", help="the controller tables (their destinations)")
    parser.add_argument("--path", type=OutputPath(*PLOT), help="state-space path PNG")
    parser.add_argument(
        "--gif", type=OutputPath(*GIF), help="animated GIF of the trajectory's figure_motion"
    )


def _script_check(args: argparse.Namespace) -> str | None:
    if not (args.path or args.gif):
        return "give --path and/or --gif"
    return None


def _script(args: argparse.Namespace) -> None:
    from mosys.plots.script import plot_script, write_script_gif

    if args.path:
        plot_script(args.trajectory, args.tables, args.path)
    if args.gif:
        write_script_gif(args.trajectory, args.gif)


def _controls_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("trajectories", nargs="+", help="trajectories (.h5) to compare")
    parser.add_argument("--control", help="the control drawn (default: the first)")
    parser.add_argument("-o", "--output", required=True, type=OutputPath(*PLOT), help="PNG")


def _controls_check(args: argparse.Namespace) -> str | None:
    if args.control is not None and not args.control.strip():
        return "--control must name a control (default: the first)"
    return None


def _controls(args: argparse.Namespace) -> None:
    from mosys.plots.controls import plot_controls

    plot_controls(args.trajectories, args.output, args.control)


def _free_swing_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--dynamics", required=True, help="generated dynamics of a 1-joint figure")
    parser.add_argument("-o", "--output", required=True, type=OutputPath(*PLOT), help="PNG")


def _free_swing(args: argparse.Namespace) -> None:
    from mosys.dynamics.load import load_dynamics
    from mosys.errors import InputError
    from mosys.plots.free_swing import free_swing_figure
    from mosys.plots.style import save_figure

    dynamics = load_dynamics(args.dynamics)
    try:
        figure = free_swing_figure(dynamics)
    except InputError as error:  # about the module: say which
        raise InputError(f"{args.dynamics}: {error}") from None
    save_figure(figure, args.output)


def _car_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("trajectories", nargs="*", help="car trajectories (.h5)")
    parser.add_argument(
        "--frames",
        type=OutputPath(*PLOT),
        help="PNG: one panel per trajectory, the car every 0.3 s",
    )
    parser.add_argument("--gif", type=OutputPath(*GIF), help="animated GIF of the first trajectory")
    parser.add_argument(
        "--map",
        action=InputThenOutput,
        suffixes=PLOT,
        metavar=("START_GRID", "PNG"),
        help="success map",
    )
    parser.add_argument(
        "--consistency",
        action=InputThenOutput,
        suffixes=PLOT,
        metavar=("START_GRID", "PNG"),
        help="parking time / cost-to-go of the starts that parked",
    )


def _car_check(args: argparse.Namespace) -> str | None:
    if not (args.frames or args.gif or args.map or args.consistency):
        return "give --frames, --gif, --map and/or --consistency"
    if (args.frames or args.gif) and not args.trajectories:
        return "--frames and --gif need trajectories"
    return None


def _car(args: argparse.Namespace) -> None:
    from mosys.plots.car import plot_parking_frames, write_parking_gif
    from mosys.plots.car_starts import plot_consistency, plot_success_map

    if args.frames:
        plot_parking_frames(args.trajectories, args.frames)
    if args.gif:
        write_parking_gif(args.trajectories[0], args.gif)
    if args.map:
        plot_success_map(args.map[0], args.map[1])
    if args.consistency:
        plot_consistency(args.consistency[0], args.consistency[1])


def _luxo_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("trajectory", help="a trajectory of Luxo's figure (.h5)")
    parser.add_argument(
        "--strip", type=OutputPath(*PLOT), help="PNG: the lamp every few frames of one motion"
    )
    parser.add_argument(
        "--motion",
        help="the motion (motor program) the strip draws: NAME its first run, NAME:K its K-th "
        "(default: the script's first motion)",
    )
    parser.add_argument(
        "--forces", type=OutputPath(*PLOT), help="PNG: joint torques and contact forces over time"
    )
    parser.add_argument(
        "--gif", type=OutputPath(*GIF), help="animated GIF of the whole trajectory, terrain drawn"
    )


def _luxo_check(args: argparse.Namespace) -> str | None:
    if not (args.strip or args.forces or args.gif):
        return "give --strip, --forces and/or --gif"
    if args.motion is not None and not args.strip:
        return "--motion names the motion --strip draws: give --strip too"
    return None


def _luxo(args: argparse.Namespace) -> None:
    from mosys.plots.luxo import plot_motion_strip, plot_torques_and_forces, write_show_gif

    if args.strip:
        plot_motion_strip(args.trajectory, args.strip, args.motion)
    if args.forces:
        plot_torques_and_forces(args.trajectory, args.forces)
    if args.gif:
        write_show_gif(args.trajectory, args.gif)


def _bsr_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("results", nargs="+", help="all seed files of one search (.h5)")
    parser.add_argument(
        "--learning", type=OutputPath(*PLOT), help="PNG: best fitness per seed (Figure 8 style)"
    )
    parser.add_argument(
        "--filmstrip",
        type=OutputPath(*PLOT),
        help="PNG: the best seed's motion (Figures 9-12 style)",
    )
    parser.add_argument(
        "--gif", type=OutputPath(*GIF), help="animated GIF of the best seed's motion"
    )


def _bsr_check(args: argparse.Namespace) -> str | None:
    if not (args.learning or args.filmstrip or args.gif):
        return "give --learning, --filmstrip and/or --gif"
    return None


def _bsr(args: argparse.Namespace) -> None:
    from mosys.plots import bsr, bsr_learning, bsr_results

    if args.learning:
        bsr_learning.plot_learning(args.results, args.learning)
    if args.filmstrip or args.gif:
        # the best recorded motion (nominal fitness), ties to the lowest seed
        best = bsr_results.best_result_path(args.results)
        if args.filmstrip:
            bsr.plot_filmstrip(best, args.filmstrip)
        if args.gif:
            bsr.write_motion_gif(best, args.gif)


def _bsr_learning_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "results", nargs="+", help="seed files (.h5) of one or more searches, grouped by name"
    )
    parser.add_argument("-o", "--output", required=True, type=OutputPath(*PLOT), help="PNG")


def _bsr_learning(args: argparse.Namespace) -> None:
    from mosys.plots import bsr_learning, bsr_results

    results = bsr_results.group_by_search(args.results)
    bsr_learning.plot_learning_comparison(results, args.output)


def _bsr3d_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "results",
        nargs="+",
        help="seed files (.h5) of one 3-D search, or of a chain's searches in order",
    )
    parser.add_argument(
        "--filmstrip", type=OutputPath(*PLOT), help="PNG: the best motion (Figures 15-17 style)"
    )
    parser.add_argument("--gif", type=OutputPath(*GIF), help="animated GIF of that motion")
    parser.add_argument(
        "--rest", type=OutputPath(*PLOT), help="PNG: the figure at rest, seen from four sides"
    )
    parser.add_argument(
        "--interval", type=float, help="seconds between the filmstrip's poses (default: chosen)"
    )
    parser.add_argument(
        "--azimuth",
        type=float,
        help="the filmstrip's and GIF's camera, deg round from the figure's right side towards "
        "its front (-180 to 180; default: chosen, 30 to 60)",
    )
    parser.add_argument(
        "--elevation", type=float, help="the camera's height, deg above the floor (0 to 90; 30)"
    )


def _bsr3d_check(args: argparse.Namespace) -> str | None:
    if not (args.filmstrip or args.gif or args.rest):
        return "give --filmstrip, --gif and/or --rest"
    if args.interval is not None and not 0 < args.interval < float("inf"):
        return f"--interval must be a positive number of seconds, got {args.interval}"
    if args.azimuth is not None and not -180 <= args.azimuth <= 180:
        return f"--azimuth must be between -180 and 180 deg, got {args.azimuth}"
    if args.elevation is not None and not 0 <= args.elevation <= 90:
        return f"--elevation must be between 0 and 90 deg, got {args.elevation}"
    return None


def _bsr3d(args: argparse.Namespace) -> None:
    from mosys.plots import bsr3d, figure_at_rest, scene3d

    # one file per search: the last search's best seed, before it the seeds it continues
    chain = bsr3d.chain_paths(args.results)
    elevation = scene3d.CAMERA_ELEVATION if args.elevation is None else args.elevation
    camera = None if args.azimuth is None else scene3d.Camera(args.azimuth, elevation)
    if args.filmstrip:
        bsr3d.plot_filmstrip(chain, args.filmstrip, args.interval, camera, elevation)
    if args.gif:
        bsr3d.write_motion_gif(chain, args.gif, camera=camera, elevation=elevation)
    if args.rest:
        figure_at_rest.plot_result_at_rest(chain[0], args.rest)


def _bsr3d_kinds_arguments(parser: argparse.ArgumentParser) -> None:
    for kind in ("time", "sense"):
        parser.add_argument(
            f"--{kind}",
            nargs="+",
            default=[],
            metavar="RESULT",
            help=f"seed files (.h5) of the {kind}-based search",
        )
    parser.add_argument("-o", "--output", required=True, type=OutputPath(*PLOT), help="PNG")
    parser.add_argument("--log-x", action="store_true", help="evaluations on a log axis")


def _bsr3d_kinds_check(args: argparse.Namespace) -> str | None:
    if not (args.time or args.sense):
        return "give --time and/or --sense result files"
    return None


def _bsr3d_kinds(args: argparse.Namespace) -> None:
    from mosys.plots import bsr3d_learning

    bsr3d_learning.plot_learning_kinds(args.time, args.sense, args.output, log_x=args.log_x)


def _bsr3d_seeds_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "results",
        nargs="+",
        help="all seed files of one search, or of a sense-based and a time-based search of one "
        "problem, drawn side by side (.h5)",
    )
    parser.add_argument("-o", "--output", required=True, type=OutputPath(*PLOT), help="PNG")


def _bsr3d_seeds(args: argparse.Namespace) -> None:
    from mosys.plots import bsr3d_learning

    bsr3d_learning.plot_seeds(args.results, args.output)


def _composite_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("result", help="results/composite/NAME.h5")
    parser.add_argument(
        "--filmstrips", type=OutputPath(*PLOT), help="PNG: before and after (Figures 13-14 style)"
    )
    parser.add_argument(
        "--search", type=OutputPath(*PLOT), help="PNG: the best total after each generation"
    )
    parser.add_argument("--gif", type=OutputPath(*GIF), help="animated GIF of the refined motion")


def _composite_check(args: argparse.Namespace) -> str | None:
    if not (args.filmstrips or args.search or args.gif):
        return "give --filmstrips, --search and/or --gif"
    return None


def _composite(args: argparse.Namespace) -> None:
    from mosys.plots import composite

    if args.filmstrips:
        composite.plot_filmstrips(args.result, args.filmstrips)
    if args.search:
        composite.plot_search(args.result, args.search)
    if args.gif:
        composite.write_composite_gif(args.result, args.gif)


FAMILY = Family(
    "plots (mosys plot KIND)",
    (
        Verb(
            "plot controller",
            "a controller's portrait and torque map",
            _controller_arguments,
            _controller,
            _controller_check,
        ),
        Verb(
            "plot script",
            "a script's path (Figure 16 style) and its GIF",
            _script_arguments,
            _script,
            _script_check,
        ),
        Verb(
            "plot controls",
            "a control against time in several scripts, with slew limits",
            _controls_arguments,
            _controls,
            _controls_check,
        ),
        Verb(
            "plot free-swing",
            "Figure 5: free-swing orbits and separatrix of a 1-joint figure",
            _free_swing_arguments,
            _free_swing,
        ),
        Verb(
            "plot car",
            "car frames (Figure 19 style), a GIF, the success map",
            _car_arguments,
            _car,
            _car_check,
        ),
        Verb(
            "plot luxo",
            "Luxo: a motion's strip (Figure 22), forces, a GIF",
            _luxo_arguments,
            _luxo,
            _luxo_check,
        ),
        Verb(
            "plot bsr",
            "a BSR search: learning curves, filmstrip, GIF",
            _bsr_arguments,
            _bsr,
            _bsr_check,
        ),
        Verb(
            "plot bsr-learning",
            "learning curves of BSR searches compared (Figure 7 style)",
            _bsr_learning_arguments,
            _bsr_learning,
        ),
        Verb(
            "plot bsr3d",
            "3-D BSR searches: filmstrip (Figures 15-17), GIF, figure",
            _bsr3d_arguments,
            _bsr3d,
            _bsr3d_check,
        ),
        Verb(
            "plot bsr3d-kinds",
            "time- vs sense-based learning curves (Figure 7 style)",
            _bsr3d_kinds_arguments,
            _bsr3d_kinds,
            _bsr3d_kinds_check,
        ),
        Verb(
            "plot bsr3d-seeds",
            "each seed's learning curve (Figure 8 style)",
            _bsr3d_seeds_arguments,
            _bsr3d_seeds,
        ),
        Verb(
            "plot composite",
            "a composite motion: filmstrips before/after, the search, a GIF",
            _composite_arguments,
            _composite,
            _composite_check,
        ),
    ),
)
