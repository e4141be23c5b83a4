"""The car's plots (Figure 19, the parking GIF, the start-grid success map) from small car
trajectories and a start grid built here: the car's own kinematics (mosys.dynamics.vehicle)
integrated in numpy, collisions found by the real geometry kernel. The figures are checked
through their matplotlib artists (``parking_frames_figure``, ``success_map_figure``)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import h5py
import matplotlib
import numpy as np
import pytest
from conftest import assert_png
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.collections import PathCollection, PolyCollection
from matplotlib.colors import same_color
from matplotlib.figure import Figure
from matplotlib.patches import Polygon
from PIL import Image

import mosys.plots.car as car_plots
import mosys.plots.car_scene as car_scene
import mosys.plots.car_starts as car_starts
import mosys.plots.style as style
from mosys.io.start_grid import (
    NO_WAY,
    NOT_FREE,
    OUTSIDE_DOMAIN,
    consistency_ratios,
    consistency_summary,
)
from mosys.io.trajectory import Trajectory, write_trajectory
from mosys.kernels.geometry import first_colliding_sample, pack_polygons
from mosys.plots.car import (
    drawn_samples,
    outcome_text,
    parking_frames_figure,
    plot_parking_frames,
    read_car_trajectory,
    wheel_segments,
    write_parking_gif,
)
from mosys.plots.car_scene import FAILURE_COLOR, OBSTACLE_FACE, view_limits
from mosys.plots.car_starts import (
    TIMEOUT_COLOR,
    consistency_figure,
    plot_consistency,
    plot_success_map,
    read_drawn_start_grid,
    success_map_figure,
)
from mosys.plots.style import GIF_HOLD_MS, PlotInputError, frame_indices

WHEELBASE = 2.5  # m, as specs/figures/car.fig
BODY = [[0.8, -0.85], [0.8, 0.85], [-3.2, 0.85], [-3.2, -0.85]]  # m, car frame
OBSTACLES = {
    "curb": [[-12.0, -1.0], [16.0, -1.0], [16.0, 0.0], [-12.0, 0.0]],
    "rear_car": [[-8.0, 0.3], [-3.5, 0.3], [-3.5, 2.0], [-8.0, 2.0]],
    "front_car": [[4.0, 0.3], [8.5, 0.3], [8.5, 2.0], [4.0, 2.0]],
}
DESTINATION = {"x": 2.6, "y": 1.15, "heading": 0.0}
STATE_ORDER = ("x", "y", "heading", "steer", "speed")
DT = 0.05  # s


def drive(start, controls, dt=DT) -> np.ndarray:
    """Euler steps of the car's kinematics (mosys.dynamics.vehicle) from ``start`` (x m, y m,
    heading deg, steer deg) through ``controls``: (steer deg, speed m/s, seconds) legs, the
    steer set at once. Returns the (N, 5) states in STATE_ORDER, spec units."""
    x, y, heading, steer = start
    rows = [[x, y, heading, steer, 0.0]]
    for steer, speed, seconds in controls:
        for _ in range(round(seconds / dt)):
            h, d = math.radians(heading), math.radians(steer)
            x += dt * speed * math.cos(h + d)
            y += dt * speed * math.sin(h + d)
            heading += math.degrees(dt * speed * math.sin(d) / WHEELBASE)
            rows.append([x, y, heading, steer, speed])
    return np.array(rows)


def parking_states(first_steer: float) -> np.ndarray:
    """A reverse parallel park into the destination: the destination pose driven out forwards
    (left, then right), played backwards; starts with the steer at ``first_steer``."""
    legs = [(0, -1.0, 1.2), (35, 1.2, 3.0), (-35, 1.2, 3.0), (0, 1.2, 1.0)]
    out = drive((DESTINATION["x"], DESTINATION["y"], 0.0, 0.0), legs)
    states = out[::-1].copy()
    states[:, 4] *= -1  # driven backwards in time: the speeds reverse
    states[0, 3] = first_steer
    return states


def car_attrs(states: np.ndarray, t: np.ndarray, seconds: float, **overrides) -> dict:
    """The car runtime's root attributes for a run, its collision found by the real kernel."""
    vertices, starts = pack_polygons([np.array(p) for p in OBSTACLES.values()])
    poses = np.column_stack([states[:, 0], states[:, 1], np.radians(states[:, 2])])
    sample, obstacle = first_colliding_sample(
        np.ascontiguousarray(poses), np.array(BODY), vertices, starts
    )
    final = states[-1]
    parked = bool(
        sample < 0
        and abs(final[0] - DESTINATION["x"]) < 0.2
        and abs(final[1] - DESTINATION["y"]) < 0.2
        and t[-1] <= seconds
    )
    attrs = {
        "body_outline": json.dumps(BODY),
        "obstacles": json.dumps(list(OBSTACLES.values())),
        "obstacle_names": list(OBSTACLES),
        "destination": json.dumps(DESTINATION),
        "wheelbase": WHEELBASE,
        "collision_index": int(sample),
        "collided_with": list(OBSTACLES)[obstacle] if sample >= 0 else "",
        "parked": parked,
        "parking_seconds": float(t[-1]) if parked else math.nan,
        "simulated_seconds": seconds,
    }
    attrs.update(overrides)
    return {key: value for key, value in attrs.items() if value is not None}


def write_car_trajectory(
    path: Path, states: np.ndarray, seconds=20.0, state_order=STATE_ORDER, **overrides
) -> Path:
    """A car trajectory file: ``states`` (N, 5) in STATE_ORDER, written in ``state_order``."""
    t = DT * np.arange(len(states))
    attrs = car_attrs(states, t, seconds, **overrides)
    columns = [STATE_ORDER.index(name) for name in state_order]
    write_trajectory(
        path,
        Trajectory(
            t=t,
            state=states[:, columns],
            control=np.zeros((len(t), 2)),
            controller=np.zeros(len(t), dtype=np.int64),
            state_order=tuple(state_order),
            control_names=("steer_rate", "wheel_accel"),
            controllers=("park",),
            attrs=attrs,
            motion=None,
        ),
    )
    return path


def crash_states() -> np.ndarray:
    """Straight ahead, heading −15°, into the front car."""
    return drive((-6.0, 4.5, -15.0, 0.0), [(0, 2.0, 6.0)])


def lost_states() -> np.ndarray:
    """A slow loop far from the gap: never parks, never touches anything."""
    return drive((-2.0, 6.0, 0.0, 20.0), [(20, 0.8, 6.0)])


@pytest.fixture
def parks(tmp_path) -> Path:
    return write_car_trajectory(tmp_path / "park_1.h5", parking_states(-30.0))


@pytest.fixture
def crashes(tmp_path) -> Path:
    return write_car_trajectory(tmp_path / "park_2.h5", crash_states())


@pytest.fixture
def lost(tmp_path) -> Path:
    return write_car_trajectory(tmp_path / "park_3.h5", lost_states(), seconds=6.0)


def write_start_grid(path: Path, steers=(0.0,), headings=(0.0,)) -> Path:
    """Per (heading, steer), a 2 × 3 grid of start positions run, outcomes by position: the lower
    row parks at the first heading and steer (8, 10 and 12 s, left to right, from a cost-to-go
    of 8 s: 1.0, 1.25 and 1.5 times it), the upper row's left start collides, the rest time
    out; and two starts not run: one in the front car (not free), one the pose search found no
    path from. Cost-to-go 9 s at the other starts run, inf at those not run."""
    rows, parked, collided, seconds, excluded = [], [], [], [], []
    for heading in headings:
        for steer in steers:
            first = steer == steers[0] and heading == headings[0]
            for j, y in enumerate((4.0, 6.0)):
                for i, x in enumerate((0.0, 3.0, 6.0)):
                    rows.append([x, y, heading, steer, 0.0])
                    parked.append(j == 0 and first)
                    collided.append(j == 1 and i == 0)
                    seconds.append(8.0 + 2.0 * i if parked[-1] else math.nan)
                    excluded.append("")
            for x, reason in ((6.0, NOT_FREE), (0.0, NO_WAY)):
                rows.append([x, 1.0, heading, steer, 0.0])
                parked.append(False)
                collided.append(False)
                seconds.append(math.nan)
                excluded.append(reason)
    excluded = np.array(excluded, dtype=object)
    cost_to_go = np.where(np.array(parked), 8.0, np.where(excluded == "", 9.0, math.inf))
    path_length = np.select([excluded == NOT_FREE, excluded == NO_WAY], [math.nan, math.inf], 6.5)
    with h5py.File(path, "w") as h5:
        h5["start"] = np.array(rows)
        h5["parked"] = np.array(parked)
        h5["collided"] = np.array(collided)
        h5["parking_seconds"] = np.array(seconds)
        h5.create_dataset("excluded", data=excluded, dtype=h5py.string_dtype())
        h5["cost_to_go"] = cost_to_go
        h5["path_length"] = path_length
        h5.attrs["state_order"] = list(STATE_ORDER)
        h5.attrs["body_outline"] = json.dumps(BODY)
        h5.attrs["obstacles"] = json.dumps(list(OBSTACLES.values()))
        h5.attrs["obstacle_names"] = list(OBSTACLES)
        h5.attrs["destination"] = json.dumps(DESTINATION)
        h5.attrs["controller"] = "park"
        h5.attrs["simulated_seconds"] = 20.0
    return path


def markers(ax) -> dict[str, np.ndarray]:
    """A map panel's marker collections by gid (their legend text): the (k, 2) m positions."""
    return {
        c.get_gid(): np.asarray(c.get_offsets())
        for c in ax.collections
        if isinstance(c, PathCollection)
    }


def assert_gif(path: Path) -> None:
    assert path.read_bytes()[:6] == b"GIF89a"
    with Image.open(path) as image:
        assert image.format == "GIF"
        assert image.width >= 300 and image.height >= 200, image.size
        colors = image.convert("RGB").getcolors(maxcolors=1 << 20)
        assert len(colors) > 20, f"{path} looks blank"


def outcome_label(ax):
    (label,) = [text for text in ax.texts if text.get_gid() == "outcome"]
    return label


def legend_labels(figure) -> list[str]:
    (legend,) = figure.legends
    return [text.get_text() for text in legend.get_texts()]


def polygons(ax, **style) -> list[Polygon]:
    """The axes' Polygon patches whose properties match ``style`` (linestyle, fill...)."""
    return [
        patch
        for patch in ax.patches
        if isinstance(patch, Polygon)
        and all(getattr(patch, f"get_{key}")() == value for key, value in style.items())
    ]


# --------------------------------------------------------------------------- the synthetic runs


def test_the_synthetic_runs_are_what_they_claim(parks, crashes, lost):
    parked = read_car_trajectory(parks)
    assert parked.parked and not parked.collided
    assert abs(parked.x[-1] - DESTINATION["x"]) < 1e-9 and abs(parked.y[-1] - 1.15) < 1e-9
    crashed = read_car_trajectory(crashes)
    assert crashed.collided and crashed.collided_with == "front_car"
    assert 0 < crashed.collision_index < len(crashed.t) - 1  # it drives on, into the car
    wandered = read_car_trajectory(lost)
    assert not wandered.parked and not wandered.collided


# --------------------------------------------------------------------------- pure helpers


def test_frame_indices_take_a_sample_every_interval():
    t = np.arange(0.0, 2.0 + 1e-9, 0.05)  # 41 samples, 0.3 s is exactly six steps
    np.testing.assert_array_equal(frame_indices(t, 0.3), [0, 6, 12, 18, 24, 30, 36])
    np.testing.assert_array_equal(frame_indices(t, 0.5), [0, 10, 20, 30, 40])  # both ends
    np.testing.assert_array_equal(frame_indices(t + 7.0, 0.5), [0, 10, 20, 30, 40])
    np.testing.assert_array_equal(frame_indices(t, 0.01), np.arange(41))  # no repeats
    np.testing.assert_array_equal(frame_indices(np.array([3.0]), 0.3), [0])
    assert frame_indices(np.empty(0), 0.3).size == 0


@given(
    steps=st.lists(st.floats(0.0, 1.0), min_size=1, max_size=80),
    interval=st.floats(0.01, 5.0),
)
@settings(max_examples=200, deadline=None)
def test_frame_indices_are_the_first_samples_at_or_after_each_frame_time(steps, interval):
    t = np.concatenate([[0.0], np.cumsum(steps)])
    index = frame_indices(t, interval)
    assert index[0] == 0 and np.all(np.diff(index) > 0) and index[-1] < len(t)
    for k in range(math.floor(t[-1] / interval + 1e-9) + 1):
        i = np.searchsorted(t, k * interval - 1e-9)
        assert min(i, len(t) - 1) in index
    assert len(index) <= math.floor(t[-1] / interval + 1e-9) + 1


def test_frame_indices_reject_a_bad_interval():
    with pytest.raises(ValueError, match="interval must be positive"):
        frame_indices(np.arange(3.0), 0.0)


def test_drawn_samples_stop_at_the_first_collision():
    t = DT * np.arange(100)
    np.testing.assert_array_equal(drawn_samples(t, 0.3, 17), [0, 6, 12, 17])
    np.testing.assert_array_equal(drawn_samples(t, 0.3, 18), [0, 6, 12, 18])
    free = drawn_samples(t, 0.3, -1)
    assert free[-1] == 99 and np.all(np.isin(frame_indices(t, 0.3), free))
    np.testing.assert_array_equal(drawn_samples(t, 0.3, 0), [0])


def test_outcome_text(parks, crashes, lost):
    parked = read_car_trajectory(parks)
    assert outcome_text(parked) == f"parked in {parked.parking_seconds:.1f} s"
    crashed = read_car_trajectory(crashes)
    hit_time = crashed.t[crashed.collision_index]
    assert outcome_text(crashed) == f"FAILED: hits front_car at {hit_time:.1f} s"
    assert outcome_text(read_car_trajectory(lost)) == "FAILED: not parked in 6 s"


def test_a_collision_is_a_failure_even_if_the_file_says_parked(tmp_path):
    path = write_car_trajectory(
        tmp_path / "both.h5", crash_states(), parked=True, parking_seconds=3.0
    )
    run = read_car_trajectory(path)
    assert run.failed
    assert outcome_text(run).startswith("FAILED: hits front_car at ")


def test_columns_are_found_by_name(tmp_path, parks):
    shuffled = write_car_trajectory(
        tmp_path / "shuffled.h5",
        parking_states(-30.0),
        state_order=("speed", "steer", "heading", "y", "x"),
    )
    a, b = read_car_trajectory(parks), read_car_trajectory(shuffled)
    for name in ("x", "y", "heading", "steer", "speed"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


def test_wheels_sit_on_the_axles_and_the_front_pair_steers(parks):
    run = read_car_trajectory(parks)
    wheels = wheel_segments(run, 0)  # steer -30 deg at the start
    centres = wheels.mean(axis=1)
    front = (centres[0] + centres[1]) / 2
    rear = (centres[2] + centres[3]) / 2
    np.testing.assert_allclose(front, [run.x[0], run.y[0]], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(front - rear), WHEELBASE)
    angles = np.degrees(np.arctan2(*(wheels[:, 1] - wheels[:, 0]).T[::-1]))
    np.testing.assert_allclose(angles[:2], run.heading[0] - 30.0, atol=1e-9)
    np.testing.assert_allclose(angles[2:], run.heading[0], atol=1e-9)


def test_view_limits_clip_long_obstacles_to_the_cars_region():
    cars = np.array([[0.0, 1.0], [4.0, 3.0]])
    wall = np.array([[-100.0, -1.0], [100.0, -1.0], [100.0, 0.0], [-100.0, 0.0]])
    far = np.array([[50.0, 50.0], [51.0, 50.0], [51.0, 51.0]])
    (x0, y0), (x1, y1) = view_limits(cars, [wall, far])
    assert x0 == pytest.approx(-car_scene.VIEW_MARGIN - car_scene.EDGE_MARGIN)
    assert x1 == pytest.approx(4.0 + car_scene.VIEW_MARGIN + car_scene.EDGE_MARGIN)
    # the wall shows as far as VIEW_MARGIN below the cars; the far obstacle is left out
    assert y0 == pytest.approx(1.0 - car_scene.VIEW_MARGIN - car_scene.EDGE_MARGIN)
    assert y1 == pytest.approx(3.0 + car_scene.EDGE_MARGIN)


# --------------------------------------------------------------------------- the plots


def test_parking_frames_figure(parks, crashes, lost):
    figure = parking_frames_figure([parks, crashes, lost], interval=0.3)
    panels = [ax for ax in figure.axes if ax.get_title()]
    assert len(panels) == len(figure.axes) == 3
    assert [ax.get_title().split(":")[0] for ax in panels] == ["park_1", "park_2", "park_3"]
    assert figure.get_suptitle() == "The car parking under controller park"
    assert all(ax.get_xlim() == panels[0].get_xlim() for ax in panels)
    assert all(ax.get_ylim() == panels[0].get_ylim() for ax in panels)
    assert all(ax.get_aspect() == 1.0 for ax in panels)
    assert [ax.get_ylabel() for ax in panels] == ["y (m)", "", ""]  # the left column only
    assert all(ax.get_xlabel() == "x (m)" for ax in panels)
    assert legend_labels(figure) == [
        "obstacle",
        "destination (car outline)",
        "car every 0.3 s, light → dark",
        "start outline and its front-axle midpoint",
        "final outline",
        "path of the front-axle midpoint",
        "first collision",
    ]
    # the swatches are drawn as the outlines are: the start light, the final dark
    handles = {
        text.get_text(): handle
        for text, handle in zip(
            figure.legends[0].get_texts(), figure.legends[0].legend_handles, strict=True
        )
    }
    start, final = panels[0].patches[-2:]  # after the obstacles and destination: start, final
    assert same_color(
        handles["start outline and its front-axle midpoint"].get_color(), start.get_edgecolor()
    )
    assert same_color(handles["final outline"].get_color(), final.get_edgecolor())
    parked, crashed, wandered = (outcome_label(ax) for ax in panels)
    assert parked.get_text().startswith("parked in") and parked.get_color() == "black"
    assert crashed.get_text().startswith("FAILED: hits front_car")
    assert crashed.get_color() == FAILURE_COLOR
    assert wandered.get_text() == "FAILED: not parked in 6 s"
    assert wandered.get_color() == FAILURE_COLOR
    for ax, path in zip(panels, (parks, crashes, lost), strict=True):
        run = read_car_trajectory(path)
        drawn = drawn_samples(run.t, 0.3, run.collision_index)
        obstacles = [p for p in ax.patches if same_color(p.get_facecolor(), OBSTACLE_FACE)]
        assert len(obstacles) == 3
        assert {text.get_text() for text in ax.texts} & set(OBSTACLES)  # named where they fit
        (goal,) = polygons(ax, linestyle=":")
        assert np.ptp(goal.get_xy()[:, 0]) == pytest.approx(4.0)  # the 4 m body at the goal
        # the outlines between the start and the final one, thin; those two thick
        (between,) = [c for c in ax.collections if isinstance(c, PolyCollection)]
        assert len(between.get_paths()) == len(drawn) - 2
        assert len(polygons(ax, fill=False, linewidth=2.0)) == 2
        (trace,) = [line for line in ax.lines if len(line.get_xdata()) > 1]
        np.testing.assert_array_equal(trace.get_xdata(), run.x[: drawn[-1] + 1])
    # the crash is drawn no further than its first colliding sample, that outline red
    run = read_car_trajectory(crashes)
    (trace,) = [line for line in panels[1].lines if len(line.get_xdata()) > 1]
    assert len(trace.get_xdata()) == run.collision_index + 1
    red = [p for p in panels[1].patches if same_color(p.get_edgecolor(), FAILURE_COLOR)]
    assert len(red) == 1, "the colliding outline is drawn in red"
    assert not [p for p in panels[0].patches if same_color(p.get_edgecolor(), FAILURE_COLOR)]


def test_the_collision_entry_and_a_lone_starts_steer_are_shown_only_when_there(
    parks, crashes, lost
):
    """Without a collision the legend had its red swatch all the same; a lone run's title (the
    frames', the GIF's) named its position and heading but not its wheels turned 20°."""
    figure = parking_frames_figure([parks, lost], interval=0.3)
    assert "first collision" not in legend_labels(figure)
    for path, title in (
        (lost, "park_3: from (−2, 6) m, heading 0°, steer 20°"),
        (parks, "park_1: from (7.88, 3.46) m, heading 0°, steer −30°, speed −1.2 m/s"),
        (crashes, "park_2: from (−6, 4.5) m, heading −15°"),  # wheels straight, at rest
    ):
        (panel,) = [ax for ax in parking_frames_figure([path]).axes if ax.get_title()]
        assert panel.get_title().splitlines()[0] == title


def test_a_long_run_draws_at_most_outlines_max_outlines(tmp_path, parks):
    """A 200 s loop at 0.3 s would draw 667 outlines (the verb fuzz's 2,000 s run drew 6,667,
    a black disk, in 15 s): a round interval that draws 100 to 150 instead, in the legend; a
    short run beside it takes the same interval."""
    loop = write_car_trajectory(
        tmp_path / "loop.h5", drive((-2.0, 6.0, 0.0, 20.0), [(20, 0.8, 200.0)]), seconds=200.0
    )
    figure = parking_frames_figure([parks, loop], interval=0.3)
    assert "car every 1.5 s, light → dark" in legend_labels(figure)
    for ax, path in zip((ax for ax in figure.axes if ax.get_title()), (parks, loop), strict=True):
        run = read_car_trajectory(path)
        (between,) = [c for c in ax.collections if isinstance(c, PolyCollection)]
        assert len(between.get_paths()) == len(drawn_samples(run.t, 1.5)) - 2
    assert len(drawn_samples(read_car_trajectory(loop).t, 1.5)) <= car_plots.OUTLINES_MAX


def test_a_path_agg_cannot_draw_in_one_piece_is_drawn_in_pieces(tmp_path, parks, monkeypatch):
    """Agg's "Exceeded cell block limit" (OverflowError: a car run of 2,000 s at 1e9 m/s) was
    a traceback; the figure is drawn again with Agg's path chunking, only then."""
    calls = []
    real = Figure.savefig

    def savefig(self, *args, **kwargs):
        calls.append(matplotlib.rcParams["agg.path.chunksize"])
        if len(calls) == 1:
            raise OverflowError("Exceeded cell block limit in Agg.")
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    out = tmp_path / "frames.png"
    plot_parking_frames([parks], out)
    assert calls == [0, style.AGG_CHUNK]
    assert_png(out)
    assert sorted(path.name for path in tmp_path.iterdir()) == ["frames.png", "park_1.h5"]


def test_a_long_runs_gif_keeps_to_the_frame_limit_in_real_time(tmp_path, lost, monkeypatch):
    """A 2,000 s run's GIF took 2.4 GiB and more than two minutes (a frame per 0.05 s): past
    REAL_TIME_MAX_FRAMES the step widens to whole hundredths, each frame shown that long."""
    monkeypatch.setattr(car_plots, "REAL_TIME_MAX_FRAMES", 20)
    out = tmp_path / "lost.gif"
    write_parking_gif(lost, out)  # 6 s: 121 frames at 20 fps
    with Image.open(out) as gif:
        assert gif.n_frames == 20  # every 0.32 s (6 s / 19, rounded up), and the last
        assert gif.info["duration"] == 320


def test_parking_frames_png(tmp_path, parks, crashes, lost):
    out = tmp_path / "frames.png"
    plot_parking_frames([parks, crashes, lost], out, interval=0.3)
    width, height = assert_png(out, least_width=900)
    assert width > height


def test_six_panels_are_two_rows_of_three(tmp_path):
    paths = [
        write_car_trajectory(tmp_path / f"park_{k}.h5", parking_states(steer))
        for k, steer in enumerate((-30, -15, 0, 10, 20, 30), start=1)
    ]
    figure = parking_frames_figure(paths)
    boxes = [ax.get_position() for ax in figure.axes if ax.get_title()]
    assert len(boxes) == 6
    assert len({round(b.y0, 6) for b in boxes}) == 2
    assert len({round(b.x0, 6) for b in boxes}) == 3
    assert [ax.get_title() for ax in figure.axes[:2]] == [
        "park_1: steer −30°",
        "park_2: steer −15°",
    ]
    assert [ax.get_xlabel() for ax in figure.axes] == [""] * 3 + ["x (m)"] * 3  # lower row


def test_parking_gif(tmp_path, crashes, parks):
    out = tmp_path / "park.gif"
    write_parking_gif(crashes, out, fps=10)
    assert_gif(out)
    run = read_car_trajectory(crashes)
    hit = run.collision_index
    with Image.open(out) as gif:
        # every 0.1 s up to the collision, both ends included: no frame after it
        expected = np.union1d(frame_indices(run.t[: run.collision_index + 1], 0.1), [hit])
        assert gif.n_frames == len(expected)
        assert gif.info["duration"] == 100
        first = np.asarray(gif.convert("RGB"))
        gif.seek(gif.n_frames - 1)
        assert gif.info["duration"] == GIF_HOLD_MS
        last = np.asarray(gif.convert("RGB"))
    assert np.any(first != last)
    write_parking_gif(parks, tmp_path / "parks.gif", fps=4)
    with Image.open(tmp_path / "parks.gif") as gif:
        assert gif.n_frames > 1
    assert not [p for p in tmp_path.iterdir() if "partial" in p.name]


HEADLINE = (
    "Controller park: parks from 3 of 6 starts (50.0 %); 2 more cannot park at all, not counted"
)
MAP_LEGEND = [
    "parked",
    "collision",
    "not parked in 20 s",
    "cannot park (start on an obstacle or off the domain)",
    "cannot park (no path found)",
    "destination (car outline)",
]


def test_success_map_one_panel(tmp_path):
    figure = success_map_figure(write_start_grid(tmp_path / "grid.h5"))
    assert figure.get_suptitle() == (
        f"{HEADLINE}\n"
        "every start: heading 0°, steer 0°, speed 0.0 m/s; each run simulated for up to 20 s"
    )
    panel, colorbar = figure.axes
    assert colorbar.get_ylabel() == "parking time (s)"
    assert panel.get_aspect() == 1.0 and panel.get_title() == ""
    parked, collided, late, not_free, no_way = (
        c for c in panel.collections if isinstance(c, PathCollection)
    )
    assert [c.get_gid() for c in (parked, collided, late, not_free, no_way)] == MAP_LEGEND[:-1]
    np.testing.assert_array_equal(parked.get_offsets(), [[0, 4], [3, 4], [6, 4]])
    np.testing.assert_array_equal(parked.get_array(), [8.0, 10.0, 12.0])  # s, the colours
    assert parked.get_clim() == (8.0, 12.0)
    np.testing.assert_array_equal(collided.get_offsets(), [[0, 6]])
    assert same_color(collided.get_facecolor()[0], FAILURE_COLOR)
    np.testing.assert_array_equal(late.get_offsets(), [[3, 6], [6, 6]])
    assert same_color(late.get_facecolor()[0], TIMEOUT_COLOR)
    assert len([p for p in panel.patches if same_color(p.get_facecolor(), OBSTACLE_FACE)]) == 3
    assert len(polygons(panel, linestyle=":")) == 1  # the destination
    assert legend_labels(figure) == MAP_LEGEND


def test_excluded_starts_have_their_own_markers_and_are_not_counted(tmp_path):
    figure = success_map_figure(write_start_grid(tmp_path / "grid.h5"))
    panel = figure.axes[0]
    drawn = markers(panel)
    np.testing.assert_array_equal(
        drawn["cannot park (start on an obstacle or off the domain)"], [[6, 1]]
    )
    np.testing.assert_array_equal(drawn["cannot park (no path found)"], [[0, 1]])
    # drawn once each, in no outcome's collection
    every = np.concatenate(list(drawn.values()))
    assert len(every) == 8 and len(np.unique(every, axis=0)) == 8
    by_gid = {c.get_gid(): c for c in panel.collections if isinstance(c, PathCollection)}
    not_free, no_way = (
        by_gid["cannot park (start on an obstacle or off the domain)"],
        by_gid["cannot park (no path found)"],
    )
    shapes = {c.get_gid(): c.get_paths()[0].vertices.round(3).tobytes() for c in by_gid.values()}
    assert len(set(shapes.values())) == 5, "each kind of start has a marker of its own shape"
    assert same_color(not_free.get_facecolor()[0], car_starts.NOT_FREE_COLOR)
    assert len(no_way.get_facecolor()) == 0  # hollow
    assert same_color(no_way.get_edgecolor()[0], car_starts.NO_WAY_COLOR)
    (legend,) = figure.legends
    handles = dict(zip(legend_labels(figure), legend.legend_handles, strict=True))
    assert handles["cannot park (start on an obstacle or off the domain)"].get_marker() == "+"
    assert handles["cannot park (no path found)"].get_marker() == "D"
    # 3 of the 6 starts run park: 50 %, not 3 of 8
    assert figure.get_suptitle().startswith(HEADLINE)


def test_starts_that_are_not_free_are_drawn_by_what_they_overlap(tmp_path):
    """A grid that says what makes each start not free (``excluded_detail``): a + per detail,
    each its own colour and legend entry, the overlaps in alphabetical order, then the starts
    off the domain; the rate and the other markers as before."""
    path = write_start_grid(tmp_path / "grid.h5", headings=(0.0, 90.0, 180.0))
    with h5py.File(path, "a") as h5:
        excluded = h5["excluded"].asstr()[()]
        detail = np.full(len(excluded), "", dtype=object)
        not_free = np.flatnonzero(excluded == NOT_FREE)
        detail[not_free] = [OUTSIDE_DOMAIN, "overlaps front car", "overlaps curb and front car"]
        h5.create_dataset("excluded_detail", data=detail, dtype=h5py.string_dtype())
    figure = success_map_figure(path)
    labels = [
        "cannot park: start overlaps curb and front car",
        "cannot park: start overlaps front car",
        "cannot park: start’s reference point outside the domain",
    ]
    assert legend_labels(figure) == MAP_LEGEND[:3] + labels + MAP_LEGEND[4:]
    by_gid = {}
    for ax in figure.axes[:3]:
        by_gid.update({c.get_gid(): c for c in ax.collections if isinstance(c, PathCollection)})
    colors = [by_gid[label].get_facecolor()[0] for label in labels]
    for first, second in ((0, 1), (0, 2), (1, 2)):
        assert not same_color(colors[first], colors[second])
    assert same_color(colors[0], car_starts.NOT_FREE_COLOR)
    panels = figure.axes[:3]  # headings 0°, 90°, 180°: the detail of each one's start at (6, 1)
    for ax, label in zip(panels, [labels[2], labels[1], labels[0]], strict=True):
        np.testing.assert_array_equal(markers(ax)[label], [[6, 1]])
    (legend,) = figure.legends
    handles = dict(zip(legend_labels(figure), legend.legend_handles, strict=True))
    assert {handles[label].get_marker() for label in labels} == {"+"}
    assert figure.get_suptitle().startswith(
        "Controller park: parks from 3 of 18 starts (16.7 %); 6 more cannot park at all"
    )


def test_more_kinds_of_not_free_starts_than_colours_still_look_apart(tmp_path):
    """A scene of several obstacles (a garage: three walls and a bin) has more kinds of starts
    that are not free than there are colours: past the last colour, the kinds take the colours
    again with another shape, so no two share a marker (they shared a colour and the +, and
    the map could not say which start overlapped the bin and which the right wall)."""
    count = len(car_starts.NOT_FREE_DETAIL_COLORS) + 3
    path = write_start_grid(tmp_path / "grid.h5", headings=tuple(10.0 * k for k in range(count)))
    with h5py.File(path, "a") as h5:
        excluded = h5["excluded"].asstr()[()]
        detail = np.full(len(excluded), "", dtype=object)
        not_free = np.flatnonzero(excluded == NOT_FREE)
        detail[not_free] = [f"overlaps wall_{k}" for k in range(count)]
        h5.create_dataset("excluded_detail", data=detail, dtype=h5py.string_dtype())
    figure = success_map_figure(path)
    (legend,) = figure.legends
    handles = dict(zip(legend_labels(figure), legend.legend_handles, strict=True))
    looks = set()
    for k in range(count):
        handle = handles[f"cannot park: start overlaps wall_{k}"]
        looks.add((handle.get_marker(), matplotlib.colors.to_hex(handle.get_markerfacecolor())))
    assert len(looks) == count, looks
    drawn = set()
    for ax in figure.axes[:count]:
        for c in ax.collections:
            if isinstance(c, PathCollection) and str(c.get_gid()).startswith("cannot park: start"):
                drawn.add((c.get_gid(), matplotlib.colors.to_hex(c.get_facecolor()[0])))
    assert len(drawn) == count and len({color for _, color in drawn}) == len(
        car_starts.NOT_FREE_DETAIL_COLORS
    )


def test_only_the_exclusion_reasons_present_are_in_the_legend(tmp_path):
    path = write_start_grid(tmp_path / "grid.h5")
    with h5py.File(path, "a") as h5:
        excluded = h5["excluded"].asstr()[()]
        excluded[excluded == NO_WAY] = ""  # now counted and run: it timed out
        del h5["excluded"]
        h5.create_dataset("excluded", data=excluded.astype(object), dtype=h5py.string_dtype())
    figure = success_map_figure(path)
    assert legend_labels(figure) == [label for label in MAP_LEGEND if "no path" not in label]
    assert figure.get_suptitle().startswith(
        "Controller park: parks from 3 of 7 starts (42.9 %); 1 more cannot park at all, not counted"
    )
    np.testing.assert_array_equal(
        markers(figure.axes[0])["not parked in 20 s"], [[3, 6], [6, 6], [0, 1]]
    )


def test_success_map_one_panel_per_steer(tmp_path):
    figure = success_map_figure(write_start_grid(tmp_path / "grid.h5", steers=(-30.0, 0.0)))
    panels = [ax for ax in figure.axes if ax.get_title()]
    assert [ax.get_title() for ax in panels] == ["start steer δ = −30°", "start steer δ = 0°"]
    assert figure.get_suptitle().startswith(
        "Controller park: parks from 3 of 12 starts (25.0 %); 4 more cannot park at all"
    )
    counts = [{gid: len(xy) for gid, xy in markers(ax).items()} for ax in panels]
    assert (
        counts
        == [  # no parked marker where none parks
            dict(zip(MAP_LEGEND[:-1], [3, 1, 2, 1, 1], strict=True)),
            dict(zip(MAP_LEGEND[1:-1], [1, 5, 1, 1], strict=True)),
        ]
    )


def test_success_map_table_of_panels(tmp_path):
    """Four headings × three steers: rows heading, columns steer, one colour bar."""
    path = write_start_grid(
        tmp_path / "grid.h5", steers=(-30.0, 0.0, 30.0), headings=(0.0, 90.0, 180.0, 270.0)
    )
    figure = success_map_figure(path)
    panels = [ax for ax in figure.axes if ax.get_title()]
    assert len(panels) == 12 and len(figure.axes) == 13
    boxes = [ax.get_position() for ax in panels]
    rows = sorted({round(b.y0, 6) for b in boxes}, reverse=True)
    columns = sorted({round(b.x0, 6) for b in boxes})
    assert len(rows) == 4 and len(columns) == 3
    for k, (ax, box) in enumerate(zip(panels, boxes, strict=True)):
        heading, steer = divmod(k, 3)
        assert (rows.index(round(box.y0, 6)), columns.index(round(box.x0, 6))) == (heading, steer)
        assert ax.get_title() == (
            f"start heading φ = {90 * heading}°, "
            f"steer δ = {car_scene.describe_value('steer', 30.0 * (steer - 1))}"
        )
    assert [ax.get_ylabel() for ax in panels] == ["y (m)", "", ""] * 4
    assert [ax.get_xlabel() for ax in panels] == [""] * 9 + ["x (m)"] * 3
    assert figure.get_suptitle().startswith(
        "Controller park: parks from 3 of 72 starts (4.2 %); 24 more cannot park at all"
    )
    assert figure.get_suptitle().split("\n")[1] == (
        "every start: speed 0.0 m/s; each run simulated for up to 20 s"
    )
    counts = [sum(len(xy) for xy in markers(ax).values()) for ax in panels]
    assert counts == [8] * 12


def test_marker_diameter_follows_the_grid_spacing():
    xy = np.array([[0.0, 0.0], [0.5, 0.0], [0.0, 2.0]])
    assert car_starts._marker_diameter(xy, 10.0) == pytest.approx(0.75 * 0.5 * 10.0)  # pt
    low, high = car_starts.MARKER_DIAMETER_RANGE
    assert car_starts._marker_diameter(xy, 1.0) == low
    assert car_starts._marker_diameter(xy, 100.0) == high
    assert car_starts._marker_diameter(xy[:1], 10.0) == high  # a single start


def test_success_map_png(tmp_path):
    out = tmp_path / "map.png"
    plot_success_map(write_start_grid(tmp_path / "grid.h5"), out)
    assert_png(out)


def test_a_start_at_the_destination_keeps_the_promise():
    """Parked in 0 s against a cost-to-go of 3e-15 s (or 0): nothing promised, nothing taken.
    It counted as inconsistent (ratio 0, or NaN for 0 / 0)."""
    ratios = consistency_ratios(np.array([0.0, 0.0, 0.0, 2.0]), np.array([3e-15, 0.0, 0.5, np.inf]))
    assert ratios[:3].tolist() == [1.0, 1.0, 0.0] and np.isnan(ratios[3])


def test_consistency_summary():
    median, p90, within = consistency_summary(np.array([1.0, 1.25, 1.5]))
    assert (median, within) == (1.25, pytest.approx(2 / 3))
    assert p90 == pytest.approx(1.25 + 0.8 * 0.25)  # linear interpolation
    # 0: parked from a start whose cost-to-go is unknown (inf); never within the band
    assert consistency_summary(np.array([0.75, 0.7499, 0.0]))[2] == pytest.approx(1 / 3)
    assert all(math.isnan(value) for value in consistency_summary(np.empty(0)))


def test_consistency_figure(tmp_path):
    figure = consistency_figure(write_start_grid(tmp_path / "grid.h5", steers=(-30.0, 0.0)))
    assert figure.get_suptitle() == (
        "Controller park: parking time / cost-to-go at the start, 3 starts that parked\n"
        "within ±25 %: 2 of 3 (66.7 %); median 1.25, 90th percentile 1.45"
    )
    (ax,) = figure.axes
    assert ax.get_xlabel() == "parking time / cost-to-go at the start (1: as the table predicts)"
    assert ax.get_ylabel() == "starts (count)"
    (histogram,) = ax.containers
    bars = [bar for bar in histogram if bar.get_height() > 0]
    assert [round(bar.get_x(), 9) for bar in bars] == [1.0, 1.25, 1.5]  # [left, left + 0.05)
    assert all(bar.get_height() == 1 for bar in bars)
    assert histogram[0].get_x() == pytest.approx(0.0)
    assert histogram[0].get_width() == pytest.approx(0.05)
    dashed = sorted(line.get_xdata()[0] for line in ax.lines if line.get_linestyle() == "--")
    assert dashed == [0.75, 1.25]
    assert legend_labels(figure) == [
        "within ±25 % of the cost-to-go",
        "as the table predicts",
        "median 1.25",
        "90th percentile 1.45",
    ]
    out = tmp_path / "consistency.png"
    plot_consistency(tmp_path / "grid.h5", out)
    assert_png(out)


def test_consistency_figure_against_the_whole_arrival_box_too(tmp_path):
    """A grid with ``arrival_cost_to_go`` (here 10 s where the cost-to-go is 8 s: ratios 0.8,
    1.0 and 1.2, all within 25 %) adds a title line and an outlined histogram beside the
    ratios against ``/value``, both in the legend."""
    path = write_start_grid(tmp_path / "grid.h5", steers=(-30.0, 0.0))
    with h5py.File(path, "a") as h5:
        h5["arrival_cost_to_go"] = np.where(h5["cost_to_go"][()] == 8.0, 10.0, 11.0)
    figure = consistency_figure(path)
    assert figure.get_suptitle().endswith(
        "within ±25 %: 2 of 3 (66.7 %); median 1.25, 90th percentile 1.45\n"
        "against the cost-to-go to the whole arrival box: within ±25 %: 3 (100.0 %); median 1.00"
    )
    ax = figure.axes[0]
    (filled,) = ax.containers
    assert [round(bar.get_x(), 9) for bar in filled if bar.get_height() > 0] == [1.0, 1.25, 1.5]
    (step,) = [patch for patch in ax.patches if not patch.get_fill()]  # the outline: one polygon
    xy = step.get_xy()
    assert sorted({round(x, 9) for x, y in xy if y > 0}) == [0.8, 0.85, 1.0, 1.05, 1.2, 1.25]
    assert legend_labels(figure)[1:3] == [
        "against the cost-to-go (/value)",
        "against the cost-to-go to the whole arrival box",
    ]


def test_consistency_figure_without_a_parked_start(tmp_path):
    path = write_start_grid(tmp_path / "grid.h5")
    with h5py.File(path, "a") as h5:
        h5["parked"][...] = False
        h5["parking_seconds"][...] = math.nan
    figure = consistency_figure(path)
    assert figure.get_suptitle().endswith(
        "0 starts that parked\nno start parked: nothing to compare"
    )
    (histogram,) = figure.axes[0].containers
    assert not [bar for bar in histogram if bar.get_height() > 0]


# --------------------------------------------------------------------------- bad inputs


def test_a_trajectory_without_body_outline(tmp_path):
    path = write_car_trajectory(tmp_path / "bare.h5", crash_states(), body_outline=None)
    with pytest.raises(PlotInputError) as error:
        plot_parking_frames([path], tmp_path / "x.png")
    assert str(error.value) == (
        f"{path}: not a car trajectory (root attributes): missing body_outline"
    )
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize(
    "overrides, message",
    [
        (
            {"body_outline": "[[0, 0], [1, 1]]"},
            "body_outline must be a list of at least 3 [x, y] vertices, got [[0, 0], [1, 1]]",
        ),
        (
            {"obstacles": "[[0, 0"},
            "root attribute obstacles is not valid JSON (Expecting ',' delimiter: line 1 column 7"
            " (char 6))",
        ),
        ({"obstacle_names": ["curb"]}, "3 obstacles but 1 obstacle_names ['curb']"),
        (
            {"destination": '{"x": 1}'},
            'destination must be {"x": m, "y": m, "heading": deg}, got {\'x\': 1}',
        ),
        ({"collision_index": 10_000}, "collision_index 10000 is outside the 121 samples"),
        ({"parked": True}, "parked is true but parking_seconds is nan"),
    ],
)
def test_malformed_car_attributes(tmp_path, overrides, message):
    path = write_car_trajectory(tmp_path / "bad.h5", crash_states(), **overrides)
    with pytest.raises(PlotInputError) as error:
        write_parking_gif(path, tmp_path / "x.gif")
    assert str(error.value) == f"{path}: {message}"
    assert not (tmp_path / "x.gif").exists()


def test_a_trajectory_that_is_not_a_car(tmp_path):
    path = write_car_trajectory(
        tmp_path / "pendulum.h5",
        crash_states(),
        state_order=("x", "y", "heading", "steer", "speed"),
    )
    with h5py.File(path, "a") as h5:
        h5.attrs["state_order"] = ["angle", "omega", "heading", "steer", "speed"]
    with pytest.raises(PlotInputError) as error:
        read_car_trajectory(path)
    assert str(error.value) == (
        f"{path}: state_order ['angle', 'omega', 'heading', 'steer', 'speed'] lacks x, y: "
        "not a car state"
    )
    with h5py.File(path, "a") as h5:
        del h5["t"]
    with pytest.raises(PlotInputError, match=f"^{path}: not a trajectory \\(it lacks t;"):
        read_car_trajectory(path)


def test_a_start_grid_with_missing_parts(tmp_path):
    path = write_start_grid(tmp_path / "grid.h5")
    with h5py.File(path, "a") as h5:
        del h5["collided"]
        del h5.attrs["destination"]
    with pytest.raises(PlotInputError) as error:
        plot_success_map(path, tmp_path / "map.png")
    assert str(error.value) == f"{path}: not a start grid (datasets): missing collided"
    with h5py.File(path, "a") as h5:
        h5["collided"] = np.zeros(4, dtype=bool)
    with pytest.raises(PlotInputError) as error:
        plot_success_map(path, tmp_path / "map.png")
    assert str(error.value) == f"{path}: not a start grid (root attributes): missing destination"
    with h5py.File(path, "a") as h5:
        h5.attrs["destination"] = json.dumps(DESTINATION)
    with pytest.raises(PlotInputError) as error:
        plot_success_map(path, tmp_path / "map.png")
    assert str(error.value) == f"{path}: /collided has shape (4,), expected (8,)"
    assert not (tmp_path / "map.png").exists()


@pytest.mark.parametrize("name", ["excluded", "cost_to_go", "path_length"])
def test_a_start_grid_with_a_wrong_shaped_new_dataset(tmp_path, name):
    path = write_start_grid(tmp_path / "grid.h5")
    with h5py.File(path, "a") as h5:
        values = h5[name].asstr()[()] if name == "excluded" else h5[name][()]
        del h5[name]
        dtype = h5py.string_dtype() if name == "excluded" else None
        h5.create_dataset(name, data=values.reshape(2, 4), dtype=dtype)
    for plot in (plot_success_map, plot_consistency):
        with pytest.raises(PlotInputError) as error:
            plot(path, tmp_path / "x.png")
        assert str(error.value) == f"{path}: /{name} has shape (2, 4), expected (8,)"
    assert not (tmp_path / "x.png").exists()


def refusal(path: Path, change) -> str:
    """The PlotInputError message of reading the start grid ``path`` after ``change``(h5)."""
    with h5py.File(path, "a") as h5:
        change(h5)
    with pytest.raises(PlotInputError) as error:
        read_drawn_start_grid(path)
    return str(error.value)


def replace_texts(h5, name: str, texts) -> None:
    """The text dataset ``name`` of an open start grid, made ``texts`` (replaced if there)."""
    if name in h5:
        del h5[name]
    h5.create_dataset(name, data=np.asarray(texts, dtype=object), dtype=h5py.string_dtype())


def test_a_start_grid_with_bad_exclusions(tmp_path):
    path = write_start_grid(tmp_path / "grid.h5")
    with h5py.File(path) as h5:
        excluded = h5["excluded"].asstr()[()]
    guessed = excluded.astype(object)
    guessed[6] = "looks blocked"

    def numbers(name):
        def change(h5):
            del h5[name]
            h5[name] = np.zeros(8)

        return change

    strings = "must hold strings (h5py.string_dtype())"
    assert refusal(path, numbers("excluded")) == f"{path}: /excluded {strings}"
    assert refusal(path, lambda h5: replace_texts(h5, "excluded", guessed)) == (
        f"{path}: start 6 is excluded for an unknown reason 'looks blocked' (known: "
        f"{NOT_FREE!r}, {NO_WAY!r})"
    )
    replace = {"excluded": excluded, "excluded_detail": [""] * 8}
    with h5py.File(path, "a") as h5:
        for name, texts in replace.items():
            replace_texts(h5, name, texts)
    assert refusal(path, numbers("excluded_detail")) == f"{path}: /excluded_detail {strings}"
    assert refusal(path, lambda h5: replace_texts(h5, "excluded_detail", [""] * 7)) == (
        f"{path}: /excluded_detail has shape (7,), expected (8,)"
    )

    def collide(h5):
        replace_texts(h5, "excluded_detail", [""] * 8)
        h5["collided"][7] = True

    assert refusal(path, collide) == (
        f"{path}: start 7 is excluded ({NO_WAY}) but has an outcome: parked False, collided True"
    )


def test_no_trajectories(tmp_path):
    with pytest.raises(PlotInputError, match="no trajectories"):
        plot_parking_frames([], tmp_path / "x.png")


def test_the_frames_legend_fits_the_figure_for_one_panel_or_three(parks, crashes, lost):
    """Four legend columns, right under three panels, ran off both sides of one panel."""
    for paths in ([parks], [parks, crashes, lost]):
        figure = parking_frames_figure(paths)
        figure.canvas.draw()
        (legend,) = figure.legends
        box = legend.get_window_extent()
        assert box.x0 >= 0 and box.x1 <= figure.bbox.width and box.y0 >= 0
