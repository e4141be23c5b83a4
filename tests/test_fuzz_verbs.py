"""Issue 27: a fuzz suite that drives the verbs, not only the parsers.

Hypothesis mutates the shipped specs of every kind and the verbs' numeric options
(``tests/fuzz_cases.py``); two long-lived worker processes run each case's ``mosys`` command
lines in-process in a fresh directory, under low limits (``MOSYS_MAX_MEMORY_GIB=0.5``,
``MOSYS_MAX_STEPS=200000``) so that every case is quick. Every case ends in one class:

- passing: ``ok`` (exit 0, outputs present and sound), ``refused`` (exit 2, a one-line message),
  ``limit`` (the same, past a ``MOSYS_MAX_`` limit), ``usage`` (an argparse usage error, exit 2);
- failing: ``signal`` (the worker was killed by a signal), ``hang`` (no answer within the step
  timeout), ``died`` (the worker exited), ``traceback`` (an exception escaped ``main``),
  ``bad-exit`` (an exit code other than 0 or 2), ``nan`` (a NaN or inf where the file's contract
  forbids it), ``missing`` (exit 0 without a readable output), ``leftover`` (a file left in the
  case's directory after a failure, or a partial one after success), ``message`` (exit 2 whose
  stderr, progress and warning lines aside, is not one message line, or shows a traceback).

The table of counts (kind x class) is printed whatever the result; the test fails on any case
of a failing class and lists one reproducer per distinct finding. Two profiles: a fast one in
every run (about 90 cases, 10 s), and the large one (``slow``: about 1,100 cases, every hostile
value of every numeric option among them, 2 to 4 minutes) that CI runs. The cases are the same
on every run (hypothesis derandomized). A worker that hangs or dies is replaced, so one finding
does not hide the next.

``MOSYS_FUZZ_SEED=N`` draws other cases, from seed N (the same for the same N), for a hunt
beyond the fixed draw. ``MOSYS_FUZZ_REPORT=FILE`` writes the findings (every failing case
grouped, the smallest of each group with its spec diff, command lines, outcome and traceback)
to FILE as Markdown; ``MOSYS_FUZZ_KEEP=DIR`` copies each failing case's directory and logs
there.
"""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

import fuzz_cases as fc
import pytest
from conftest import SUMMARY_PROPERTY

# cases per kind (after duplicates are dropped, a few fewer)
FAST = {"fig": 14, "ssc": 14, "anim": 14, "mot": 10, "bsr": 16, "comp": 12, "cli": 20}
LARGE = {"fig": 130, "ssc": 140, "anim": 140, "mot": 100, "bsr": 160, "comp": 110, "cli": 110}
# Seconds a step may take before it counts as a hang: the slowest sound case takes 5 to 12 s (a
# BSR generation of 10,000 controllers; the longer on a busy machine), most under 0.1 s.
FAST_TIMEOUT = 20.0
LARGE_TIMEOUT = 30.0
WORKERS = 2


@pytest.fixture(scope="module")
def shared(tmp_path_factory) -> Path:
    directory = tmp_path_factory.mktemp("fuzz_shared")
    fc.build_shared(directory)
    return directory


def fresh_seed() -> int | None:
    """``MOSYS_FUZZ_SEED``: draw the cases from this seed instead of the fixed draw."""
    text = os.environ.get("MOSYS_FUZZ_SEED")
    return None if text is None else int(text)


def run_profile(name: str, sizes: dict[str, int], timeout: float, root: Path, shared: Path,
                record_property, grid: bool = False) -> list[fc.Outcome]:  # fmt: skip
    """Draw the profile's cases (and with ``grid``, add ``fc.cli_grid``), run them, judge them,
    print the table; the outcomes."""
    cases = [
        (f"{kind}-{number:04d}", case)
        for kind, drawn in fc.draw_profile(sizes, fresh_seed()).items()
        for number, case in enumerate(drawn)
    ]
    if grid:
        cases += [(f"cli-grid-{number:04d}", case) for number, case in enumerate(fc.cli_grid())]
    before = sorted(path.relative_to(shared) for path in shared.rglob("*"))
    start = time.monotonic()
    with fc.Pool(root, shared, WORKERS, timeout) as pool:
        runs = pool.run_cases(cases)
        baseline = [fc.judge(run) for run in pool.baseline]
    wall = time.monotonic() - start
    outcomes = sorted((fc.judge(run) for run in runs), key=lambda outcome: outcome.case_id)
    for run, outcome in zip(sorted(runs, key=lambda run: run.case_id), outcomes, strict=True):
        if not outcome.failing:
            fc.clean(run)
    keep = os.environ.get("MOSYS_FUZZ_KEEP")
    if keep:
        for outcome in outcomes:
            if outcome.failing:
                target = Path(keep) / name / outcome.case_id
                shutil.copytree(root / "cases" / outcome.case_id, target, dirs_exist_ok=True)
                for log in (root / "logs").glob(f"{outcome.case_id}.*"):
                    shutil.copy(log, target.parent / log.name)
                (target.parent / f"{outcome.case_id}.md").write_text(fc.reproducer(outcome))
    report = os.environ.get("MOSYS_FUZZ_REPORT")
    if report:
        Path(report).write_text(fc.findings_markdown(outcomes, f"verb fuzz, {name} profile"))
    slowest = sorted(outcomes, key=lambda outcome: -outcome.seconds)[:5]
    summary = "\n".join([
        f"verb fuzz, {name} profile: {len(outcomes)} cases in {wall:.1f} s on {WORKERS} "
        f"workers (step timeout {timeout:g} s)",
        fc.counts_table(outcomes),
        "slowest: " + ", ".join(f"{o.case_id} {o.seconds:.1f} s" for o in slowest),
    ])  # fmt: skip
    # conftest's pytest_terminal_summary prints it at the end of the run (from xdist's workers too)
    record_property(SUMMARY_PROPERTY, summary)
    assert all(outcome.klass == "ok" for outcome in baseline), [
        (outcome.case_id, outcome.case.verbs, outcome.problems)
        for outcome in baseline
        if outcome.klass != "ok"
    ]
    after = sorted(path.relative_to(shared) for path in shared.rglob("*"))
    assert after == before, "a verb wrote beside its inputs"
    return outcomes


def assert_no_findings(outcomes: list[fc.Outcome]) -> None:
    failing = [outcome for outcome in outcomes if outcome.failing]
    if not failing:
        return
    groups: dict[str, list[fc.Outcome]] = {}
    for outcome in failing:
        groups.setdefault(fc.signature(outcome), []).append(outcome)
    lines = [f"{len(failing)} of {len(outcomes)} cases failed, {len(groups)} distinct findings:"]
    for key, members in sorted(groups.items()):
        smallest = min(members, key=lambda o: (o.case.size(), o.case_id))
        lines += ["", f"{key}: {len(members)} cases, e.g.", fc.reproducer(smallest)]
    pytest.fail("\n".join(lines), pytrace=False)


MISBEHAVING = {  # pseudo-verb -> the class the runner must give it
    "selftest-signal": "signal",
    "selftest-hang": "hang",
    "selftest-raise": "traceback",
    "selftest-exit": "died",
    "selftest-exit-1": "bad-exit",
    "selftest-nan": "nan",
    "selftest-partial": "leftover",
    "selftest-chatty": "message",
}


def test_the_runner_sorts_misbehaviour_into_its_classes(tmp_path):
    """Each way a verb can fail, played by a pseudo-verb in the worker, lands in its class; the
    worker is replaced after a signal, a hang and an exit, and the next case still runs."""

    def case(verb: str) -> fc.Case:
        step = fc.Step((verb, "{case}/out.h5"), ("out.h5",), "trajectory")
        return fc.Case("cli", "", (verb,), (), (step,))

    cases = [(verb, case(verb)) for verb in MISBEHAVING]
    with fc.Pool(tmp_path, tmp_path, 1, timeout=2.0, warmup=False) as pool:
        runs = pool.run_cases(cases)
    classes = {run.case_id: fc.judge(run).klass for run in runs}
    assert classes == MISBEHAVING
    crash = fc.judge(next(run for run in runs if run.case_id == "selftest-signal"))
    assert "SIGSEGV" in crash.problems[0] and "Fatal Python error" in crash.traceback


def test_fuzz_fast_profile(tmp_path, shared, record_property):
    """About 90 cases across every kind, in the default run."""
    outcomes = run_profile("fast", FAST, FAST_TIMEOUT, tmp_path, shared, record_property)
    assert {outcome.case.kind for outcome in outcomes} == set(fc.KINDS)
    assert_no_findings(outcomes)


@pytest.mark.slow
def test_fuzz_large_profile(tmp_path, shared, record_property):
    """About 1,100 cases across every kind (CI), every hostile value of every numeric option
    among them."""
    outcomes = run_profile(
        "large", LARGE, LARGE_TIMEOUT, tmp_path, shared, record_property, grid=True
    )
    assert len(outcomes) >= 1000
    assert {outcome.case.kind for outcome in outcomes} == set(fc.KINDS)
    assert_no_findings(outcomes)
