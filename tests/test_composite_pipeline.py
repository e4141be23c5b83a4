"""A composite motion end to end (§3): the script bound to real BSR controllers, Figure 5's
search, the result file's contract, its table and the robustness comparison."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest
from contract_check import composite_result_problems

from mosys.bsr.search import nominal_run
from mosys.cli import main
from mosys.composite.measures import phase_measures
from mosys.composite.result_file import composite_to_file
from mosys.composite.robustness import bind_spec, fitness_from_starts, perturbed_starts
from mosys.composite.session import open_session
from mosys.io.bsr_result import read_bsr_result
from mosys.io.composite_result import CompositeMotion, read_composite_result
from mosys.io.trajectory import FigureMotion
from mosys.paper_tables.composite import composite_frame
from mosys.paper_tables.robustness import robustness_frame
from mosys.parsing.composite import parse_composite_script
from mosys.parsing.tokens import SpecError

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"


def session_of(workspace, script_path=None):
    script = parse_composite_script(script_path or workspace.script)
    return open_session(script, workspace.controller_files(), SPECS / "figures", SPECS / "bsr")


def test_the_result_file_keeps_the_contract(composite_workspace):
    # DESIGN.md's result, read as another tool reads it (tests/contract_check.py)
    assert composite_result_problems(composite_workspace.result, composite_workspace.script) == []
    with h5py.File(composite_workspace.result, "r") as h5:
        for group in ("figure_motion", "before/figure_motion"):
            assert h5[f"{group}/endpoints"].shape[1:] == (5, 2, 2)
            assert np.all(np.diff(h5[f"{group}/t"][()]) > 0)
        assert h5.attrs["simulations"] == 4 * 3 * 2 + 1  # Q x G x H mutants and the guess
        phases = json.loads(h5.attrs["phases"])
        guess = json.loads(h5.attrs["phases_before"])
    assert [p["ticks"] for p in guess] == [215, 150, 100]
    for listed in (phases, guess):
        assert [p["controller"] for p in listed] == [
            "starman_cartwheel_robust",
            "starman_jump_robust",
            "starman_shuffle_robust",
        ]
        assert listed[0]["start"] == 0.0
        assert all(a["end"] == b["start"] for a, b in zip(listed, listed[1:], strict=False))
        assert listed[-1]["end"] == pytest.approx(4.65)
        assert all(p["end"] - p["start"] == pytest.approx(p["ticks"] * 0.01) for p in listed)


def test_the_stored_scores_are_the_sessions(composite_workspace):
    result = read_composite_result(composite_workspace.result)
    session = session_of(composite_workspace)
    for stored, ticks, total, scores in (
        (result.before, result.attrs["ticks_before"], "score_before", result.scores_before),
        (result.after, result.attrs["ticks_after"], "score_after", result.scores_after),
    ):
        scored = session.score(ticks)
        assert scored.total == result.attrs[total]
        assert scored.scores == scores
        np.testing.assert_array_equal(stored.motion.endpoints, scored.motion.rod_ends)
        np.testing.assert_array_equal(stored.phase, scored.motion.phase)
    curve = result.best_by_generation
    assert np.all(np.diff(curve) >= 0) and curve[-1] == result.attrs["score_after"]
    assert result.attrs["score_after"] >= result.attrs["score_before"]


def test_the_search_is_deterministic(composite_workspace, tmp_path):
    again = tmp_path / "again.h5"
    composite_to_file(
        composite_workspace.script,
        composite_workspace.controller_files(),
        again,
        SPECS / "figures",
        SPECS / "bsr",
        {"q": 4, "g": 3, "h": 2},
        budget="test",
    )
    first, second = (read_composite_result(p) for p in (composite_workspace.result, again))
    np.testing.assert_array_equal(first.after.motion.endpoints, second.after.motion.endpoints)
    np.testing.assert_array_equal(first.best_by_generation, second.best_by_generation)
    assert first.attrs["phases"] == second.attrs["phases"]


def test_each_phase_takes_the_seed_best_from_the_nominal_start(composite_workspace, tmp_path):
    session = session_of(composite_workspace)
    for phase, seed in zip(session.script.phases, session.seeds, strict=True):
        files = composite_workspace.controller_files()[phase.controller]
        nominal = {
            int(read_bsr_result(f).attrs["seed"]): read_bsr_result(f).attrs["nominal_fitness"]
            for f in files
        }
        assert seed == max(nominal, key=nominal.get)
    # seed= on a phase line overrides the choice
    text = composite_workspace.script.read_text()
    other = 3 - session.seeds[1]
    script = tmp_path / "seeded.comp"
    script.write_text(
        text.replace(
            "controller=starman_jump_robust", f"controller=starman_jump_robust seed={other}"
        )
    )
    assert session_of(composite_workspace, script).seeds[1] == other


def test_the_motion_starts_from_the_first_searchs_start_pose(composite_workspace):
    session = session_of(composite_workspace)
    setup = bind_spec(SPECS / "bsr" / "starman_cartwheel_robust.bsr", SPECS / "figures")
    files = composite_workspace.controller_files()["starman_cartwheel_robust"]
    chosen = next(f for f in files if f.name == f"seed{session.seeds[0]}.h5")
    run = nominal_run(setup, read_bsr_result(chosen).controller)
    motion = session.run([100, 50, 50])
    np.testing.assert_array_equal(motion.rod_ends[:101], run.rod_ends[:101])


def test_seed_files_of_two_builds_of_a_search_are_refused(composite_workspace, tmp_path):
    """A seed left from an earlier build (another G) beside a rebuilt one was mixed in without
    a word: the best of them was taken as the phase's controller."""
    import h5py

    files = composite_workspace.controller_files()
    folder = tmp_path / "starman_jump_robust"
    folder.mkdir()
    mixed = [shutil.copy(path, folder / Path(path).name) for path in files["starman_jump_robust"]]
    with h5py.File(mixed[1], "r+") as stale:
        stale.attrs["generations"] = 200
    files["starman_jump_robust"] = [Path(path) for path in mixed]
    script = parse_composite_script(composite_workspace.script)
    with pytest.raises(SpecError) as error:
        open_session(script, files, SPECS / "figures", SPECS / "bsr")
    assert str(error.value) == (
        f"{script.path}:9:28: expected the seed files of one build of starman_jump_robust "
        f"({folder / 'seed1.h5'} and {folder / 'seed2.h5'} differ in generations: rebuild or "
        "remove the stale ones, or name a seed), found 'starman_jump_robust'"
    )


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            ("controller=starman_jump_robust", "controller=starman_hop"),
            f":9:28: expected a BSR search (no spec {SPECS / 'bsr/starman_hop.bsr'}), "
            "found 'starman_hop'",
        ),
        (
            ("controller=starman_jump_robust", "controller=starman_jump_robust seed=7"),
            ":9:53: expected a built seed of starman_jump_robust (1, 2), found '7'",
        ),
        (
            ("figure starman", "figure beryl"),
            ":8:28: expected a search of figure 'beryl' (starman_cartwheel_robust moves "
            "'starman'), found 'starman_cartwheel_robust'",
        ),
    ],
)
def test_what_the_script_names_must_exist(composite_workspace, tmp_path, edit, message):
    script = tmp_path / "seeded.comp"
    script.write_text(composite_workspace.script.read_text().replace(*edit))
    with pytest.raises(SpecError) as error:
        session_of(composite_workspace, script)
    assert str(error.value) == f"{script}{message}"


def test_a_phase_whose_search_is_not_among_the_controllers_given_says_so(
    composite_workspace, tmp_path, capsys
):
    jump = composite_workspace.controller_files()["starman_jump_robust"][0]
    script = composite_workspace.script
    argv = ["composite", script, "--controllers", jump, "-o", tmp_path / "c.h5"]
    assert main([str(arg) for arg in argv]) == 2
    assert capsys.readouterr().err.strip() == (
        f"{script}:8:28: expected a built BSR search (no --controllers file "
        "starman_cartwheel_robust/seedK.h5: snakemake results/composite/SCRIPT.h5 builds a "
        "script's searches first), found 'starman_cartwheel_robust'"
    )
    assert not list(tmp_path.iterdir())


def test_a_result_of_another_search_in_a_phases_folder_is_refused(composite_workspace, tmp_path):
    """The files are grouped by folder: one of another search (the same figure) copied into
    the jump's folder is refused at the phase's controller, not run as the jump."""
    files = composite_workspace.controller_files()
    stray = tmp_path / "starman_jump_robust" / "seed1.h5"
    stray.parent.mkdir()
    shutil.copy(files["starman_shuffle_robust"][0], stray)
    files["starman_jump_robust"] = [stray]
    script = parse_composite_script(composite_workspace.script)
    with pytest.raises(SpecError) as error:
        open_session(script, files, SPECS / "figures", SPECS / "bsr")
    assert str(error.value) == (
        f"{script.path}:9:28: expected results of the search starman_jump_robust ({stray} is a "
        "result of starman_shuffle_robust), found 'starman_jump_robust'"
    )


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            ("total = (1.0 + cartwheel)", "total = (1.0 + cartwheels)"),
            ":22:16: expected a phase name, one of cartwheel, jump, shuffle, found 'cartwheels'",
        ),
        (
            ("max_t(min_i(y_i(t)))", "max_t(min_i(y_i(t))"),
            ":18:55: expected ')' to close 'max_t(' at column 24, found end of line",
        ),
        (
            ("max_t(min_i(y_i(t)))", "mean_t(min_i(y_i(t)))"),
            ":18:19: expected a function before '(' (one of max_t, min_t, max_i, min_i), "
            "found 'mean_t'",
        ),
    ],
)
def test_a_malformed_script_fails_at_its_column_and_writes_nothing(
    composite_workspace, tmp_path, capsys, edit, message
):
    script = tmp_path / "bad.comp"
    text = composite_workspace.script.read_text()
    assert edit[0] in text
    script.write_text(text.replace(*edit))
    output = tmp_path / "out.h5"
    code = main(
        [
            "composite",
            str(script),
            "--bsr-results",
            str(composite_workspace.bsr_results),
            "--q",
            "2",
            "--g",
            "1",
            "--h",
            "1",
            "-o",
            str(output),
        ]
    )
    assert code == 2
    assert capsys.readouterr().err == f"{script}{message}\n"
    assert not output.exists() and not list(tmp_path.glob(".*partial"))


def test_a_search_the_pipeline_has_no_results_for_is_named_at_its_column(
    composite_workspace, tmp_path, capsys
):
    # the workflow passes every seed file of the phases' searches; a misspelt search has none
    script = tmp_path / "typo.comp"
    script.write_text(
        composite_workspace.script.read_text().replace("=starman_jump_robust", "=starman_jmp")
    )
    files = [
        str(f) for f in (composite_workspace.bsr_results / "starman_cartwheel_robust").glob("*.h5")
    ]
    output = tmp_path / "out.h5"
    assert main(["composite", str(script), "--controllers", *files, "-o", str(output)]) == 2
    assert capsys.readouterr().err == (
        f"{script}:9:28: expected a BSR search (no spec specs/bsr/starman_jmp.bsr), "
        "found 'starman_jmp'\n"
    )
    # the specs are checked first, then the results: the shipped script with none given
    script = composite_workspace.script
    assert main(["composite", str(script), "--controllers", "-o", str(output)]) == 2
    assert capsys.readouterr().err == (
        f"{script}:8:28: expected a built BSR search (no --controllers file "
        "starman_cartwheel_robust/seedK.h5: snakemake results/composite/SCRIPT.h5 builds a "
        "script's searches first), found 'starman_cartwheel_robust'\n"
    )
    empty = tmp_path / "bsr"
    assert main(["composite", str(script), "--bsr-results", str(empty), "-o", str(output)]) == 2
    assert capsys.readouterr().err == (
        f"{script}:8:28: expected a built BSR search (no {empty}/starman_cartwheel_robust/"
        "seed*.h5: snakemake results/composite/SCRIPT.h5 builds a script's searches first), "
        "found 'starman_cartwheel_robust'\n"
    )
    assert not output.exists()


def test_the_cli_writes_the_result(composite_workspace, tmp_path, capsys):
    output = tmp_path / "show.h5"
    files = [str(f) for fs in composite_workspace.controller_files().values() for f in fs]
    code = main(
        [
            "composite",
            str(composite_workspace.script),
            "--controllers",
            *files,
            "--q",
            "4",
            "--g",
            "3",
            "--h",
            "2",
            "--budget",
            "test",
            "-o",
            str(output),
        ]
    )
    assert code == 0
    assert "215, 150, 100" in capsys.readouterr().out
    ours, theirs = (read_composite_result(p) for p in (output, composite_workspace.result))
    assert ours.attrs["score_after"] == theirs.attrs["score_after"]


def stored(endpoints: np.ndarray, phase: np.ndarray) -> CompositeMotion:
    n = endpoints.shape[0]
    motion = FigureMotion(
        t=np.arange(n) * 0.01,
        endpoints=endpoints,
        com=endpoints.mean(axis=(1, 2)),
        rod_names=("a",),
        rod_mass=np.ones(1),
        rod_length=np.ones(1),
        rod_com=np.full(1, 0.5),
        rod_inertia=np.ones(1),
        gravity=9.81,
        terrain=[],
        contact="none",
    )
    return CompositeMotion(motion=motion, phase=phase, active_rule=np.zeros(n, np.int64))


def test_phase_measures_count_turns_distance_and_clearance():
    # one rod spinning about its middle: 1.5 turns over phase 0, then rising 0.5 m in phase 1
    angle = np.concatenate([np.linspace(0, 3 * np.pi, 101), np.full(50, 3 * np.pi)])
    centre = np.stack([np.linspace(0, 2, 151), np.r_[np.ones(101), np.linspace(1, 1.5, 50)]], 1)
    half = 0.5 * np.stack([np.cos(angle), np.sin(angle)], 1)
    ends = np.stack([centre - half, centre + half], 1)[:, None]
    phase = np.r_[np.zeros(101, np.int64), np.ones(50, np.int64)]
    first, second = phase_measures(stored(ends, phase))
    assert first.rotations == pytest.approx(1.5)
    assert first.distance == pytest.approx(centre[101, 0] - centre[0, 0])
    assert first.clearance == pytest.approx(1.0)  # the lowest end is at 1 - 0.5 |sin|
    assert second.rotations == pytest.approx(0.0, abs=1e-9)
    assert second.clearance == pytest.approx(1.5)  # level, its middle risen to 1.5 m
    assert first.flight == second.flight == 0.0  # never on the ground


def test_a_flight_counts_from_the_phases_first_touchdown():
    # a level rod falling from 1 m to the ground at sample 60, then hopping to 0.3 m
    height = np.r_[np.linspace(1.0, 0.0, 61), 0.3 * np.sin(np.linspace(0, np.pi, 40))]
    ends = np.zeros((101, 1, 2, 2))
    ends[:, 0, 1, 0] = 1.0
    ends[:, 0, :, 1] = height[:, None]
    first, second = phase_measures(
        stored(ends, np.r_[np.zeros(31, np.int64), np.ones(70, np.int64)])
    )
    assert first.clearance == 1.0 and first.flight == 0.0
    assert second.clearance == pytest.approx(1 - 31 / 60) and second.flight == pytest.approx(
        0.3, abs=1e-3
    )


def test_robustness_compares_both_twins_on_the_same_starts(composite_workspace):
    setup = bind_spec(SPECS / "bsr" / "starman_jump_robust.bsr", SPECS / "figures")
    path = composite_workspace.bsr_results / "starman_jump_robust" / "seed1.h5"
    result = read_bsr_result(path)
    start = nominal_run(setup, result.controller)  # the nominal start reproduces the attr
    assert start.terms @ setup.weights == pytest.approx(result.attrs["nominal_fitness"])
    starts = perturbed_starts(setup, setup.spec.perturbation, 5, 1)
    np.testing.assert_array_equal(starts, perturbed_starts(setup, setup.spec.perturbation, 5, 1))
    fitness = fitness_from_starts(setup, result.controller, starts)
    assert fitness.shape == (5,) and np.unique(fitness).size > 1
    plain = composite_workspace.root / "plain" / "starman_jump"
    plain.mkdir(parents=True)
    shutil.copy(path, plain / "seed1.h5")  # a stand-in twin: the same controller
    frame = robustness_frame(
        [("starman_jump_robust", "starman_jump")],
        [path, plain / "seed1.h5"],
        SPECS / "bsr",
        SPECS / "figures",
        starts=5,
    )
    assert list(frame["controller"]) == ["robust", "plain"]
    assert frame["chosen perturbed mean"].iloc[0] == pytest.approx(round(fitness.mean(), 2))


def test_the_composite_table(composite_workspace):
    frame = composite_frame([composite_workspace.result])
    row = frame.iloc[0]
    assert row["script"] == "starman_show" and row["budget"] == "test"
    assert row["simulations"] == 25 and row["Q x G x H"] == "4 x 3 x 2"
    assert row["cartwheel ticks before"] == 215
    assert (
        row["cartwheel ticks after"] + row["jump ticks after"] + row["shuffle ticks after"] == 465
    )


def test_the_markdown_table_leaves_another_scripts_phases_empty_and_keeps_nan():
    """The CSV leaves the cells of phases a script does not have empty; the Markdown showed
    nan there, which its caption gives to a division by zero."""
    from mosys.paper_tables.composite import markdown_table

    rows = [
        {"script": "one", "a score after": float("nan")},
        {"script": "two", "b score after": 1.5},
    ]
    frame = pd.DataFrame(rows)
    lines = markdown_table(frame, rows).splitlines()
    cells = [[cell.strip() for cell in line.strip("|").split("|")] for line in lines[2:]]
    assert cells == [["one", "nan", ""], ["two", "", "1.5"]]
