"""results/bsr3d_all built by the real workflow at CI's reduced budget (config/ci.yaml: G = 20,
two seeds): the files keep the 3-D contracts, Rex's three searches chain through their result
files (each starts where the best seed of the one before ends, and editing the turn reruns the
turn and the second walk only), and the physics rules hold on every motion built."""

from __future__ import annotations

import json
import re

import h5py
import pandas as pd
import pytest
from contract_check import chain_problems, contract_problems
from test_workflow import copy_workflow, edited_spec, planned_jobs, snakemake

from mosys.bsr.lone_contact import lone_contacts, sliding
from mosys.io.bsr_result import read_bsr_result

CI = ("--configfile", "config/ci.yaml")
SEARCHES = (
    "cujo_bound",
    "rex_walk",
    "rex_turn",
    "rex_walk_again",
    "rex_walk_sense",
    "bob_walk",
    "bob_walk_time",
)
SINK = 0.01  # m: no endpoint goes further into the floor than this
CHAIN = {"rex_turn": "rex_walk", "rex_walk_again": "rex_turn"}  # search -> the one it continues


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    work = copy_workflow(tmp_path_factory.mktemp("bsr3d"))
    snakemake(work, "results/bsr3d_all", *CI)
    return work


def results(work, name):
    return sorted((work / "results/bsr" / name).glob("seed*.h5"))


@pytest.mark.slow
def test_bsr3d_all_builds_every_search_plot_and_the_table(built):
    listed = (built / "results/bsr3d_all").read_text()
    for name in SEARCHES:
        assert len(results(built, name)) == 2
        assert f"results/bsr/{name}/seed1.h5" in listed
        assert (built / "results/plots/bsr3d" / name / "learning.png").stat().st_size > 10_000
    for motion in ("cujo", "rex", "bob", "bob_time"):
        for plot in ("filmstrip.png", "motion.gif", "rest.png"):
            assert (built / "results/plots/bsr3d" / motion / plot).stat().st_size > 10_000
    for plot in ("learning_kinds.png", "seeds.png"):
        assert (built / "results/plots/bsr3d" / plot).stat().st_size > 10_000
    table = (built / "results/tables/bsr3d_runs.csv").read_text()
    assert all(name in table for name in SEARCHES)
    assert table.count(",ci,") == len(SEARCHES)


@pytest.mark.slow
def test_every_3d_result_keeps_the_contract(built):
    # DESIGN.md's BSR result and 3-D figure_motion as another tool reads them
    # (tests/contract_check.py: shapes, attributes, the terms measured again on the motion)
    counts, problems = contract_problems(built)
    assert counts["bsr result"] == 2 * len(SEARCHES)
    assert problems == []
    for name in SEARCHES:
        for path in results(built, name):
            with h5py.File(path, "r") as h5:
                motion = h5["best/figure_motion"]
                rods = len(motion.attrs["rod_names"])
                assert int(motion.attrs["dimensions"]) == 3
                assert motion.attrs["heading_rod"] in list(motion.attrs["rod_names"])
                feet = json.loads(motion.attrs["feet"])
                assert feet and all(0 <= rod < rods and end in (0, 1) for rod, end in feet)
                assert h5.attrs["chain"] == CHAIN.get(name, "")
                # unchained searches start facing +x
                if not h5.attrs["chain"]:
                    assert motion["com"][0, 2] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.slow
def test_each_of_rexs_searches_starts_where_the_best_seed_of_the_one_before_ends(built):
    for name, before in CHAIN.items():
        assert results(built, name) and results(built, before)
    # tests/contract_check.py: each chained seed's chain_seed is the best seed of the search it
    # continues (the highest best_fitness, the lowest seed on a tie), and its first sample is
    # that seed's last, bit for bit
    assert chain_problems(built / "results") == []


@pytest.mark.slow
def test_no_endpoint_sinks_and_no_lone_contact_slides_in_any_3d_motion(built):
    for name in SEARCHES:
        for path in results(built, name):
            motion = read_bsr_result(path).motion
            assert motion.endpoints[..., 1].min() > -SINK
            assert sliding(lone_contacts(motion.t, motion.endpoints)) == []


@pytest.mark.slow
def test_editing_the_turn_reruns_the_turn_and_the_second_walk_not_the_first(built):
    spec = built / "specs/bsr/rex_turn.bsr"
    text = spec.read_text()
    edited = re.sub(r"heading_sine=[\d.]+", "heading_sine=3.5", text)
    assert edited != text
    with edited_spec(spec, edited):
        jobs = planned_jobs(built, "results/bsr3d_all", *CI)
        output = snakemake(built, "--dry-run", "results/bsr3d_all", *CI)
    searched = sorted(re.findall(r"wildcards: name=(\w+), seed=(\d+)", output))
    assert searched == [(name, seed) for name in ("rex_turn", "rex_walk_again") for seed in "12"]
    assert jobs == {
        "bsr_search": 4,
        "bsr3d_motion_plots": 1,
        "bsr3d_search_learning": 2,
        "bsr3d_runs_table": 1,
        "bsr3d_targets_table": 1,
        "bsr3d_all": 1,
    }


@pytest.mark.slow
def test_the_targets_table_measures_each_target_on_the_files(built):
    frame = pd.read_csv(built / "results/tables/bsr3d_targets.csv", keep_default_na=False)
    assert list(frame["search"]) == [
        "cujo_bound",
        "rex_walk -> rex_turn -> rex_walk_again",
        "bob_walk",
        "bob_walk_time vs bob_walk",
        "every motion",
    ]
    # Cujo's body lengths, measured again: the best seed's distance over his spine's length
    best = max(
        (read_bsr_result(path) for path in results(built, "cujo_bound")),
        key=lambda result: (result.attrs["best_fitness"], -result.attrs["seed"]),
    )
    lengths = best.fitness_terms["distance"] / best.motion.rod_length[0]
    assert frame["measured"][0].startswith(f"{lengths:.2f} body lengths")
    assert frame["met"][0] == (
        "yes" if lengths >= 3 and "fell" not in frame["measured"][0] else "no"
    )
    # Rex: an angle only between walks long enough to have a direction (at the CI budget a
    # walk of a few centimetres gave one)
    rex = re.fullmatch(
        r"(\d+) deg apart|no direction to compare \(a walk under 0.5 m\)",
        frame["measured"][1].split(";")[0],
    )
    walked = [float(m) for m in re.findall(r"([\d.]+) m", frame["measured"][1].split(";")[1])]
    assert rex is not None and len(walked) == 2
    assert (rex[1] is not None) == (min(walked) >= 0.5)
    if rex[1] is None:
        assert frame["met"][1] == "no"
    # the physics holds at any budget
    assert frame["met"][4] == "yes"
    assert set(frame["budget"]) == {"ci"}  # the physics row's too (it was left blank)
