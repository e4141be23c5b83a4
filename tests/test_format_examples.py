"""The ``mosys info`` examples in docs/formats/ against ``mosys info`` on the same kind of file made
now: the same sections, root attribute names, groups, datasets and group attribute names (the
values, such as hashes, timings and fitness, may differ). Three examples had drifted unnoticed
(a table and a search without ``policy_sweeps`` and ``compile_seconds``, a trajectory's
``/state`` without its units), found by reading the pages against real files on 2026-12-07.
The files are conftest's ``made`` (``mosys info``'s tests share them), and for the car's three
examples a table, a run and a start grid of a small scene (the shipped files take a minute to
make)."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

from conftest import ROOT, SPECS

from mosys.cli import main

FORMATS = ROOT / "docs" / "formats"


def example(page: str, marker: str) -> list[str]:
    """The lines of the first code block after the line of ``page`` holding ``marker``."""
    lines = (FORMATS / page).read_text(encoding="utf-8").splitlines()
    at = next(k for k, line in enumerate(lines) if marker in line)
    start = next(k for k in range(at, len(lines)) if lines[k].startswith("```")) + 1
    end = next(k for k in range(start, len(lines)) if lines[k].startswith("```"))
    return lines[start:end]


KEPT = ("root attributes", "groups and datasets")  # the sections whose names are compared


def structure(lines: list[str]) -> dict[str, list[str]]:
    """The section titles (``sections``), and for the KEPT sections the names in them: a root
    attribute's name; a group's path; a dataset's path, dtype and unit (the columns the table's
    header places); ``PATH @NAME`` for a group's attribute."""
    titles: list[str] = []
    names: dict[str, list[str]] = {}
    current: list[str] | None = None
    group, columns = "", {}
    for line in lines:
        if line and not line.startswith(" ") and line.endswith(":"):
            line = re.sub(r" \(\d+\):$", ":", line)  # "root attributes (34):": the names count
            titles.append(line)
            current = names.setdefault(line, []) if line.startswith(KEPT) else None
        elif current is None or not line.strip():
            continue
        elif line.startswith("  path "):  # the datasets' header: where the columns start
            columns = {word: line.index(f" {word}") + 1 for word in ("dtype", "unit", "summary")}
        elif line.startswith("    "):  # an attribute of the group above
            current.append(f"{group} @{line.split()[0]}")
        elif line.split()[1:2] == ["group"] or not line.startswith("  /"):
            group = line.split()[0]  # a group, or a root attribute's name
            if group != "git_commit":  # absent outside a git checkout (docs/formats/README.md)
                current.append(group)
        else:
            dtype = line[columns["dtype"] : columns["unit"]].strip()
            unit = line[columns["unit"] : columns["summary"]].strip()
            current.append(f"{line.split()[0]} {dtype} [{unit}]")
    return {"sections": titles, **names}


def info(path: Path, capsys) -> list[str]:
    assert main(["info", str(path)]) == 0
    return capsys.readouterr().out.splitlines()


def same_structure(page: str, marker: str, path: Path, capsys, partial: bool = False) -> None:
    """The example's structure is that of ``mosys info path`` (``partial``: an example of some
    sections only, compared on those)."""
    shown = structure(example(page, marker))
    made = structure(info(path, capsys))
    if partial:
        made["sections"] = [title for title in made["sections"] if title in shown["sections"]]
    assert shown == {key: made.get(key) for key in shown}, f"docs/formats/{page}: {marker}"
    assert shown.keys() == made.keys() or partial, f"docs/formats/{page}: {marker}"


def test_the_controller_table_example(made, capsys):
    marker = "mosys info results/controllers/pendulum/A.h5"
    same_structure("controller_table.md", marker, made["controller table"], capsys)


def test_the_trajectory_and_figure_motion_examples(made, capsys):
    same_structure("trajectory.md", "Figure 15 script", made["trajectory"], capsys)
    marker = "The pendulum's trajectory"
    same_structure("figure_motion.md", marker, made["trajectory"], capsys, partial=True)


def test_the_bsr_result_example(made, capsys):
    marker = "mosys info results/bsr/starman_jump_robust/seed1.h5"
    same_structure("bsr_result.md", marker, made["BSR search result"], capsys)


def test_the_composite_result_example(made, capsys):
    marker = "mosys info results/composite/starman_show.h5"
    same_structure("composite_result.md", marker, made["composite result"], capsys)


def test_the_cars_examples(car, tmp_path, capsys):
    """The car's table, trajectory and start grid, made from the car test's small scene with
    the shipped table's known_weight and policy lines (so the same datasets; seconds, not a
    minute)."""
    from test_car import SMALL

    from mosys.animation.trajectory_file import run_animation_script
    from mosys.parsing.controller import parse_controller_text
    from mosys.ssc.generate import generate_controller

    shipped = (SPECS / "controllers" / "car" / "park.ssc").read_text().splitlines()
    lines = [line for line in shipped if line.startswith(("known_weight", "policy"))]
    spec = parse_controller_text(SMALL + "\n".join(lines) + "\n", "park.ssc")
    (tmp_path / "controllers").mkdir()
    table = tmp_path / "controllers" / "park.h5"
    generate_controller(spec, car, table, quiet=True)
    marker = "mosys info results/controllers/car/park.h5"
    same_structure("controller_table.md", marker, table, capsys, partial=True)
    (tmp_path / "dynamics").mkdir()
    shutil.copy(car.__file__, tmp_path / "dynamics" / "car.py")  # the fixture's, compiled
    script = tmp_path / "park_1.anim"
    script.write_text("state car 1,1.5,0,-30,0\nswapcon car conpark.ctab\nsim 0.5\n")
    trajectory = tmp_path / "park_1.h5"
    controllers, dynamics = tmp_path / "controllers", tmp_path / "dynamics"
    run_animation_script(script, controllers, dynamics, trajectory, 0.01)
    same_structure("trajectory.md", "A car trajectory", trajectory, capsys, partial=True)
    grid = tmp_path / "start_grid.h5"
    axes = ["--x", "-1", "1", "2", "--y", "1.5", "1.5", "1", "--heading", "0", "--steer", "0"]
    argv = ["starts", str(table), "--dynamics", str(dynamics / "car.py"), *axes]
    assert main([*argv, "--seconds", "2", "--quiet", "-o", str(grid)]) == 0
    capsys.readouterr()  # its line of results
    same_structure("start_grid.md", "mosys info results/car/start_grid.h5", grid, capsys)
