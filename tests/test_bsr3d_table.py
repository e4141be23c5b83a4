"""The 3-D BSR runs table (``mosys bsr3d-table``) from small synthetic 3-D search results
written with ``write_bsr_result``: Rex walking (four seeds, two tying for the best), Rex turning
from the walk's best seed, Cujo bounding on the ci budget. Every number the rows hold is
checked exactly against values worked out by hand from the files' attributes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from mosys.cli import main
from mosys.errors import InputError
from mosys.io.bsr_result import BsrController, BsrResult, write_bsr_result
from mosys.io.trajectory import FigureMotion
from mosys.paper_tables.bsr import speed_up
from mosys.paper_tables.bsr3d import (
    COLUMNS,
    PAPER_FIGURE,
    SPEED_UP,
    budget_sentence,
    runs3d_frame,
    write_bsr3d_table,
)

SAMPLES = 5  # of each motion, 0.1 s apart
RODS = 2


def motion(dimensions: int) -> FigureMotion:
    """Two rods standing on end and sliding along x: a 3-D motion (x, y, z; y up), or its 2-D
    (x, y) counterpart."""
    t = np.linspace(0.0, 0.4, SAMPLES)
    endpoints = np.zeros((SAMPLES, RODS, 2, dimensions))
    endpoints[:, :, :, 0] = t[:, None, None]
    endpoints[:, 0, 1, 1] = endpoints[:, 1, 0, 1] = 0.5
    endpoints[:, 1, 1, 1] = 1.0
    com = np.zeros((SAMPLES, dimensions))
    com[:, 0], com[:, 1] = t, 0.5
    extra = {"heading_rod": "lower", "feet": ((0, 0),)} if dimensions == 3 else {}
    return FigureMotion(
        t=t,
        endpoints=endpoints,
        com=com,
        rod_names=("lower", "upper"),
        rod_mass=np.ones(RODS),
        rod_length=np.full(RODS, 0.5),
        rod_com=np.full(RODS, 0.5),
        rod_inertia=np.full(RODS, 0.02),
        gravity=9.81,
        terrain=[[-100.0, 0.0], [100.0, 0.0]],
        contact="penalty",
        dimensions=dimensions,
        **extra,
    )


def write_seed(directory: Path, name: str, seed: int, dimensions: int = 3, **attrs) -> Path:
    """``directory/name/seedK.h5``: a time-based search's seed file whose root attributes are
    those below, ``attrs`` replacing or (with value None) removing some."""
    terms = {
        "distance": 0.5 * seed,
        "sideways": 0.1234,
        "heading_change": -12.34,
        "max_height": 0.6,
        "fall": 0.0,
        "heading_deviation": 0.05,
        "feet_distance": 0.4,
        "foot_steps": 7,
        "contact_distance": 0.3,
        "rotations": 0.0,
    }
    root = {
        "name": name,
        "figure": "rex",
        "controller_kind": "time",
        "seed": seed,
        "evaluations": 2000,
        "duration": 10.0,
        "dt": 0.01,
        "best_fitness": 1.0,
        "fitness_weights": json.dumps({"distance": 1.0, "sideways": -0.5}),
        "fitness_terms": json.dumps(terms),
        "spec_sha256": "0" * 64,
        "wall_seconds": 3.0,
        "chain": "",
        "chain_seed": 0,
        "budget": "paper",
        "generations": 20,
        "controllers": 100,
        "reseed": 10,
        "rules": 4,
        "period": 1.2,
        "tau_min": 0.05,
        "steps": 1000,
        "steps_per_second": 5.0e5,
        "threads": 1,
        "searched_variables": 47,
        "min_com_height": 0.3,
        "standing_com_height": 0.6,
    }
    root.update(attrs)
    empty = np.zeros((4, 0))
    result = BsrResult(
        evaluations=np.array([100, int(root.get("evaluations") or 100)], np.int64),
        best_fitness=np.array([0.0, float(root.get("best_fitness") or 0.0)]),
        controller=BsrController(
            "time", np.zeros((4, 1)), np.full(4, 0.1), empty, empty, np.full(4, 0.3), 1.2
        ),
        motion=motion(dimensions),
        active_rule=np.zeros(SAMPLES, np.int64),
        joint_names=("knee",),
        sense_names=(),
        attrs={key: value for key, value in root.items() if value is not None},
    )
    path = directory / name / f"seed{seed}.h5"
    path.parent.mkdir(parents=True, exist_ok=True)
    write_bsr_result(path, result)
    return path


@pytest.fixture(scope="module")
def seed_files(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """The seed files, searches interleaved: rex_walk seeds 1-4 (ms per evaluation 1.5, 2.5,
    1.0, 3.0; best fitness 1.0, 4.25, 4.25, 2.0), rex_turn (chained on rex_walk's seed 2, 120 ms
    per evaluation), cujo_bound (ci budget, 1500 steps)."""
    root = tmp_path_factory.mktemp("bsr3d")
    walk = {
        1: {"wall_seconds": 3.0, "best_fitness": 1.0},
        2: {"wall_seconds": 5.0, "best_fitness": 4.25},
        3: {"wall_seconds": 4.0, "evaluations": 4000, "best_fitness": 4.25},
        4: {"wall_seconds": 6.0, "best_fitness": 2.0},
    }
    paths = [write_seed(root, "rex_walk", seed, **attrs) for seed, attrs in walk.items()]
    turn = write_seed(
        root,
        "rex_turn",
        1,
        chain="rex_walk",
        chain_seed=2,
        evaluations=100,
        wall_seconds=12.0,
        best_fitness=33.3333,
    )
    cujo = write_seed(
        root,
        "cujo_bound",
        5,
        figure="cujo",
        budget="ci",
        generations=2,
        rules=5,
        searched_variables=34,
        steps=1500,
        duration=3.0,
        dt=0.002,
        evaluations=400,
        wall_seconds=0.6,
        min_com_height=0.26,
        standing_com_height=0.4,
        best_fitness=2.5,
    )
    return [paths[0], paths[1], turn, paths[2], cujo, paths[3]]


def test_one_row_per_search_in_the_order_first_met(seed_files: list[Path]) -> None:
    frame = runs3d_frame(seed_files)
    assert list(frame.columns) == list(COLUMNS)
    assert list(frame["search"]) == ["rex_walk", "rex_turn", "cujo_bound"]
    assert list(frame["seeds"]) == [4, 1, 1]


def test_rows_hold_the_medians_the_speed_up_and_the_best_seeds_terms(
    seed_files: list[Path],
) -> None:
    frame = runs3d_frame(seed_files).set_index("search")
    walk = frame.loc["rex_walk"].to_dict()
    # ms per evaluation: median of 1.5, 2.5, 1.0, 3.0; 1,000 steps per evaluation: 300 / 2.0
    assert walk == {
        "figure": "rex",
        "kind": "time",
        "chain": "",
        "rules": 4,
        "searched variables": 47,
        "T (s)": 10.0,
        "dt (s)": 0.01,
        "steps per evaluation": 1000,
        "budget": "paper",
        "generations": 20,
        "threads": 1,
        "seeds": 4,
        "evaluations per seed": 2000,
        "wall per seed (s)": 4.5,
        "ms per evaluation": 2.0,
        "ms per 1,000 steps": 2.0,
        "paper": PAPER_FIGURE,
        SPEED_UP: "150x",
        "best fitness": 4.25,
        "median fitness": 3.125,
        "best seed": 2,  # ties with seed 3: the lowest seed
        "distance (m)": 1.0,
        "sideways (m)": 0.123,
        "heading change (deg)": -12.3,
        "foot steps": 7,
        "lowest com / standing com": 0.5,
    }
    turn = frame.loc["rex_turn"]
    assert turn["chain"] == "rex_walk (seed 2)"
    assert (turn["ms per evaluation"], turn["ms per 1,000 steps"]) == (120.0, 120.0)
    assert turn[SPEED_UP] == "2.5x"
    assert (turn["best fitness"], turn["median fitness"]) == (33.333, 33.333)
    cujo = frame.loc["cujo_bound"]
    # 0.6 s / 400 evaluations = 1.5 ms per 1,500 steps: 1.0 ms per 1,000 steps
    assert cujo[["figure", "chain", "rules", "searched variables", "T (s)", "dt (s)"]].tolist() == [
        "cujo",
        "",
        5,
        34,
        3.0,
        0.002,
    ]
    assert cujo[["steps per evaluation", "budget", "generations"]].tolist() == [1500, "ci", 2]
    assert cujo[["ms per evaluation", "ms per 1,000 steps", SPEED_UP]].tolist() == [
        1.5,
        1.0,
        "300x",
    ]
    assert (cujo["best seed"], cujo["distance (m)"], cujo["lowest com / standing com"]) == (
        5,
        2.5,
        0.65,
    )


def test_speed_up_text() -> None:
    assert [speed_up(ratio) for ratio in (2400.4, 10.0, 9.87, 2.5, 0.123)] == [
        "2400x",
        "10x",
        "9.9x",
        "2.5x",
        "0.12x",
    ]


def test_budget_sentence_names_the_budget_of_every_row() -> None:
    one = pd.DataFrame({"search": ["a", "b"], "budget": ["ci", "ci"]})
    assert budget_sentence(one) == "All rows: the ci budget."
    mixed = pd.DataFrame({"search": ["a", "b", "c"], "budget": ["ci", "paper", "ci"]})
    assert budget_sentence(mixed) == "Budget ci: a, c; paper: b."


def test_writes_csv_and_markdown(seed_files: list[Path], tmp_path: Path) -> None:
    csv_path, md_path = tmp_path / "tables" / "bsr3d_runs.csv", tmp_path / "bsr3d_runs.md"
    frame = write_bsr3d_table(seed_files, str(csv_path), str(md_path))
    read_back = pd.read_csv(csv_path, keep_default_na=False)
    assert list(read_back.columns) == list(COLUMNS)
    assert read_back["search"].tolist() == frame["search"].tolist()
    assert read_back["chain"].tolist() == ["", "rex_walk (seed 2)", ""]
    assert read_back["ms per 1,000 steps"].tolist() == [2.0, 120.0, 1.0]
    caption, table = md_path.read_text(encoding="utf-8").split("\n\n", 1)
    assert caption.startswith("3-D BSR searches after Auslander et al. (1995), §4: ")
    assert "Budget paper: rex_walk, rex_turn; ci: cujo_bound." in caption
    assert table == frame.to_markdown(index=False) + "\n"
    assert sorted(path.name for path in tmp_path.rglob("*")) == [
        "bsr3d_runs.csv",
        "bsr3d_runs.md",
        "tables",
    ]


def test_cli_writes_the_table(seed_files: list[Path], tmp_path: Path) -> None:
    csv_path, md_path = tmp_path / "runs.csv", tmp_path / "runs.md"
    arguments = ["bsr3d-table", *map(str, seed_files), "--csv", str(csv_path), "--md", str(md_path)]
    assert main(arguments) == 0
    assert pd.read_csv(csv_path)["search"].tolist() == ["rex_walk", "rex_turn", "cujo_bound"]
    assert md_path.read_text(encoding="utf-8").startswith("3-D BSR searches")


def test_no_files_is_an_error() -> None:
    with pytest.raises(InputError) as error:
        runs3d_frame([])
    assert str(error.value) == "no 3-D BSR result files given"


def test_a_2d_result_is_refused_and_nothing_written(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    flat = write_seed(tmp_path, "starman_walk", 1, dimensions=2)
    csv_path, md_path = tmp_path / "runs.csv", tmp_path / "runs.md"
    assert main(["bsr3d-table", str(flat), "--csv", str(csv_path), "--md", str(md_path)]) == 2
    assert capsys.readouterr().err == (
        f"mosys: {flat}: a 2-D search result; bsr3d-table tabulates 3-D searches (bsr-table the "
        "2-D ones)\n"
    )
    assert not csv_path.exists() and not md_path.exists()


def test_bsr_table_refuses_a_3d_result_and_writes_nothing(
    seed_files: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    csv_path, md_path = tmp_path / "runs.csv", tmp_path / "runs.md"
    spatial = str(seed_files[0])
    assert main(["bsr-table", spatial, "--csv", str(csv_path), "--md", str(md_path)]) == 2
    assert capsys.readouterr().err == (
        f"mosys: {spatial}: a 3-D search result; bsr-table tabulates 2-D searches (bsr3d-table "
        "the 3-D ones)\n"
    )
    assert not csv_path.exists() and not md_path.exists()


def test_a_missing_attribute_or_term_is_named(tmp_path: Path) -> None:
    old = write_seed(tmp_path, "old", 1, chain=None, searched_variables=None)
    with pytest.raises(InputError) as error:
        runs3d_frame([old])
    assert str(error.value) == (
        f"{old}: not a 3-D BSR result file: no root attribute chain, searched_variables"
    )
    terms = json.dumps({"distance": 1.0, "sideways": 0.0, "heading_change": 0.0})
    no_steps = write_seed(tmp_path, "no_steps", 1, fitness_terms=terms)
    with pytest.raises(InputError) as error:
        runs3d_frame([no_steps])
    assert str(error.value) == f"{no_steps}: fitness_terms has no foot_steps"


def test_the_2d_table_names_a_missing_attribute_or_term(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """``mosys bsr-table`` stopped with a KeyError traceback, exit 1, on a file without a fitness
    term or a root attribute it reads (the 3-D table named them)."""
    csv_path, md_path = tmp_path / "runs.csv", tmp_path / "runs.md"
    terms = json.dumps({"distance": 1.0, "max_height": 0.5, "contact_distance": 0.0})
    cases = (
        (
            write_seed(tmp_path, "no_fall", 1, 2, fitness_terms=terms),
            "fitness_terms has no rotations, fall",
        ),
        (
            write_seed(tmp_path, "no_rate", 1, 2, steps_per_second=None),
            "not a 2-D BSR result file: no root attribute steps_per_second",
        ),
    )
    for path, message in cases:
        argv = ["bsr-table", str(path), "--csv", str(csv_path), "--md", str(md_path)]
        assert main(argv) == 2
        assert capsys.readouterr().err == f"mosys: {path}: {message}\n"
        assert not csv_path.exists() and not md_path.exists()


def test_seeds_of_one_search_must_share_their_set_up(tmp_path: Path) -> None:
    paths = [
        write_seed(tmp_path, "rex_turn", 1, chain="rex_walk", chain_seed=2),
        write_seed(tmp_path, "rex_turn", 2, chain="rex_walk", chain_seed=3),
    ]
    with pytest.raises(InputError) as error:
        runs3d_frame(paths)
    assert str(error.value) == (
        "search 'rex_turn': its seed files differ in chain_seed (seed 1: 2, seed 2: 3)"
    )
