"""Mistakes the workflow catches before any job runs (dry runs of a copy of the workflow, nothing
built): a config key the schema does not know, a config naming a spec that is not there, a
target no rule makes, a spec that is missing
or malformed (the parser's own file:line:column message), and a controller drawn with its own
figure's dynamics."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from test_workflow import ROOT, copy_workflow, run_snakemake


@pytest.fixture(scope="module")
def work(tmp_path_factory) -> Path:
    return copy_workflow(tmp_path_factory.mktemp("mistakes"))


def dry_run(work: Path, *args: str):
    done = run_snakemake(work, "--dry-run", "--printshellcmds", *args)
    return done.returncode, done.stdout + done.stderr


def dry_run_with_spec(work: Path, spec: str, text: str, target: str):
    """``dry_run`` of ``target`` with ``text`` written to the spec ``spec`` (a path in the
    workflow) for the run only."""
    path = work / spec
    path.write_text(text, encoding="utf-8")
    try:
        return dry_run(work, target)
    finally:
        path.unlink()


def dry_run_with_edit(work: Path, shipped: str, copy: str, edit: tuple[str, str], target: str):
    """``dry_run_with_spec`` of a copy (``copy``) of the shipped spec ``shipped`` with one edit
    (old, new): (the number of the line edited, return code, output)."""
    text = (work / shipped).read_text(encoding="utf-8")
    line = next(n for n, row in enumerate(text.splitlines(), 1) if edit[0] in row)
    return (line, *dry_run_with_spec(work, copy, text.replace(*edit), target))


def test_a_mistyped_config_key_is_refused_before_anything_runs(work):
    code, output = dry_run(work, "results/pendulum_all", "--config", "bsr={generation: 5}")
    assert code != 0
    assert "Additional properties are not allowed ('generation' was unexpected)" in output
    code, output = dry_run(work, "results/pendulum_all", "--config", "pendulm={group: x}")
    assert code != 0 and "'pendulm' was unexpected" in output
    assert not (work / "results").exists()


def test_numbers_given_with_config_are_numbers(work):
    """--config passes nested values as strings: bsr='{generations: 100, seeds: 1}' was refused
    ('100' is not of type 'integer'). Where the schema wants a number, a numeral is one."""
    budget = "bsr={generations: 100, seeds: 1}"
    code, output = dry_run(work, "results/bsr_all", "--config", budget, "--quiet", "rules")
    assert code == 0, output
    assert re.search(r"^bsr_search\s+5$", output, re.M), output  # one seed of each search
    code, output = dry_run(work, "results/bsr_all", "--config", "bsr={generations: many}")
    assert code != 0 and "'many' is not of type 'integer', 'null'" in output


def test_a_whole_float_where_an_integer_is_wanted_is_that_integer(work, tmp_path):
    """The schema takes 2.0 (and 1e300) as an integer; 1e300 seeds raised in a slice."""
    counts = {}
    for seeds in ("2.0", "2", "1.0e+300", "null"):
        extra = tmp_path / "seeds.yaml"
        extra.write_text(f"bsr3d:\n  seeds: {seeds}\n", encoding="utf-8")
        args = ("--configfile", "config/config.yaml", str(extra), "--quiet", "rules")
        code, output = dry_run(work, "results/bsr3d_all", *args)
        assert code == 0, output
        counts[seeds] = re.search(r"^bsr_search\s+(\d+)$", output, re.M).group(1)
    assert counts["2.0"] == counts["2"] and counts["1.0e+300"] == counts["null"], counts


def test_the_command_line_reads_numbers_as_a_yaml_file_does(work):
    """--config passes nested values as strings: seeds: 2.0 was refused ('2.0' is not of type
    'integer') where a YAML file's is 2, and dt: .inf got the schema's message, not the
    finite-number check's."""
    counts = {}
    for seeds in ("2.0", "2", "1e300", "null"):
        budget = f"bsr3d={{seeds: {seeds}}}"
        code, output = dry_run(work, "results/bsr3d_all", "--config", budget, "--quiet", "rules")
        assert code == 0, output
        counts[seeds] = re.search(r"^bsr_search\s+(\d+)$", output, re.M).group(1)
    assert counts["2.0"] == counts["2"] != counts["null"] == counts["1e300"], counts
    for config, message in [
        ("bsr3d={seeds: 2.5}", "2.5 is not of type 'integer', 'null'"),
        ("car={dt: .inf}", "config car.dt: expected a finite number, found inf"),
        ("car={dt: -.Inf}", "-inf is less than or equal to the minimum of 0"),
        ("car={dt: .nan}", "config car.dt: expected a finite number, found nan"),
        ("bsr={generations: many}", "'many' is not of type 'integer', 'null'"),
    ]:
        code, output = dry_run(work, "results/pendulum_all", "--config", config)
        assert code != 0 and message in output, (config, output)


def test_the_car_gif_script_draws_on_the_car_controllers_when_left_out_of_car_scripts(work):
    """car.gif_script is the car's: left out of car.scripts, it had drawn on controllers of
    its own name (specs/controllers/park_1/), and the dry run stopped."""
    code, output = dry_run(work, "results/car_all", "--config", "car={scripts: [park_3]}")
    assert code == 0, output
    assert "mosys run specs/scripts/park_1.anim" in output, output


@pytest.mark.parametrize(
    ("config", "message"),
    [
        ("bsr:\n  searches: [nope]\n", "config bsr.searches: 'nope' names no spec"),
        ("car:\n  gif_script: nope\n", "config car.gif_script: 'nope' names no spec"),
        (
            "pendulum:\n  compare_controls: [pendulum, nope]\n",
            "config pendulum.compare_controls: 'nope' names no spec (specs/scripts/nope.anim",
        ),
        (
            "car:\n  start_grid:\n    x: [-2.0, 7.5, 2.5]\n",
            "2.5 is not of type 'integer'",
        ),
        ("car:\n  start_grid:\n    heading: []\n", "[] should be non-empty"),
        (
            "bsr3d:\n  variability: {time: nope}\n",
            "config bsr3d.variability: 'nope' names no spec",
        ),
        (
            "bsr3d:\n  variability: {sense: null, time: null}\n",
            "config bsr3d.variability: a search of at least one kind (sense or time), found none",
        ),
        ("bsr3d:\n  variability: bob_walk\n", "'bob_walk' is not of type 'object'"),
        ("bsr3d:\n  cameras: {rex: {elevation: 100}}\n", "100 is greater than the maximum of 90"),
        ("bsr3d:\n  cameras: {rex: {zoom: 2}}\n", "'zoom' was unexpected"),
        (  # a chain out of order was refused by the plot, after every search had run
            "bsr3d:\n  motions: {rex: [rex_walk, rex_walk_again, rex_turn]}\n",
            "config bsr3d.motions.rex: rex_walk_again continues rex_turn (its spec's chain"
            " line), so it cannot follow rex_walk: list a chain's searches in order",
        ),
        (
            "bsr3d:\n  targets: {chain: [rex_turn, rex_walk_again, rex_walk]}\n",
            "config bsr3d.targets.chain: rex_walk continues no search (its spec has no chain"
            " line), so it cannot follow rex_walk_again",
        ),
        (  # a 3-D search among the 2-D ones was refused by the 2-D table, after it had run
            "bsr:\n  searches: [starman_jump, rex_walk]\n",
            "config bsr.searches: rex_walk is a search of the 3-D figure rex"
            " (specs/bsr/rex_walk.bsr); bsr.searches takes searches of 2-D figures",
        ),
        (
            "bsr3d:\n  motions: {cujo: [beryl_tumble]}\n",
            "config bsr3d.motions.cujo: beryl_tumble is a search of the 2-D figure beryl",
        ),
        (
            "composite:\n  robustness: {rex_walk_sense: starman_jump}\n",
            "config composite.robustness: rex_walk_sense is a search of the 3-D figure rex",
        ),
        (  # a camera for no motion was ignored: the plots went ahead with their own
            "bsr3d:\n  cameras: {rexx: {azimuth: 10}}\n",
            "config bsr3d.cameras: 'rexx' names no motion of bsr3d.motions"
            " (cujo, rex, bob, bob_time) and no search spec (specs/bsr/rexx.bsr does not exist)",
        ),
        (  # NaN passes every bound of the schema
            "bsr3d:\n  cameras: {rex: {azimuth: .nan}}\n",
            "config bsr3d.cameras.rex.azimuth: expected a finite number, found nan",
        ),
        ("car:\n  start_grid:\n    heading: [0.0, .nan]\n", "config car.start_grid.heading[1]: "),
        (  # an infinity passes a lower bound alone
            "car:\n  dt: .inf\n",
            "config car.dt: expected a finite number, found inf",
        ),
        ("limits:\n  steps: .inf\n", "config limits.steps: expected a finite number, found inf"),
        ("car:\n  start_grid:\n    steer: [-.inf]\n", "config car.start_grid.steer[0]: "),
    ],
)
def test_a_config_naming_no_spec_or_an_impossible_grid_is_refused_before_anything_runs(
    work, tmp_path, config, message
):
    """A name with no spec used to fail inside a rule's input function (a traceback naming only
    the spec); a start grid of 2.5 x values passed the schema and failed in its job."""
    extra = tmp_path / "extra.yaml"
    extra.write_text(config, encoding="utf-8")
    code, output = dry_run(work, "all", "--configfile", "config/config.yaml", str(extra))
    assert code != 0
    assert message in output, output
    assert not (work / "results").exists()


@pytest.mark.parametrize(
    "target",
    [
        "results/plots/car/manoeuvr.gif",  # the car's GIF is manoeuvre.gif
        "results/controllers/pendulum/sub/A.h5",  # a wildcard never spans a '/'
        "results/bsr/starman_shuffle/seedX.h5",  # a seed is a number
        "results/plots/pendulum/A_portrait.jpg",
    ],
)
def test_a_target_no_rule_makes_says_so(work, target):
    code, output = dry_run(work, target)
    assert code != 0
    assert f"No rule to produce {target}" in output


def test_a_missing_spec_stops_the_dag_with_the_parsers_message(work):
    code, output = dry_run(work, "results/trajectories/nosuch.anim.h5")
    assert code != 0 and "No rule to produce" in output
    code, output = dry_run(work, "results/trajectories/nosuch.h5")
    assert code != 0
    assert "specs/scripts/nosuch.anim:1:1: expected an existing spec file" in output


def test_a_script_naming_a_controller_without_a_spec_is_caught_in_the_dag(work):
    (work / "specs/scripts/q.anim").write_text(
        "state link -90,0\nswapcon link conQ.ctab\nsim 1\n", encoding="utf-8"
    )
    code, output = dry_run(work, "results/trajectories/q.h5")
    assert code != 0
    assert (
        "specs/scripts/q.anim:2: conQ.ctab names controller Q, whose spec "
        "specs/controllers/q/Q.ssc does not exist: the script's controllers come from "
        "specs/controllers/q/ (the script's own name, as for any script not configured "
        "otherwise)"
    ) in output
    (work / "specs/scripts/q.anim").unlink()


def test_a_script_naming_a_motor_program_without_a_spec_is_caught_in_the_dag(work):
    """It was Snakemake's MissingInputException naming the .mot, not the script's line."""
    line, code, output = dry_run_with_edit(
        work,
        "specs/scripts/luxo_show.anim",
        "specs/scripts/my_luxo.anim",
        ("motor luxo long_jump", "motor luxo long_jmp"),
        "results/trajectories/my_luxo.h5",
    )
    assert code != 0
    assert (
        f"specs/scripts/my_luxo.anim:{line}:12: expected a motor program "
        "(specs/motor/luxo/long_jmp.mot does not exist), found 'long_jmp'"
    ) in output


def test_a_script_of_the_cars_figure_draws_on_the_cars_controllers(work):
    """A parking script of your own was sent to a controller folder of its own name."""
    text = "object car figure=car\nstate car 6.5,3.25,-10,0,0\nswapcon car conpark.ctab\nsim 30\n"
    code, output = dry_run_with_spec(
        work, "specs/scripts/my_park.anim", text, "results/trajectories/my_park.h5"
    )
    assert code == 0, output
    assert "mosys run specs/scripts/my_park.anim --controllers results/controllers/car " in output
    assert "--dt 0.01 " in output  # the car's step


def test_a_chain_line_naming_no_search_stops_the_dag_at_that_line(work):
    """It stopped at the missing spec's line 1 (``specs/bsr/rex_wlak.bsr:1:1: expected an
    existing spec file``), a file the user never wrote."""
    line, code, output = dry_run_with_edit(
        work,
        "specs/bsr/rex_turn.bsr",
        "specs/bsr/my_turn.bsr",
        ("chain rex_walk", "chain rex_wlak"),
        "results/bsr/my_turn/seed1.h5",
    )
    assert code != 0
    assert (
        f"specs/bsr/my_turn.bsr:{line}:7: expected the name of a search in specs/bsr/ to "
        "continue, found 'rex_wlak' (specs/bsr/rex_wlak.bsr does not exist)"
    ) in output


@pytest.mark.parametrize(
    ("search", "expected"),
    [
        ("starman_shufle", "a BSR search (no spec specs/bsr/starman_shufle.bsr)"),
        ("beryl_shuffle", "a search of figure 'starman' (beryl_shuffle moves 'beryl')"),
    ],
)
def test_a_composite_phase_naming_no_search_or_another_figures_stops_the_dag(
    work, search, expected
):
    """Both ran the composite's searches first (at the paper's budget, five of them) and failed
    in the composite's job; a misspelt search stopped at the missing .bsr's line 1."""
    line, code, output = dry_run_with_edit(
        work,
        "specs/composite/starman_show.comp",
        "specs/composite/mine.comp",
        ("controller=starman_shuffle_robust", f"controller={search}"),
        "results/composite/mine.h5",
    )
    assert code != 0
    assert f"specs/composite/mine.comp:{line}:28: expected {expected}, found '{search}'" in output
    assert "bsr_search" not in output


def test_a_3d_search_of_your_own_is_drawn_without_registering_it(work):
    """A motion's plots for a search the config does not name: the search and the searches
    its chain lines continue, in order (it was a KeyError); its seeds' learning curves."""
    code, output = dry_run(work, "results/plots/bsr3d/rex_turn/filmstrip.png")
    assert code == 0, output
    plot = next(line for line in output.splitlines() if "mosys plot bsr3d " in line)
    walk = plot.index("results/bsr/rex_walk/seed1.h5")
    assert walk < plot.index("results/bsr/rex_turn/seed1.h5")
    assert "rex_walk_again" not in plot
    code, output = dry_run(work, "results/plots/bsr3d/bob_walk/learning.png")
    assert code == 0, output
    assert "mosys plot bsr3d-seeds results/bsr/bob_walk/seed1.h5" in output
    code, output = dry_run(work, "results/plots/bsr3d/nosuch/filmstrip.png")
    assert code != 0
    assert (
        "results/plots/bsr3d/nosuch/: expected a motion of config bsr3d.motions (cujo, rex, "
        "bob, bob_time) or a search spec, found 'nosuch' (specs/bsr/nosuch.bsr does not exist)"
    ) in output


def test_a_malformed_spec_stops_the_dag_with_its_location(work):
    spec = work / "specs/scripts/pendulum_catch.anim"
    text = spec.read_text(encoding="utf-8")
    try:
        spec.write_text(text.replace("swapcon conB.ctab once", "swapcon conB.ctab twice"))
        code, output = dry_run(work, "results/pendulum_all")
        assert code != 0
        assert "specs/scripts/pendulum_catch.anim:9:" in output
        assert "expected 'once' or end of line, found 'twice'" in output
    finally:
        spec.write_text(text, encoding="utf-8")


def test_a_controller_is_drawn_with_its_own_figures_dynamics(work):
    code, output = dry_run(work, "results/plots/luxo/land_portrait.png")
    assert code == 0, output
    assert "mosys plot controller results/controllers/luxo/land.h5" in output
    assert "--dynamics results/dynamics/luxo_grounded.py" in output
    assert "results/dynamics/link1.py" not in output


def test_the_configs_limits_reach_the_jobs(work):
    """``limits: {memory_gib: ...}`` in a config file (README, "Limits") is what the DP job is
    held to: it refuses, exit 2, its log says why, and nothing is left behind."""
    config = work / "tiny_limits.yaml"
    config.write_text("limits:\n  memory_gib: 0.000001\n", encoding="utf-8")
    done = run_snakemake(work, "results/controllers/pendulum/A.h5", "--configfile", str(config))
    assert done.returncode != 0
    log = (work / "results/logs/dp/pendulum/A.log").read_text(encoding="utf-8")
    assert "specs/controllers/pendulum/A.ssc:9:6: expected a job that fits in 0.00 GiB" in log
    assert "raise MOSYS_MAX_MEMORY_GIB to allow it" in log
    assert not (work / "results/controllers/pendulum/A.h5").exists()


def test_a_motions_camera_reaches_its_plot_only(work, tmp_path):
    """config bsr3d.cameras sets a 3-D motion's filmstrip and GIF camera (README, "3-D
    figures"): its options reach that motion's `mosys plot bsr3d` only, in a fixed order, from a
    config file or from --config's strings; a motion without one lets the plot choose."""
    camera = tmp_path / "camera.yaml"
    camera.write_text(
        "bsr3d:\n  cameras: {rex: {interval: 0.5, azimuth: 50, elevation: null}}\n",
        encoding="utf-8",
    )
    targets = ("results/plots/bsr3d/rex/filmstrip.png", "results/plots/bsr3d/cujo/filmstrip.png")
    code, output = dry_run(work, *targets, "--configfile", "config/config.yaml", str(camera))
    assert code == 0, output
    commands = set(re.findall(r"(mosys plot bsr3d .*) > results/logs", output))
    rex = [line for line in commands if "bsr/rex_walk/" in line]
    cujo = [line for line in commands if "bsr/cujo_bound/" in line]
    assert len(rex) == len(cujo) == 1, commands
    assert rex[0].endswith("--rest results/plots/bsr3d/rex/rest.png --azimuth 50 --interval 0.5")
    assert cujo[0].endswith("--rest results/plots/bsr3d/cujo/rest.png")
    code, output = dry_run(work, targets[0], "--config", "bsr3d={cameras: {rex: {azimuth: -30}}}")
    assert code == 0, output
    assert "--rest results/plots/bsr3d/rex/rest.png --azimuth -30.0" in output


def test_a_3d_search_of_ones_own_takes_the_bsr3d_budget(tmp_path):
    """A user's own 3-D search, asked for by its file and listed in no config list, is capped by
    bsr3d.generations and bsr3d.seeds (README: "bsr3d.seeds for a 3-D search"): it took the 2-D
    block's (bsr), so --config bsr3d='{generations: 20, seeds: 1}' ran every seed at the spec's
    own G."""
    work = copy_workflow(tmp_path)
    spec = (work / "specs/bsr/cujo_bound.bsr").read_text(encoding="utf-8")
    (work / "specs/bsr/my_bound.bsr").write_text(spec, encoding="utf-8")
    target = "results/plots/bsr3d/my_bound/learning.png"
    code, output = dry_run(work, target, "--config", "bsr3d={generations: 20, seeds: 1}")
    assert code == 0, output
    searches = re.findall(r"mosys bsr-search specs/bsr/my_bound\.bsr [^\n]*", output)
    assert len(searches) == 1 and "--generations 20" in searches[0], output
    code, output = dry_run(work, target, "--config", "bsr={generations: 20, seeds: 1}")
    assert code == 0, output
    searches = re.findall(r"mosys bsr-search specs/bsr/my_bound\.bsr [^\n]*", output)
    assert len(searches) == 3 and "--generations" not in " ".join(searches), output


def test_a_search_capped_under_the_paper_config_is_labelled_custom(work):
    """A G cut by --config under config.yaml (budget: paper) was labelled 'paper' in the result
    and the runs tables, which say paper means each spec's own G."""
    code, output = dry_run(
        work, "results/bsr/starman_jump/seed1.h5", "--config", "bsr={generations: 20}"
    )
    assert code == 0, output
    assert "--generations 20 --budget custom" in output, output
    code, output = dry_run(work, "results/bsr/starman_jump/seed1.h5", "--config", "bsr={seeds: 1}")
    assert code == 0, output
    assert "--budget paper" in output and "--generations" not in output, output


def test_every_report_category_is_a_link_target_of_the_html_report():
    """``snakemake --report`` appends ``.. _CATEGORY: javascript:...`` to every caption, and a
    colon ends an RST target's name: "1990 paper: the pendulum" and "1990 paper: the car" both
    became the target "1990 paper", 36 warnings per report and links that went nowhere."""
    import docutils.core
    import docutils.nodes

    rules = [ROOT / "Snakefile", *sorted((ROOT / "workflow" / "rules").glob("*.smk"))]
    text = "".join(path.read_text() for path in rules)
    names = set(re.findall(r'category="([^"{]+)"', text))  # and subcategory=; not wildcards
    assert len(names) > 10
    links = "".join(f".. _{name}: javascript:app.showCategory('x')\n" for name in sorted(names))
    document = docutils.core.publish_doctree(links, settings_overrides={"report_level": 5})
    assert set(document.nameids) == {docutils.nodes.fully_normalize_name(n) for n in names}
