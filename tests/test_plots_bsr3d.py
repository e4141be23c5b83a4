"""The 3-D BSR plots (Figures 15-17 as a filmstrip and a GIF, Figures 7 and 8, a figure at rest)
from small synthetic search results: a seven-rod stick dog (a spine, a head, four legs, a tail)
walking 1 m forward, turning 90° to its left on the spot, and walking 1 m on, written with
``write_bsr_result`` as three chained searches ``dog_walk`` -> ``dog_turn`` -> ``dog_walk2``
(two seeds each; the chain goes through seed 1 of the first two, the best), and a time-based and
a sense-based search of a few seeds with made-up non-decreasing learning curves. The figures
are checked through their matplotlib artists."""

from __future__ import annotations

import dataclasses
import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import assert_png
from hypothesis import given
from hypothesis import strategies as st
from matplotlib.collections import LineCollection, PolyCollection
from PIL import Image

import mosys.plots.bsr3d as bsr3d
import mosys.plots.bsr3d_learning as bsr3d_learning
import mosys.plots.bsr_learning as bsr_learning
import mosys.plots.figure_at_rest as figure_at_rest
import mosys.plots.scene3d as scene3d
from mosys.cli import main
from mosys.io.bsr_result import BsrController, BsrResult, read_bsr_result, write_bsr_result
from mosys.io.trajectory import FigureMotion
from mosys.plots.bsr3d import (
    chain_paths,
    filmstrip_figure,
    headings,
    join_chain,
    plot_filmstrip,
    write_motion_gif,
)
from mosys.plots.bsr3d_learning import (
    learning_kinds_figure,
    plot_learning_kinds,
    plot_seeds,
    seeds_figure,
)
from mosys.plots.bsr_learning import curves_on_grid
from mosys.plots.bsr_results import TITLE_WIDTH
from mosys.plots.figure_at_rest import figure_at_rest_figure, plot_figure_at_rest
from mosys.plots.scene3d import (
    FRONT,
    SIDE,
    TOP,
    Camera,
    camera_text,
    choose_camera,
    floor_cells,
    project,
)
from mosys.plots.style import (
    PlotInputError,
    controller_colors,
    frame_samples,
    lighten,
    samples_to_the_end,
)

DT = 0.01  # s between samples
SEGMENT = 2.0  # s: each search's motion
ROD_NAMES = ("spine", "head", "front_left", "front_right", "back_left", "back_right", "tail")
FEET = ((2, 1), (3, 1), (4, 1), (5, 1))
HIP, SHOULDER = np.array([-0.3, 0.5, 0.0]), np.array([0.3, 0.5, 0.0])


def dog_pose(time: float) -> np.ndarray:
    """The dog in its own frame (facing +x, y up, its hips over the origin's -0.3 m), its legs
    swinging (diagonal pairs together, a stride of 0.3 m, feet lifting 5 cm): (7, 2, 3) m."""
    swing = 0.15 * np.sin(2 * math.pi * time / 0.8 + np.array([0.0, math.pi, math.pi, 0.0]))
    lift = 0.05 * np.clip(np.cos(2 * math.pi * time / 0.8 + np.array([0, 1, 1, 0]) * math.pi), 0, 1)
    pose = np.zeros((7, 2, 3))
    pose[0] = HIP, SHOULDER
    pose[1] = SHOULDER, SHOULDER + [0.2, 0.2, 0.0]
    for leg, (top, side) in enumerate(((SHOULDER, -1), (SHOULDER, 1), (HIP, -1), (HIP, 1))):
        pose[2 + leg] = top, [top[0] + swing[leg], lift[leg], 0.12 * side]
    pose[6] = HIP, HIP + [-0.2, 0.1, 0.0]
    return pose


def dog_course(time: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where the dog's middle is (N, 3) m and its heading (N,) deg at global ``time`` (N,) s:
    1 m along +x in the first 2 s, a turn of 90° to the left on the spot in the next 2 s, then
    1 m along -z."""
    walk = np.clip(time / SEGMENT, 0, 1)
    turn = np.clip((time - SEGMENT) / SEGMENT, 0, 1)
    again = np.clip((time - 2 * SEGMENT) / SEGMENT, 0, 1)
    place = np.stack([walk, np.zeros_like(time), -again], axis=1)
    return place, 90.0 * turn


def dog_motion(start: float, duration: float = SEGMENT) -> FigureMotion:
    """The dog from global time ``start`` s for ``duration`` s, its own t from 0."""
    t = np.arange(0.0, duration + DT / 2, DT)
    place, heading = dog_course(start + t)
    endpoints = np.empty((len(t), 7, 2, 3))
    for n, time in enumerate(start + t):
        angle = math.radians(heading[n])
        c, s = math.cos(angle), math.sin(angle)
        turn = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])  # +x to (c, 0, -s): left from above
        endpoints[n] = dog_pose(time) @ turn.T + place[n]
    rods = len(ROD_NAMES)
    return FigureMotion(
        t=t,
        endpoints=endpoints,
        com=endpoints.mean(axis=(1, 2)),
        rod_names=ROD_NAMES,
        rod_mass=np.ones(rods),
        rod_length=np.linalg.norm(endpoints[0, :, 1] - endpoints[0, :, 0], axis=1),
        rod_com=np.full(rods, 0.5),
        rod_inertia=np.full(rods, 0.01),
        gravity=9.81,
        terrain=[[-1000.0, 0.0], [1000.0, 0.0]],
        contact="penalty",
        dimensions=3,
        heading_rod="spine",
        heading_offset=0.0,
        feet=FEET,
    )


def time_controller() -> BsrController:
    rng = np.random.default_rng(3)
    empty = np.zeros((4, 0))
    return BsrController(
        "time",
        rng.uniform(-0.5, 0.5, (4, 12)),
        rng.uniform(0.05, 0.3, 4),
        empty,
        empty,
        np.array([0.2, 0.2, 0.2, 0.2]),
        0.8,
    )


def write_dog_search(
    directory: Path,
    name: str,
    motion: FigureMotion,
    finals: dict[int, float],
    chain: str = "",
    chain_seed: int = 0,
    terms: dict | None = None,
) -> list[Path]:
    """A search's seed files ``directory/name/seedK.h5``, all with ``motion``, seed K's best
    fitness ``finals[K]``."""
    paths = []
    for seed, final in finals.items():
        evaluations = np.array([100, 1000, 5000, 20000], dtype=np.int64)
        result = BsrResult(
            evaluations=evaluations,
            best_fitness=final * np.array([0.2, 0.5, 0.9, 1.0]),
            controller=time_controller(),
            motion=motion,
            active_rule=np.zeros(len(motion.t), dtype=np.int64),
            joint_names=tuple(f"{rod}_{angle}" for rod in ROD_NAMES[1:] for angle in "θψ"),
            sense_names=(),
            attrs={
                "name": name,
                "figure": "cujo",
                "controller_kind": "time",
                "seed": seed,
                "evaluations": 20000,
                "best_fitness": final,
                "fitness_terms": json.dumps(
                    terms or {"distance": 1.0, "sideways": 0.01, "heading_change": 0.0}
                ),
                "fitness_weights": json.dumps({"distance": 1.0, "sideways": -1.0}),
                "chain": chain,
                "chain_seed": chain_seed,
                "duration": SEGMENT,
                "dt": 0.001,
                "budget": "test",
            },
        )
        path = directory / name / f"seed{seed}.h5"
        path.parent.mkdir(parents=True, exist_ok=True)
        write_bsr_result(path, result)
        paths.append(path)
    return paths


@pytest.fixture(scope="module")
def chain(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[Path]]:
    """dog_walk (seeds 1, 2: seed 1 the best) -> dog_turn (continuing seed 1; seeds 1, 2:
    seed 1 the best) -> dog_walk2 (continuing dog_turn's seed 1; seeds 1, 2: seed 2 the best).
    Seed 2 of dog_walk and dog_turn move the same as seed 1 but 0.5 m further along z."""
    root = tmp_path_factory.mktemp("bsr3d")
    walk, turn, again = (dog_motion(k * SEGMENT) for k in range(3))

    turned = {"distance": 0.0, "sideways": 0.0, "heading_change": 90.0}
    return {
        "dog_walk": write_dog_search(root, "dog_walk", walk, {1: 1.0})
        + write_dog_search(root, "dog_walk", shifted(walk), {2: 0.5}),
        "dog_turn": write_dog_search(root, "dog_turn", turn, {1: 90.0}, "dog_walk", 1, turned)
        + write_dog_search(root, "dog_turn", shifted(turn), {2: 80.0}, "dog_walk", 2, turned),
        "dog_walk2": write_dog_search(root, "dog_walk2", again, {1: 0.8, 2: 1.0}, "dog_turn", 1),
    }


def shifted(motion: FigureMotion, along_z: float = 0.5) -> FigureMotion:
    """``motion`` moved ``along_z`` m along z."""
    offset = np.array([0.0, 0.0, along_z])
    return dataclasses.replace(motion, endpoints=motion.endpoints + offset, com=motion.com + offset)


def chain_files(chain: dict[str, list[Path]]) -> list[Path]:
    """The chain through seed 1, seed 1 and seed 2."""
    return [chain["dog_walk"][0], chain["dog_turn"][0], chain["dog_walk2"][1]]


def write_learning(directory: Path, name: str, kind: str, finals: dict[int, float]) -> list[Path]:
    """A 3-D search of ``kind``, seed K's learning curve (made up: 60 records from 100 to
    150,000 evaluations, rising at a rate of its own) ending at ``finals[K]``."""
    paths = write_dog_search(directory, name, dog_motion(0.0, 0.5), finals)
    evaluations = np.unique(np.geomspace(100, 150_000, 60).astype(np.int64))
    for path, (seed, final) in zip(paths, finals.items(), strict=True):
        rise = 1 - np.exp(-evaluations / (8_000.0 * seed))
        best = final * rise / rise[-1]
        result = read_bsr_result(path)
        attrs = {**result.attrs, "controller_kind": kind}
        write_bsr_result(
            path,
            dataclasses.replace(result, evaluations=evaluations, best_fitness=best, attrs=attrs),
        )
    return paths


@pytest.fixture(scope="module")
def kinds(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[Path]]:
    """A time-based search 'dog_time' (4 seeds) and a sense-based one 'dog_sense' (3 seeds)."""
    root = tmp_path_factory.mktemp("kinds")
    return {
        "time": write_learning(root, "dog_time", "time", {1: 3.0, 2: 2.5, 3: 3.4, 4: 2.0}),
        "sense": write_learning(root, "dog_sense", "sense", {1: 2.0, 2: 1.2, 3: 2.6}),
    }


def flat_copy(path: Path, out: Path) -> Path:
    """``path`` rewritten with a 2-D figure (its x and y kept)."""
    result = read_bsr_result(path)
    motion = dataclasses.replace(
        result.motion,
        endpoints=result.motion.endpoints[..., :2],
        com=result.motion.com[:, :2],
        dimensions=2,
    )
    write_bsr_result(out, dataclasses.replace(result, motion=motion))
    return out


def legend_labels(legend) -> list[str]:
    return [text.get_text() for text in legend.get_texts()]


# --------------------------------------------------------------------------- the camera


def test_the_camera_views_project_as_drawn_by_hand() -> None:
    point = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(project(point, SIDE), [1.0, 2.0, 3.0], atol=1e-12)
    np.testing.assert_allclose(project(point, FRONT), [-3.0, 2.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(project(point, TOP), [1.0, -3.0, 2.0], atol=1e-12)
    # VIEW: 30° round from the right side towards the front, 30° up
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    np.testing.assert_allclose(project([1.0, 0.0, 0.0]), [c, -s * s, s * c], atol=1e-12)
    np.testing.assert_allclose(project([0.0, 1.0, 0.0]), [0.0, c, s], atol=1e-12)
    np.testing.assert_allclose(project([0.0, 0.0, -1.0]), [s, s * c, -c * c], atol=1e-12)
    assert project(np.zeros((4, 7, 2, 3))).shape == (4, 7, 2, 3)


@given(
    azimuth=st.floats(-180, 180),
    elevation=st.floats(-89, 90),
    point=st.lists(st.floats(-100, 100), min_size=3, max_size=3),
)
def test_every_camera_is_a_rotation_with_a_level_right_axis(
    azimuth: float, elevation: float, point: list[float]
) -> None:
    camera = Camera(azimuth, elevation)
    basis = camera.basis()
    np.testing.assert_allclose(basis @ basis.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(basis) == pytest.approx(1.0)  # right, up, towards: right-handed
    assert basis[0, 1] == 0.0  # the picture's right axis is level
    assert basis[2, 1] == pytest.approx(math.sin(math.radians(elevation)))
    seen = project(np.array(point), camera)
    assert np.linalg.norm(seen) == pytest.approx(np.linalg.norm(point), abs=1e-9)


def test_a_motion_is_seen_from_where_its_poses_spread_out() -> None:
    """A walk straight forward from the default view; a walk away from it (-z, after a left
    turn) from as far round as the views go; an L of both from between; a figure standing
    still, or moving less than a tenth of its size, from the default (the first of equals)."""
    forward = np.array([[0.6 * k, 0.5, 0.0] for k in range(6)])
    away = np.array([[0.0, 0.5, -0.6 * k] for k in range(6)])
    turned = np.concatenate([forward, forward[-1] + away[1:] * [1.0, 0.0, 1.0]])
    assert choose_camera(forward, 2.0) == Camera(30.0)
    assert choose_camera(away, 2.0) == Camera(60.0)
    assert choose_camera(turned, 2.0) == Camera(45.0)  # both walks alike: halfway
    assert choose_camera(np.repeat(forward[:1], 4, axis=0), 2.0) == Camera(30.0)
    assert choose_camera(away * 0.1, 20.0) == Camera(30.0)
    assert camera_text(Camera(45.0)) == (
        "seen from its front right (45° round from its right side), 30° above the floor"
    )
    assert camera_text(Camera(0.0, 0.0)) == "seen from its right side, 0° above the floor"


def test_floor_squares_are_nice_and_aligned_to_the_world() -> None:
    points = np.array([[0.0, 0.3, 0.0], [1.0, 0.5, -1.0]])
    cell, x_edges, z_edges = floor_cells(points, margin=0.1, size=1.0)
    assert cell == 0.2  # a fifth of the figure's size
    np.testing.assert_allclose(x_edges, np.arange(-1, 7) * 0.2)
    np.testing.assert_allclose(z_edges, np.arange(-6, 2) * 0.2)
    far = np.array([[0.0, 0.0, 0.0], [40.0, 0.0, 0.0]])  # long: at most 30 squares
    assert floor_cells(far, margin=0.1, size=1.0)[0] == 2.0


# --------------------------------------------------------------------------- reading a chain


def test_the_chain_is_joined_into_one_continuous_motion(chain: dict[str, list[Path]]) -> None:
    joined = join_chain(chain_files(chain))
    motion = joined.motion
    assert joined.names == ("dog_walk", "dog_turn", "dog_walk2")
    assert len(motion.t) == 3 * 201 - 2  # each hand-over sample once
    np.testing.assert_array_equal(joined.starts, [0, 200, 400])
    assert motion.t[0] == 0.0 and motion.t[-1] == pytest.approx(6.0)
    assert np.all(np.diff(motion.t) > 0)
    step = np.linalg.norm(np.diff(motion.endpoints, axis=0), axis=-1).max()
    assert step < 0.05  # no jump anywhere, the hand-overs included
    np.testing.assert_array_equal(np.bincount(joined.segment), [201, 200, 200])
    np.testing.assert_allclose(motion.com[-1, [0, 2]], [1.0, -1.0], atol=0.05)
    heading = headings(motion)
    assert heading[[0, 200, 300, 400, -1]] == pytest.approx([0, 0, 45, 90, 90], abs=1e-9)


def test_chain_paths_follow_the_chain_seeds_back_from_the_best_last(
    chain: dict[str, list[Path]],
) -> None:
    everything = [path for paths in chain.values() for path in reversed(paths)]
    assert chain_paths(everything) == chain_files(chain)
    assert chain_paths(chain["dog_walk"]) == [chain["dog_walk"][0]]  # the best seed


def test_join_chain_says_what_does_not_join(chain: dict[str, list[Path]], tmp_path: Path) -> None:
    walk, turn = chain["dog_walk"][0], chain["dog_turn"][0]
    with pytest.raises(PlotInputError) as error:
        join_chain([turn, walk])
    assert str(error.value) == (
        f"{walk}: search dog_walk continues no search, so it cannot follow {turn} (search "
        "dog_turn): give a chain's files in order, each search after the one it continues"
    )
    other = chain["dog_walk"][1]
    with pytest.raises(PlotInputError) as error:
        join_chain([other, turn])
    assert (
        str(error.value)
        == f"{turn}: search dog_turn continues seed 1 of dog_walk, not seed 2 ({other})"
    )
    turn_apart = shifted(dog_motion(SEGMENT), 0.25)
    apart = write_dog_search(tmp_path, "dog_turn", turn_apart, {1: 1.0}, "dog_walk", 1)[0]
    with pytest.raises(PlotInputError) as error:
        join_chain([walk, apart])
    assert str(error.value) == (
        f"{apart}: its first pose is 0.25 m from the last pose of {walk} (at most 0.001 m: a "
        "chained search starts where the one it continues ends)"
    )
    flat = flat_copy(walk, tmp_path / "flat.h5")
    with pytest.raises(PlotInputError) as error:
        join_chain([flat])
    assert str(error.value) == (
        f"{flat}: best/figure_motion is the motion of a 2-D figure; this plot draws 3-D figures "
        "(mosys plot bsr draws 2-D ones)"
    )
    with pytest.raises(PlotInputError) as error:
        join_chain([])
    assert str(error.value) == "no BSR result files given"


# --------------------------------------------------------------------------- the filmstrip


def test_filmstrip_draws_the_chain_as_one_motion(chain: dict[str, list[Path]]) -> None:
    files = chain_files(chain)
    figure = filmstrip_figure(files, interval=0.5)
    scene, colorbar, key = figure.axes
    joined = join_chain(files)
    assert figure.get_suptitle().splitlines()[:2] == [
        "cujo: the chained BSR searches dog_walk → dog_turn → dog_walk2",
        "poses every 0.5 s from 0 s to 6 s, coloured by search, light → dark, with their "
        "shadows; the centre of mass's path on the floor (■ start, ● hand-over)",
    ]
    # the chain turns left and walks on, away from the default view: seen from further round
    assert figure.get_suptitle().splitlines()[2:] == [
        "arrows: the heading at the start of each search and at the end; floor squares 0.25 m",
        "seen from its front right (45° round from its right side), 30° above the floor",
    ]
    size = scene3d.pose_size(joined.motion.endpoints)
    posed = joined.motion.com[samples_to_the_end(joined.motion.t, 0.5)]
    camera = choose_camera(posed, size)
    assert camera == Camera(45.0)
    # the whole floor, as that camera sees it, lies within the picture
    edges = floor_cells(joined.motion.endpoints, scene3d.FLOOR_MARGIN * size, size)[1:]
    corners = project(scene3d.floor_corners(*edges), camera)
    for axis, limits in enumerate((scene.get_xlim(), scene.get_ylim())):
        assert limits[0] < corners[:, axis].min() and corners[:, axis].max() < limits[1]
    # the poses: one stick figure every 0.5 s, coloured by search, light to dark
    poses = [c for c in scene.collections if isinstance(c, LineCollection) and c.get_path_effects()]
    assert len(poses) == 13
    colors = bsr3d.search_colors(joined)
    drawn = {tuple(np.round(c.get_color()[0], 6)) for c in poses}
    assert tuple(np.round(lighten(colors[0], bsr3d.LIGHTEST), 6)) in drawn  # t = 0
    assert tuple(np.round(colors[2], 6)) in drawn  # t = 6 s, the last search's end
    # the centre of mass's path on the floor: one line per search, each starting where the
    # one before ends
    paths = [line for line in scene.lines if line.get_linewidth() == bsr3d.PATH_WIDTH]
    assert [line.get_color() for line in paths] == colors
    for before, after in zip(paths, paths[1:], strict=False):
        np.testing.assert_allclose(before.get_xydata()[-1], after.get_xydata()[0])
    floor_com = joined.motion.com * [1.0, 0.0, 1.0]
    np.testing.assert_allclose(paths[0].get_xydata()[0], project(floor_com[0], camera)[:2])
    np.testing.assert_allclose(paths[-1].get_xydata()[-1], project(floor_com[-1], camera)[:2])
    # the floor, the heading arrows, the legend and the colour bar of time
    (floor,) = [c for c in scene.collections if isinstance(c, PolyCollection)]
    size = scene3d.pose_size(joined.motion.endpoints)
    _, x_edges, z_edges = floor_cells(joined.motion.endpoints, scene3d.FLOOR_MARGIN * size, size)
    assert len(floor.get_paths()) == (len(x_edges) - 1) * (len(z_edges) - 1)
    assert len(scene.texts) == 4  # the heading at each search's start and at the end
    (legend,) = figure.legends
    assert legend_labels(legend) == [
        "dog_walk: time-based controller, seed 1, t 0–2 s, fitness 1\n"
        "    distance +1.00 m, sideways 0.01 m, heading change +0.0 deg",
        "dog_turn: time-based controller, seed 1, t 2–4 s, fitness 90\n"
        "    distance +0.00 m, sideways 0.00 m, heading change +90.0 deg",
        "dog_walk2: time-based controller, seed 2, t 4–6 s, fitness 1\n"
        "    distance +1.00 m, sideways 0.01 m, heading change +0.0 deg",
    ]
    assert colorbar.get_ylabel() == "time t (s)"
    assert sorted(line.get_ydata()[0] for line in colorbar.lines) == pytest.approx([2.0, 4.0])
    assert [text.get_text() for text in key.texts if text.get_text()] == ["x", "y", "z"]
    arrows = [text for text in key.texts if getattr(text, "arrow_patch", None)]
    tips = np.array([arrow.xy for arrow in arrows])  # each world axis as the camera sees it
    np.testing.assert_allclose(tips, project(np.eye(3), camera)[:, :2])


def test_filmstrip_of_one_search_chooses_its_poses(
    chain: dict[str, list[Path]], tmp_path: Path
) -> None:
    figure = filmstrip_figure(chain["dog_walk"][:1])
    title = figure.get_suptitle()
    assert title.startswith("cujo: the best motion of BSR search dog_walk\nposes every 0.4 s")
    assert "(■ its start)" in title and "hand-over" not in title
    poses = [c for c in figure.axes[0].collections if c.get_path_effects()]
    # 1 m covered by a figure 1.19 m long: 1 + 3 / 1.19 poses, so the fewest, about 6
    assert scene3d.pose_size(read_bsr_result(chain["dog_walk"][0]).motion.endpoints) == (
        pytest.approx(math.hypot(0.95, 0.7, 0.12), abs=0.01)
    )
    assert bsr3d.pose_count(join_chain(chain["dog_walk"][:1])) == bsr3d.POSE_COUNT[0] == 6
    assert len(poses) == 6
    out = tmp_path / "walk.png"
    plot_filmstrip(chain_files(chain), out)
    assert_png(out, least_width=800)


def test_motion_gif_of_a_chain_is_real_time(chain: dict[str, list[Path]], tmp_path: Path) -> None:
    out = tmp_path / "chain.gif"
    write_motion_gif(chain_files(chain), out)
    t = join_chain(chain_files(chain)).motion.t
    samples, step = frame_samples(t, 25, 150)
    assert step == 0.05  # 6 s in at most 150 frames
    with Image.open(out) as gif:
        assert gif.n_frames == len(samples) == 121
        assert gif.info["duration"] == 50
        assert 400 < gif.size[0] < 800
    assert 10_000 < out.stat().st_size < 3_000_000
    assert not list(tmp_path.glob(".*.partial"))
    short = tmp_path / "short.gif"
    write_motion_gif(chain["dog_walk"][:1], short, max_frames=9)
    with Image.open(short) as gif:
        assert gif.n_frames == 9 and gif.info["duration"] == 250


# --------------------------------------------------------------------------- learning curves


def test_learning_kinds_figure(kinds: dict[str, list[Path]]) -> None:
    figure = learning_kinds_figure(kinds["time"], kinds["sense"])
    (ax,) = figure.axes
    assert figure.get_suptitle() == (
        "Learning curves for both kinds of motion controller: cujo\n"
        "time-based dog_time (4 seeds) vs sense-based dog_sense (3 seeds)\n"
        "fitness = 1·distance − 1·sideways"
    )
    assert ax.get_xlabel() == "controller evaluations (count)"
    assert ax.get_ylabel() == "best fitness so far (Σ weight × term)"
    assert ax.get_xscale() == "linear"
    faint = [line for line in ax.lines if line.get_alpha() == bsr3d_learning.SEED_ALPHA]
    bold = [line for line in ax.lines if line.get_linewidth() == bsr3d_learning.MEDIAN_WIDTH]
    assert len(faint) == 7
    assert [line.get_linestyle() for line in bold] == ["--", "-"]  # time dashed, sense solid
    results = [read_bsr_result(path) for path in kinds["sense"]]
    grid, values = curves_on_grid(results)
    np.testing.assert_allclose(bold[1].get_ydata(), np.nanmedian(values, axis=0))
    assert [text.get_text() for text in ax.texts] == ["2.75", "2"]  # the final medians
    # both beyond the longest curve's end, apart: a shorter curve's label sat on the other
    right = max(line.get_xdata()[-1] for line in bold)
    assert all(text.get_position()[0] > right for text in ax.texts)
    heights = sorted(text.get_position()[1] for text in ax.texts)
    low, high = ax.get_ylim()
    assert heights[1] - heights[0] >= 0.9 * (high - low) * (11.5 / 72) / (
        ax.get_position().height * figure.get_size_inches()[1]
    )
    (legend,) = figure.legends
    assert legend_labels(legend) == [
        "dog_time (time-based): median over 4 seeds",
        "dog_time: each seed",
        "dog_sense (sense-based): median over 3 seeds",
        "dog_sense: each seed",
    ]
    logged = learning_kinds_figure(kinds["time"], [], log_x=True)
    assert logged.axes[0].get_xscale() == "log"
    assert logged.axes[0].get_xlabel() == "controller evaluations (count, log scale)"


def test_learning_kinds_cuts_off_a_first_population_far_below(
    kinds: dict[str, list[Path]], tmp_path: Path
) -> None:
    """Rex's first population's -7.7 (60 of 60,000 evaluations, then 0.8 and up) squeezed the
    curves into the top of the plot: such a start is cut off and the cut noted."""
    low_start = []
    for path in kinds["time"]:
        result = read_bsr_result(path)
        best = result.best_fitness.copy()
        best[:2] = -40.0  # the first two records (100 and 113 evaluations) far below
        low_start.append(tmp_path / path.name)
        write_bsr_result(low_start[-1], dataclasses.replace(result, best_fitness=best))
    results = [read_bsr_result(path) for path in low_start + kinds["sense"]]
    cut = bsr_learning.cut_start(results, 150_000)
    # the curves rise: the lowest kept is the lowest held at 1 % of the axis, 1,500 evaluations
    kept = min(float(r.best_fitness[r.evaluations <= 1_500][-1]) for r in results)
    assert cut == bsr_learning.CutStart(
        low=pytest.approx(kept - bsr_learning.EARLY_PAD * (3.4 - kept)),
        high=pytest.approx(3.4 + bsr_learning.EARLY_TOP * (3.4 - kept)),  # not 5 % of 43.4
        evaluations=113,
        lowest=-40.0,
    )
    (ax,) = learning_kinds_figure(low_start, kinds["sense"]).axes
    assert ax.get_ylim() == pytest.approx((cut.low, cut.high))
    assert [text.get_text() for text in ax.texts] == [
        "↓ below the axis: the best of the first 113 evaluations, down to −40",
        "2.75",  # the final medians
        "2",
    ]
    # a start that stays within half the range is drawn whole, as is any start on a log axis
    assert bsr_learning.cut_start([read_bsr_result(p) for p in kinds["sense"]], 150_000) is None
    (logged,) = learning_kinds_figure(low_start, [], log_x=True).axes
    assert logged.get_ylim()[0] < -40 and len(logged.texts) == 1


def test_learning_kinds_title_fits_two_long_fitness_functions(
    kinds: dict[str, list[Path]], tmp_path: Path
) -> None:
    """Two searches' fitness functions side by side on one line ran off both edges."""
    weights = {
        "distance": 1, "feet_distance": 1, "sideways": -1, "fall": -100,
        "heading_deviation": -0.02, "min_height": 2, "foot_steps": 0.2,
    }  # fmt: skip
    sense = []
    for path in kinds["sense"]:
        result = read_bsr_result(path)
        attrs = {**result.attrs, "fitness_weights": json.dumps(weights)}
        sense.append(tmp_path / path.name)
        write_bsr_result(sense[-1], dataclasses.replace(result, attrs=attrs))
    title = learning_kinds_figure(kinds["time"], sense).get_suptitle()
    lines = title.splitlines()
    assert lines[2] == "dog_time: fitness = 1·distance − 1·sideways"
    assert lines[3].startswith("dog_sense: fitness = 1·distance + 1·feet_distance")
    assert len(lines) == 5 and "0.2·foot_steps" in lines[4]
    assert max(map(len, lines)) <= TITLE_WIDTH


def test_learning_kinds_errors(kinds: dict[str, list[Path]], chain: dict[str, list[Path]]) -> None:
    with pytest.raises(PlotInputError) as error:
        learning_kinds_figure(kinds["sense"], [])
    assert str(error.value) == (
        f"{kinds['sense'][0]}: a sense-based search's result given as time-based"
    )
    with pytest.raises(PlotInputError) as error:
        learning_kinds_figure([*kinds["time"], chain["dog_walk"][0]], [])
    assert str(error.value) == (
        "the time-based files are of more than one search (dog_time, dog_walk): give the seeds "
        "of one search per kind"
    )
    with pytest.raises(PlotInputError) as error:
        learning_kinds_figure([], [])
    assert str(error.value) == "plot_learning_kinds: no BSR result files given"


def test_seeds_figure_is_figure_8(kinds: dict[str, list[Path]], tmp_path: Path) -> None:
    figure = seeds_figure(kinds["sense"])  # one search: its learning figure
    curves, finals = figure.axes
    assert figure.get_suptitle().startswith(
        "BSR search dog_sense: sense-based controller for cujo, 3 seeds\n"
    )
    assert [line.get_label() for line in curves.lines] == ["seed 1", "seed 2", "seed 3"]
    assert [text.get_text() for text in finals.texts] == [
        "seed 1: 2.00",
        "seed 2: 1.20",
        "seed 3: 2.60",
    ]
    with pytest.raises(PlotInputError) as error:
        seeds_figure([])
    assert str(error.value) == "plot_seeds: no BSR result files given"
    out = tmp_path / "seeds.png"
    plot_seeds(kinds["sense"], out)
    assert_png(out, least_width=800)
    kinds_png = tmp_path / "kinds.png"
    plot_learning_kinds(kinds["time"], kinds["sense"], kinds_png)
    assert_png(kinds_png, least_width=800)


def test_seeds_figure_of_both_kinds(kinds: dict[str, list[Path]], tmp_path: Path) -> None:
    """Figure 8 with the other kind's seeds beside (Bob's walk, sense- and time-based): every
    seed's curve in its kind's style, and a column of final best fitness per kind, sense-based
    first, each named with its median below it and marked by a black bar."""
    figure = seeds_figure([*kinds["time"], *kinds["sense"]])
    curves, finals = figure.axes
    assert figure.get_suptitle() == (
        "Variability in search-algorithm performance: cujo\n"
        "sense-based dog_sense (3 seeds) vs time-based dog_time (4 seeds)\n"
        "fitness = 1·distance − 1·sideways"
    )
    assert [line.get_label() for line in curves.lines] == [
        *(f"dog_sense seed {seed}" for seed in (1, 2, 3)),
        *(f"dog_time seed {seed}" for seed in (1, 2, 3, 4)),
    ]
    assert {line.get_linestyle() for line in curves.lines[:3]} == {"-"}
    assert {line.get_linestyle() for line in curves.lines[3:]} == {"--"}
    assert [tick.get_text() for tick in finals.get_xticklabels()] == [
        "sense-based\nmedian 2.00",
        "time-based\nmedian 2.75",
    ]
    assert [text.get_text() for text in finals.texts] == [
        "seed 1: 2.00",
        "seed 2: 1.20",
        "seed 3: 2.60",
        "seed 1: 3.00",
        "seed 2: 2.50",
        "seed 3: 3.40",
        "seed 4: 2.00",
    ]
    dots = [line for line in finals.lines if line.get_marker() == "o"]
    sense_x, time_x = dots[0].get_xdata()[0], dots[-1].get_xdata()[0]
    assert sense_x < 0.5 < time_x  # a column each
    medians = [line for line in finals.lines if line.get_color() == "k"]
    assert [line.get_ydata()[0] for line in medians] == pytest.approx([2.0, 2.75])
    out = tmp_path / "both.png"
    plot_seeds([*kinds["sense"], *kinds["time"]], out)
    assert_png(out, least_width=800)
    other = write_learning(tmp_path, "dog_sense_again", "sense", {1: 1.0})
    with pytest.raises(PlotInputError) as error:
        seeds_figure([*kinds["sense"], *kinds["time"], *other])
    assert "more than one search" in str(error.value)


def test_close_finals_get_a_scale_of_their_own(tmp_path: Path) -> None:
    """Seeds that end close together after a long climb (Bob's five between 3.2 and 3.9 after
    starting at -50) are drawn on the finals panel's own scale, its range shaded behind the
    curves; seeds spread over the curves' range keep the curves' scale."""
    close = write_learning(tmp_path, "dog_close", "time", {1: 10.0, 2: 10.4, 3: 9.8})
    figure = seeds_figure(close)
    curves, finals = figure.axes
    low, high = finals.get_ylim()
    assert 9.0 < low < 9.8 and 10.4 < high < 11.0
    assert finals.get_title() == "final best fitness\n(the shaded band, enlarged)"
    (band,) = curves.patches
    assert band.get_y() == pytest.approx(low) and band.get_height() == pytest.approx(high - low)
    assert curves.get_ylim()[0] < 1.0  # the curves keep their whole range
    spread = seeds_figure(write_learning(tmp_path, "dog_spread", "time", {1: 1.0, 2: 10.0}))
    curves, finals = spread.axes
    assert finals.get_ylim() == curves.get_ylim()
    assert finals.get_title() == "final best fitness"
    assert not curves.patches


def write_curves(directory: Path, name: str, kind: str, finals: dict[int, float]) -> list[Path]:
    """A search whose seeds climb fast from about -60 and then creep up to ``finals[K]`` over
    the rest of 150,000 evaluations (Bob's walk): made up, as ``write_learning``."""
    paths = write_learning(directory, name, kind, finals)
    for path, (seed, final) in zip(paths, finals.items(), strict=True):
        result = read_bsr_result(path)
        e = result.evaluations.astype(float)
        best = final - 60.0 * np.exp(-e / 1_500.0) - 0.3 * seed * (1 - e / 150_000)
        write_bsr_result(path, dataclasses.replace(result, best_fitness=best))
    return paths


def assert_band_enlarges_the_late_progress(figure, late_low: float, late_high: float) -> None:
    """The curves drawn again under themselves in the range of their late progress, the finals
    beside them on that scale, the range shaded on the whole curves, the figure taller."""
    curves, finals, band = figure.axes
    low, high = band.get_ylim()
    assert finals.get_ylim() == (low, high) and low < late_low and late_high < high
    padded = 1 + 2 * bsr_learning.FINALS_PAD  # the late values' span, padded as the finals'
    assert high - low <= padded * bsr_learning.LATE_SPREAD * np.ptp(curves.get_ylim())
    for drawn, again in zip(curves.lines, band.lines, strict=True):
        np.testing.assert_array_equal(drawn.get_xdata(), again.get_xdata())
        np.testing.assert_array_equal(drawn.get_ydata(), again.get_ydata())
        assert (drawn.get_color(), drawn.get_linestyle()) == (
            again.get_color(),
            again.get_linestyle(),
        )
        assert drawn.get_drawstyle() == again.get_drawstyle() == "steps-post"
    (shade,) = curves.patches
    assert (shade.get_y(), shade.get_y() + shade.get_height()) == pytest.approx((low, high))
    assert band.get_xlabel() == "controller evaluations (count)" and not curves.get_xlabel()
    assert not any(label.get_visible() for label in curves.get_xticklabels())
    assert band.get_position().y1 < curves.get_position().y0  # under the curves
    assert finals.get_position().y0 == pytest.approx(band.get_position().y0)  # beside the band
    assert finals.get_title() == "final best fitness"
    height = bsr_learning.LEARNING_HEIGHT + bsr_learning.BAND_HEIGHT
    assert figure.get_size_inches() == pytest.approx((bsr_learning.LEARNING_WIDTH, height))


def test_late_progress_too_narrow_to_read_is_enlarged_under_the_curves(tmp_path: Path) -> None:
    """Bob's seeds climbed from -70 in the first 5,000 evaluations and then from 2.5 to 3.75
    over 55,000 more, which on that scale was one line: the curves are drawn again in the range
    of their late progress, and the finals beside them on that scale."""
    sense = write_curves(tmp_path, "bob_sense", "sense", {1: 3.2, 2: 3.9, 3: 3.5})
    late = np.concatenate(
        [bsr_learning.held_from(read_bsr_result(p), 0.25 * 150_000) for p in sense]
    )
    assert np.ptp(late) > 0.5  # the late progress: 2.9 to 3.9, each seed creeping up
    one = seeds_figure(sense)
    assert_band_enlarges_the_late_progress(one, late.min(), late.max())
    assert [text.get_text() for text in one.axes[1].texts] == [
        "seed 1: 3.20",
        "seed 2: 3.90",
        "seed 3: 3.50",
    ]
    time = write_curves(tmp_path, "bob_time", "time", {1: 2.4, 2: 2.9, 3: 2.1})
    late = np.concatenate(
        [bsr_learning.held_from(read_bsr_result(p), 0.25 * 150_000) for p in [*sense, *time]]
    )
    both = seeds_figure([*sense, *time])
    assert_band_enlarges_the_late_progress(both, late.min(), late.max())
    assert [tick.get_text() for tick in both.axes[1].get_xticklabels()] == [
        "sense-based\nmedian 3.50",
        "time-based\nmedian 2.40",
    ]
    out = tmp_path / "seeds.png"
    plot_seeds([*sense, *time], out)
    assert_png(out, least_width=800)


def test_late_progress_that_can_be_read_is_not_enlarged(kinds: dict[str, list[Path]]) -> None:
    """Seeds that climb over most of the search (Rex's walk) are read on the curves' own scale:
    no band, and the figure keeps its size."""
    figure = seeds_figure([*kinds["time"], *kinds["sense"]])
    assert len(figure.axes) == 2
    assert figure.get_size_inches() == pytest.approx(
        (bsr_learning.LEARNING_WIDTH, bsr_learning.LEARNING_HEIGHT)
    )
    assert (
        bsr_learning.late_band([read_bsr_result(p) for p in kinds["time"]], 150_000, -1.0, 4.0)
        is None
    )


def test_a_median_label_has_a_leader_only_where_its_curve_falls_short(
    kinds: dict[str, list[Path]], tmp_path: Path
) -> None:
    """Figure 7's final medians: a curve that runs to its label has no line before the number
    (a short line there read as a minus sign, '—5.61'); one that ends well before the longest
    has a dotted leader from its end."""
    (ax,) = learning_kinds_figure(kinds["time"], kinds["sense"]).axes
    labels = {text.get_text(): text for text in ax.texts}
    assert labels["2.75"].arrow_patch is None and labels["2"].arrow_patch is None
    shorter = []
    for path in kinds["sense"]:
        result = read_bsr_result(path)
        kept = result.evaluations <= 75_000
        shorter.append(tmp_path / path.name)
        write_bsr_result(
            shorter[-1],
            dataclasses.replace(
                result,
                evaluations=result.evaluations[kept],
                best_fitness=result.best_fitness[kept],
            ),
        )
    (ax,) = learning_kinds_figure(kinds["time"], shorter).axes
    labels = {text.get_text(): text for text in ax.texts}
    assert labels["2.75"].arrow_patch is None
    (short,) = [text for name, text in labels.items() if name != "2.75"]
    assert short.arrow_patch is not None and short.arrow_patch.get_linestyle() == ":"


# --------------------------------------------------------------------------- a figure at rest


def test_figure_at_rest(tmp_path: Path) -> None:
    motion = dog_motion(0.0)
    figure = figure_at_rest_figure(motion, "Cujo")
    main_view, key, side, front, top = figure.axes
    assert figure.get_suptitle() == (
        "Cujo at rest (t = 0 s): 7 rods, 7 kg, heading rod spine\n"
        "▲ the rod ends it walks on; the heading rod is drawn thicker"
    )
    assert main_view.get_title() == (
        "seen from its front right (30° round from its right side), 30° above the floor"
    )
    names = [text.get_text() for text in main_view.texts]
    assert sorted(names[:-1]) == sorted(ROD_NAMES) and names[-1] == "floor squares 0.25 m"
    assert [ax.get_title() for ax in (side, front, top)] == [
        "from its right side",
        "from its front",
        "from above",
    ]
    assert [(ax.get_xlabel(), ax.get_ylabel()) for ax in (side, front, top)] == [
        ("x (m)", "y (m)"),
        ("−z (m)", "y (m)"),
        ("x (m)", "−z (m)"),
    ]
    spans = {round(np.ptp(ax.get_xlim()), 9) for ax in (side, front, top)}
    assert len(spans) == 1  # one scale
    for ax in (main_view, side, front, top):
        feet = [line for line in ax.lines if line.get_marker() == figure_at_rest.FOOT_MARKER]
        assert len(feet) == 4
        rods = [line for line in ax.lines if line.get_marker() == "o"]
        widest = max(rods, key=lambda line: line.get_linewidth())
        assert widest.get_color() == controller_colors(list(ROD_NAMES))["spine"]
    # the side view shows the spine from hip to shoulder at 0.5 m
    spine = [line for line in side.lines if line.get_marker() == "o"]
    assert any(np.allclose(line.get_xydata(), [[-0.3, 0.5], [0.3, 0.5]]) for line in spine)
    out = tmp_path / "rest.png"
    plot_figure_at_rest(motion, out, "Cujo")
    assert_png(out, least_width=800)
    flat = dataclasses.replace(motion, endpoints=motion.endpoints[..., :2], dimensions=2)
    with pytest.raises(PlotInputError) as error:
        figure_at_rest_figure(flat)
    assert str(error.value) == (
        "plot_figure_at_rest: needs a 3-D figure's motion, endpoints (N, rods, 2, 3); got "
        "dimensions 2, endpoints (201, 7, 2, 2)"
    )


def test_rest_layout_puts_a_long_figures_small_views_under_it() -> None:
    """A long, low figure (Rex, Cujo) in the column layout's narrow oblique view left wide blank
    bands above and below it: its small views go in a row under a view as wide as the figure;
    a tall one (Bob) keeps them in a column beside it."""

    def inside(box, size) -> bool:
        left, bottom, width, height = box
        return left >= 0 and bottom >= 0 and left + width <= size[0] and bottom + height <= size[1]

    low = figure_at_rest.rest_layout(np.array([2.6, 1.0]), title_lines=2)
    tall = figure_at_rest.rest_layout(np.array([1.0, 1.6]), title_lines=2)
    for layout in (low, tall):
        assert all(inside(box, layout.size) for box in (layout.main, *layout.small))
    assert low.size[0] == tall.size[0]
    assert low.size[1] < tall.size[1]  # the blank bands gone
    assert low.main[2] > tall.main[2]  # a wider oblique view
    main_bottom = low.main[1]
    assert all(
        box[1] + box[3] + figure_at_rest.REST_SMALL_LABELS <= main_bottom + 1e-9
        for box in low.small
    )
    lefts = [box[0] for box in low.small]
    assert lefts == sorted(lefts) and all(  # side by side, apart
        right[0] - (left[0] + left[2]) >= figure_at_rest.REST_SMALL_LEFT
        for left, right in itertools.pairwise(low.small)
    )
    main_right = tall.main[0] + tall.main[2]
    assert all(box[0] >= main_right for box in tall.small)  # the column beside it
    tops = [box[1] for box in tall.small]
    assert tops == sorted(tops, reverse=True)  # side view, front view, top view down the page


# --------------------------------------------------------------------------- the command line


def test_cli_draws_the_chain_from_all_its_seeds(
    chain: dict[str, list[Path]], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    drawn = []
    real = bsr3d.plot_filmstrip

    def recorded(paths, path, *args):
        drawn.append(list(paths))
        return real(paths, path, *args)

    monkeypatch.setattr(bsr3d, "plot_filmstrip", recorded)
    strip, gif, rest = tmp_path / "strip.png", tmp_path / "chain.gif", tmp_path / "rest.png"
    files = [str(path) for paths in chain.values() for path in paths]
    code = main(
        ["plot", "bsr3d", *files, "--filmstrip", str(strip), "--gif", str(gif)]
        + ["--rest", str(rest), "--interval", "0.5"]
    )
    assert code == 0
    assert drawn == [chain_files(chain)]
    assert_png(strip, least_width=800)
    assert_png(rest, least_width=800)
    assert gif.stat().st_size > 10_000


def test_cli_learning_curves(kinds: dict[str, list[Path]], tmp_path: Path) -> None:
    compared, seeds = tmp_path / "kinds.png", tmp_path / "seeds.png"
    time_files, sense_files = map(str, kinds["time"]), map(str, kinds["sense"])
    command = ["plot", "bsr3d-kinds", "--time", *time_files, "--sense", *sense_files]
    assert main([*command, "-o", str(compared), "--log-x"]) == 0
    assert_png(compared, least_width=800)
    assert main(["plot", "bsr3d-seeds", *map(str, kinds["time"]), "-o", str(seeds)]) == 0
    assert_png(seeds, least_width=800)


def test_cli_rejects_bad_input(
    chain: dict[str, list[Path]], tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    flat = flat_copy(chain["dog_walk"][0], tmp_path / "flat.h5")
    out = tmp_path / "strip.png"
    assert main(["plot", "bsr3d", str(flat), "--filmstrip", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"mosys: {flat}: best/figure_motion is the motion of a 2-D figure; this plot draws 3-D "
        "figures (mosys plot bsr draws 2-D ones)\n"
    )
    assert not out.exists()
    for arguments in (
        ["plot", "bsr3d", str(flat)],  # no output asked for
        ["plot", "bsr3d", str(flat), "--filmstrip", str(out), "--interval", "0"],
        ["plot", "bsr3d-kinds", "-o", str(out)],
    ):
        with pytest.raises(SystemExit) as exit_:
            main(arguments)
        assert exit_.value.code == 2
    assert (
        "mosys plot bsr3d-kinds: error: give --time and/or --sense result files"
        in capsys.readouterr().err
    )
    files = [str(path) for path in chain_files(chain)]
    for option, value, message in (
        ("--azimuth", "200", "--azimuth must be between -180 and 180 deg, got 200.0"),
        ("--elevation", "-5", "--elevation must be between 0 and 90 deg, got -5.0"),
        ("--elevation", "nan", "--elevation must be between 0 and 90 deg, got nan"),
    ):
        with pytest.raises(SystemExit) as exit_:
            main(["plot", "bsr3d", *files, "--filmstrip", str(out), option, value])
        assert exit_.value.code == 2
        assert f"mosys plot bsr3d: error: {message}" in capsys.readouterr().err
    assert not out.exists()


def test_the_camera_can_be_given(
    chain: dict[str, list[Path]], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """--azimuth and --elevation: the camera as given; --elevation alone: the azimuth still
    chosen (the chain turns away from the default view: 45°), at that height."""
    drawn = []
    monkeypatch.setattr(bsr3d, "save_figure", lambda figure, path: drawn.append(figure))
    files = [str(path) for path in chain_files(chain)]
    out = str(tmp_path / "strip.png")
    for options, seen in (
        (["--azimuth", "0", "--elevation", "90"], "seen from above"),
        (["--azimuth", "10"], "seen from its front right (10° round from its right side), 30° "),
        (["--elevation", "60"], "seen from its front right (45° round from its right side), 60° "),
    ):
        assert main(["plot", "bsr3d", *files, "--filmstrip", out, *options]) == 0
        assert drawn.pop().get_suptitle().splitlines()[-1].startswith(seen)


def test_text_colour_reads_on_white() -> None:
    """tab20's pale halves named rods in text hard to read; dark colours are kept as they are."""
    from matplotlib.colors import to_rgb

    from mosys.plots.style import TEXT_LUMINANCE, text_color

    def luminance(rgb) -> float:
        linear = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in rgb]
        return 0.2126 * linear[0] + 0.7152 * linear[1] + 0.0722 * linear[2]

    for pale in ("#ffbb78", "#aec7e8", "#98df8a", "white"):
        assert luminance(text_color(pale)) <= TEXT_LUMINANCE
    assert text_color("#1f77b4") == to_rgb("#1f77b4")  # tab:blue reads already
