"""The workflow's config under fuzzing: mutated copies of ``config/config.yaml`` planned by
Snakemake (dry runs of a copy of the workflow, nothing built).

Each case changes one or two of the config's values, or adds a key to one of its maps of names,
and plans one of the aggregate targets. A value is replaced by one of its own kind most of the time
(another spec of the same folder for a name, a scaled or negated number, a list shortened,
lengthened or with a name twice) and otherwise by a hostile one (a string for a number, 1e300,
an empty list, null). Every case ends in one class:

- passing: ``ok`` (the plan is made), ``refused`` (a ``WorkflowError``: the schema's message, or
  one of the workflow's own checks naming the key);
- failing: ``traceback`` (any other Python exception, raised or wrapped in Snakemake's
  ``InputFunctionException``), ``unexplained`` (a non-zero exit with neither), ``built`` (a
  dry run left a ``results/`` folder).

Found this way on 2026-12-06 and fixed: ``bsr3d.seeds: 1e300`` passed the schema and raised in
a slice; a ``car.gif_script`` left out of ``car.scripts`` stopped the plan; a chain of searches
out of order, or a 3-D search among the 2-D ones, was refused only by the plot or table that
read the results, after every search had run.

``MOSYS_FUZZ_SEED=N`` draws other cases (the verb fuzz's variable); the fixed draw otherwise.
"""

from __future__ import annotations

import copy
import os
import random
import re
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
import yaml
from test_workflow import ROOT, copy_workflow, run_snakemake

CASES = 40
WORKERS = 2  # copies of the workflow, each planning one case at a time
FIXED_SEED = 2026
TARGETS = ("all", "results/pendulum_all", "results/car_all", "results/luxo_all",
           "results/bsr_all", "results/bsr3d_all", "results/composite_all")  # fmt: skip
NAME_MAPS = (("bsr3d", "motions"), ("bsr3d", "cameras"), ("bsr3d", "kinds"),
             ("bsr3d", "variability"), ("composite", "robustness"))  # fmt: skip
HOSTILE = (-1, 0, 1.5, 1e300, -1e300, 2**63, "nope", "", [], {}, None, True, ["nope"], "../x",
           "a b", [0.0], {"a": 1})  # fmt: skip
REFUSALS = {"WorkflowError", "ValidationError", "InputFunctionException"}
EXCEPTION = re.compile(r"\b([A-Z]\w*(?:Error|Exception))\b")

SPECS = sorted(path for path in (ROOT / "specs").rglob("*") if path.is_file())
ALL_NAMES = sorted({path.stem for path in SPECS})


def same_folder_names(name: str) -> list[str]:
    """The names of the specs beside the spec called ``name`` (all names if there is none)."""
    folders = {path.parent for path in SPECS if path.stem == name}
    if not folders:
        return ALL_NAMES
    return sorted({path.stem for path in SPECS if path.parent in folders})


def leaves(node, path=()):
    """The paths of the config's values: every list and scalar, and every empty map."""
    if isinstance(node, dict):
        if not node:
            yield path
        for key, value in node.items():
            yield from leaves(value, (*path, key))
    else:
        if path:
            yield path
        if isinstance(node, list):
            for index, value in enumerate(node):
                yield from leaves(value, (*path, index))


def at(node, path):
    for key in path:
        node = node[key]
    return node


def of_its_kind(rng: random.Random, old):
    """A value like ``old``: a name of the same folder, a number scaled, a list changed."""
    if isinstance(old, bool) or old is None:
        return rng.choice([True, False, None, 0, 2])
    if isinstance(old, (int, float)):
        return rng.choice([0, -old, 2 * old, old / 2, 1000 * old, old / 1000, old + 1, 1, 3, -1,
                           1e-9, 1e6])  # fmt: skip
    if isinstance(old, str):
        return rng.choice(same_folder_names(old))
    if isinstance(old, list) and old and isinstance(old[0], str):
        pool = same_folder_names(old[0]) + old
        picked = [rng.choice(pool) for _ in range(rng.choice([0, 1, 2, len(old)]))]
        return picked + picked[:1] if rng.random() < 0.3 else picked
    if isinstance(old, list) and old:
        values = [rng.choice([value, -value, 3 * value, 0, value + 0.5, 1e6]) for value in old]
        return values[: rng.choice([len(old), 1, 0])]
    return rng.choice([[], {}, ["nope"]])


def mutated(rng: random.Random, base: dict) -> tuple[dict, list]:
    """A copy of the config with one or two changes, and the changes."""
    config, changes = copy.deepcopy(base), []
    if rng.random() < 0.25:  # a key added to a map of names, with the value of another
        section = rng.choice(NAME_MAPS)  # (no key is taken away: Snakemake merges the case's
        names = at(config, section)  # file into the shipped config, whose keys stay)
        key = rng.choice(sorted(names) or ["x"])
        new = rng.choice([*ALL_NAMES, "", "a b"])
        value = copy.deepcopy(names.get(key))
        if section == ("bsr3d", "cameras"):
            value = rng.choice([{}, {"azimuth": 10}, None, {"interval": 1e-9}])
        names[new] = value
        changes.append((".".join(section), new, value))
    paths = list(leaves(base))
    for _ in range(rng.choice([0, 1, 1, 2]) if changes else rng.choice([1, 1, 2])):
        path = rng.choice(paths)
        try:
            old = at(config, path)
        except (KeyError, IndexError, TypeError):
            continue  # under a value changed before
        value = of_its_kind(rng, old) if rng.random() < 0.7 else rng.choice(HOSTILE)
        at(config, path[:-1])[path[-1]] = copy.deepcopy(value)
        changes.append((".".join(map(str, path)), value))
    return config, changes


def draw_cases(seed: int, count: int) -> list[tuple[str, dict, list]]:
    """``count`` cases drawn from ``seed``, the same for the same seed: (target, config,
    changes)."""
    rng = random.Random(seed)
    base = yaml.safe_load((ROOT / "config" / "config.yaml").read_text(encoding="utf-8"))
    return [(rng.choice(TARGETS), *mutated(rng, base)) for _ in range(count)]


def judge(done: subprocess.CompletedProcess, work: Path) -> tuple[str, str]:
    """The case's class and the output's last lines."""
    output = done.stdout + done.stderr
    tail = "\n".join(line for line in output.splitlines()[-12:] if "profile" not in line)
    if (work / "results").exists():
        return "built", tail
    if done.returncode == 0:
        return "ok", tail
    if set(EXCEPTION.findall(output)) - REFUSALS:
        return "traceback", tail
    if "WorkflowError" in output:
        return "refused", tail
    return "unexplained", tail


def plan(work: Path, target: str, config: dict) -> tuple[str, str]:
    """Dry-run ``target`` in the copy ``work`` with ``config`` given after the shipped one."""
    extra = work / "fuzz.yaml"
    extra.write_text(yaml.safe_dump(config), encoding="utf-8")
    done = run_snakemake(work, "--dry-run", "--configfile", "fuzz.yaml", "--", target)
    return judge(done, work)


@pytest.mark.slow
def test_mutated_configs_are_planned_or_refused_with_a_message(tmp_path):
    """Forty mutated configs, each planned or refused by a WorkflowError, never a traceback."""
    seed = int(os.environ.get("MOSYS_FUZZ_SEED", FIXED_SEED))
    cases = draw_cases(seed, CASES)
    works = [tmp_path / f"work{k}" for k in range(WORKERS)]
    for work in works:
        work.mkdir()
        copy_workflow(work)

    def plan_share(k: int) -> list[tuple[int, tuple[str, str]]]:
        """Every WORKERS-th case, from the k-th, in the k-th copy, one after another."""
        return [
            (number, plan(works[k], target, config))
            for number, (target, config, _) in enumerate(cases)
            if number % WORKERS == k
        ]

    with ThreadPoolExecutor(WORKERS) as pool:
        outcomes = dict(pair for share in pool.map(plan_share, range(WORKERS)) for pair in share)
    classes = [outcomes[number][0] for number in range(len(cases))]
    failing = [
        f"{target} with {changes}: {outcomes[number][0]}\n{outcomes[number][1]}"
        for number, (target, _, changes) in enumerate(cases)
        if outcomes[number][0] not in ("ok", "refused")
    ]
    assert not failing, "\n\n".join(failing)
    assert "ok" in classes and "refused" in classes, classes  # the draw reaches both
