"""The car scene decoder (io.car_scene): one reading of the scene attributes for the runtime,
the parking judgement and the plots; what it writes reads back the same; bad attributes raise
InputError naming the file."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from mosys.errors import InputError
from mosys.io.car_scene import car_scene_attributes, has_car_scene, read_car_scene

OUTLINE = [[0.8, -0.85], [0.8, 0.85], [-3.2, 0.85], [-3.2, -0.85]]
CURB = [[-20.0, -1.0], [20.0, -1.0], [20.0, 0.0], [-20.0, 0.0]]
FRONT = [[3.0, 0.15], [7.0, 0.15], [7.0, 1.85], [3.0, 1.85]]


def table_attrs() -> dict:
    """The scene attributes of a car controller table, as h5py reads them."""
    return {
        "body_outline": json.dumps(OUTLINE),
        "obstacles": json.dumps([CURB, FRONT]),
        "obstacle_names": np.array(["curb", "front_car"], dtype=object),
        "wheelbase": 2.5,
        "domain": json.dumps([[-2.25, 0.5], [8.0, 0.5], [8.0, 4.0], [-2.25, 4.0]]),
    }


def test_a_table_scene_with_its_dest():
    scene = read_car_scene(table_attrs(), "park.h5", {"x": 0.0, "y": 1.15, "heading": 0.0})
    assert scene.body_outline.tolist() == OUTLINE
    assert [p.tolist() for p in scene.obstacles] == [CURB, FRONT]
    assert scene.obstacle_names == ("curb", "front_car")
    assert scene.destination == {"x": 0.0, "y": 1.15, "heading": 0.0}
    assert scene.wheelbase == 2.5
    assert scene.domain.shape == (4, 2)


def test_written_attributes_read_back_the_same_scene():
    scene = read_car_scene(table_attrs(), "park.h5", {"x": 0.0, "y": 1.15, "heading": 0.0})
    written = car_scene_attributes(scene)
    assert written["destination"] == '{"x": 0.0, "y": 1.15, "heading": 0.0}'
    again = read_car_scene(written, "park_1.h5")
    assert again.body_outline.tolist() == OUTLINE
    assert [p.tolist() for p in again.obstacles] == [CURB, FRONT]
    assert again.obstacle_names == scene.obstacle_names
    assert again.destination == scene.destination
    # trajectories carry the domain, which the plots draw (they used to leave it out)
    np.testing.assert_array_equal(again.domain, scene.domain)
    no_domain = car_scene_attributes(dataclasses.replace(scene, domain=np.zeros((0, 2))))
    assert "domain" not in no_domain


def test_a_vehicle_without_obstacles_has_no_scene():
    assert not has_car_scene({"wheelbase": 2.5})
    assert has_car_scene(table_attrs())


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            {"body_outline": "[[0, 0], [1, 1]]"},
            "t.h5: body_outline must be a list of at least 3 [x, y] vertices, got [[0, 0], [1, 1]]",
        ),
        (
            {"obstacles": "[[0, 0"},
            "t.h5: root attribute obstacles is not valid JSON (Expecting ',' delimiter: line 1 "
            "column 7 (char 6))",
        ),
        (
            {"obstacle_names": np.array(["curb"], dtype=object)},
            "t.h5: 2 obstacles but 1 obstacle_names ['curb']",
        ),
        (
            {"destination": '{"x": 1}'},
            't.h5: destination must be {"x": m, "y": m, "heading": deg}, got {\'x\': 1}',
        ),
        (
            {"obstacles": json.dumps([CURB, [[0, 0], [1, "nan"], [0, 1]]])},
            "t.h5: obstacle front_car has a non-finite vertex",
        ),
    ],
)
def test_bad_attributes_name_the_file_and_the_problem(change, message):
    attrs = car_scene_attributes(
        read_car_scene(table_attrs(), "park.h5", {"x": 0.0, "y": 1.15, "heading": 0.0})
    )
    attrs["obstacle_names"] = np.array(["curb", "front_car"], dtype=object)
    attrs.update(change)
    with pytest.raises(InputError) as error:
        read_car_scene(attrs, "t.h5")
    assert str(error.value) == message


def test_a_missing_attribute_is_named():
    attrs = table_attrs()
    del attrs["body_outline"]
    with pytest.raises(InputError) as error:
        read_car_scene(attrs, "t.h5", {"x": 0.0, "y": 0.0, "heading": 0.0})
    assert str(error.value) == "t.h5: not a car scene (root attributes): missing body_outline"
