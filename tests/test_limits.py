"""Issue 27, reproducer 4 and its kin: each job's integration steps and memory are estimated from
its spec before anything is allocated (``mosys.limits``), and a job past a limit exits 2 naming
the line that asked for it, what it needs and the limit (``MOSYS_MAX_STEPS``,
``MOSYS_MAX_MEMORY_GIB``, which raise or lower it); a dynamics module whose numbers lie outside
the figure spec's bounds is refused; a DP segment that diverges is reported."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_non_finite import assert_nothing_written, run_script

from mosys.cli import main
from mosys.errors import SimulationError
from mosys.limits import DEFAULT_STEPS, check_job, memory_limit_bytes, physical_memory_bytes
from mosys.parsing.controller import parse_controller_spec
from mosys.ssc.generate import dp_memory_bytes
from mosys.ssc.problem import build_problem
from mosys.ssc.solution import solve

SPECS = Path(__file__).resolve().parents[1] / "specs"
STEPS_HINT = 'raise MOSYS_MAX_STEPS to allow it (README, "Limits")'


def last_line(capsys) -> str:
    return capsys.readouterr().err.strip().splitlines()[-1]


@pytest.mark.parametrize(
    ("sim", "dt", "found"),
    [
        ("sim 100000", 0.001, "100,000,000"),  # the issue's: 12.7 GB and minutes, then killed
        ("sim 1e300", 0.001, "1e+303"),
        ("sim 0.4", 1e-300, "4e+299"),  # mosys run --dt 1e-300
    ],
)
def test_a_run_past_the_step_limit_is_refused_at_its_line(
    tmp_path, pendulum, capsys, sim, dt, found
):
    text = f"state link -90,0\nswapcon link conA.ctab\n{sim}\n"
    code, script, out = run_script(
        tmp_path, text, pendulum / "dynamics", pendulum / "controllers", dt=dt
    )
    assert code == 2
    assert last_line(capsys) == (
        f"{script}:3:1: expected at most 10,000,000 integration steps per run, found {found} "
        f"(the run to the end of this line at dt {dt:g} s); {STEPS_HINT}"
    )
    assert_nothing_written(out)


def test_the_steps_of_the_lines_add_up(tmp_path, pendulum, capsys, monkeypatch):
    """Two sim lines of 600 steps each: the second goes past a limit of 1,000."""
    monkeypatch.setenv("MOSYS_MAX_STEPS", "1000")
    text = "state link -90,0\nswapcon link conA.ctab\nsim 0.6\nsim 0.6\n"
    code, script, out = run_script(tmp_path, text, pendulum / "dynamics", pendulum / "controllers")
    assert code == 2
    assert last_line(capsys).startswith(
        f"{script}:4:1: expected at most 1,000 integration steps per run, found 1,200 "
    )
    assert_nothing_written(out)
    monkeypatch.setenv("MOSYS_MAX_STEPS", "1200")  # raised: the same script runs
    code, _, out = run_script(tmp_path, text, pendulum / "dynamics", pendulum / "controllers")
    assert code == 0 and out.exists()


def test_a_motor_program_of_1e300_seconds_is_refused(tmp_path, pendulum, capsys):
    motor = tmp_path / "motor"
    (motor / "link1").mkdir(parents=True)
    (motor / "link1" / "long.mot").write_text("figure link1\nphase 1e300 torque=0\n")
    text = "state link -90,0\nswapcon link conA.ctab\nsim 0.01\nmotor link long\n"
    code, script, out = run_script(
        tmp_path, text, pendulum / "dynamics", pendulum / "controllers", motor
    )
    assert code == 2
    assert last_line(capsys).startswith(
        f"{script}:4:1: expected at most 10,000,000 integration steps per run, found 1e+303 "
    )
    assert_nothing_written(out)


def test_the_memory_limit_refuses_a_dp_and_names_the_machine(tmp_path, pendulum, capsys):
    """A 1,000,000-sample torque line (the issue's 5.6 GiB request) against a 4 GiB limit."""
    text = (SPECS / "controllers" / "pendulum" / "A.ssc").read_text()
    spec = tmp_path / "A.ssc"
    spec.write_text(text.replace("torq torque -10.0 10.0 11 0.1", "torq torque -10 10 1000000 0.1"))
    out = tmp_path / "A.h5"
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("MOSYS_MAX_MEMORY_GIB", "4")
        argv = ["dp", str(spec), "--dynamics-dir", str(pendulum / "dynamics"), "-o", str(out)]
        assert main(argv) == 2
    machine = physical_memory_bytes() / 2**30
    assert last_line(capsys) == (
        f"{spec}:9:6: expected a job that fits in 4.00 GiB of memory (this machine has "
        f"{machine:,.2f} GiB), found about 16.90 GiB (the DP of this grid and these control "
        'samples); raise MOSYS_MAX_MEMORY_GIB to allow it (README, "Limits")'
    )
    assert_nothing_written(out)


def test_the_dp_estimate_bounds_what_the_dp_takes():
    """The estimate is an upper bound of the transition tables the DP allocates."""
    spec = parse_controller_spec(SPECS / "controllers" / "pendulum" / "A.ssc")
    nodes, controls, corners = 36 * 21, 11, 2
    assert dp_memory_bytes(spec) >= nodes * controls * (corners * (4 + 4) + 8)


@pytest.mark.parametrize("value", ["abc", "0", "-1", "inf", "nan"])
def test_a_bad_limit_setting_is_an_error(tmp_path, pendulum, capsys, monkeypatch, value):
    monkeypatch.setenv("MOSYS_MAX_STEPS", value)
    text = "state link -90,0\nswapcon link conA.ctab\nsim 0.1\n"
    code, _, out = run_script(tmp_path, text, pendulum / "dynamics", pendulum / "controllers")
    assert code == 2
    assert last_line(capsys) == f"mosys: expected a number > 0 in MOSYS_MAX_STEPS, found {value!r}"
    assert_nothing_written(out)


def test_defaults(monkeypatch):
    monkeypatch.delenv("MOSYS_MAX_STEPS", raising=False)
    monkeypatch.delenv("MOSYS_MAX_MEMORY_GIB", raising=False)
    assert memory_limit_bytes() == pytest.approx(0.8 * physical_memory_bytes())
    check_job("here", "a job", DEFAULT_STEPS, 0.0)  # at the limit: allowed
    for steps, memory in ((DEFAULT_STEPS + 1, 0.0), (np.nan, 0.0), (0.0, np.inf), (0, np.nan)):
        with pytest.raises(SimulationError, match="^here: expected "):
            check_job("here", "a job", steps, memory)


def test_starts_refuses_a_tiny_dt(tmp_path, car_park, capsys):
    out = tmp_path / "starts.h5"
    table, dynamics = car_park / "controllers" / "park.h5", car_park / "dynamics" / "car.py"
    argv = ["starts", str(table), "--dynamics", str(dynamics)]
    argv += ["--x", "0", "1", "2", "--y", "1", "2", "2", "--dt", "1e-300", "-o", str(out)]
    assert main(argv) == 2
    assert last_line(capsys) == (
        "mosys starts: expected at most 10,000,000 integration steps per run, found 2e+301 "
        f"(20 s at dt 1e-300 s per start, 1 at once); {STEPS_HINT}"
    )
    assert_nothing_written(out)


def test_bsr_search_steps_are_limited(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("MOSYS_MAX_STEPS", "100")
    out = tmp_path / "seed1.h5"
    spec = SPECS / "bsr" / "starman_jump.bsr"
    argv = ["bsr-search", str(spec), "--seed", "1", "--generations", "1", "-o", str(out)]
    assert main(argv) == 2
    assert last_line(capsys) == (
        f"{spec}:5:1: expected at most 100 integration steps per run, found 400 (10 controllers "
        f"of 10 rules, 400 steps a run); {STEPS_HINT}"
    )
    assert_nothing_written(out)


def test_composite_ticks_are_limited(tmp_path, composite_workspace, capsys):
    """The issue's ticks=99999999999 (745 GiB)."""
    script = tmp_path / "starman_show.comp"
    text = composite_workspace.script.read_text()
    script.write_text(text.replace("ticks=150\n", "ticks=99999999999\n", 1))
    out = tmp_path / "show.h5"
    argv = ["composite", str(script), "--bsr-results", str(composite_workspace.bsr_results)]
    assert main([*argv, "-o", str(out)]) == 2
    message = last_line(capsys)
    assert message.startswith(
        f"{script}:9:59: expected at most 10,000,000 integration steps per run, found "
        "100,000,000,214 (the phases' 100,000,000,214 ticks to the end of this one)"
    )
    assert_nothing_written(out)


def test_composite_ticks_past_int64_together_are_limited_and_counted_exactly(
    tmp_path, composite_workspace, capsys
):
    """Each phase's ticks fit int64 (the parser's bound), their sum need not: the limits refuse
    it at its line, counted exactly (the verb fuzz found an OverflowError in NumPy's conversion
    of ticks past int64 before the parser bounded them)."""
    script = tmp_path / "starman_show.comp"
    text = composite_workspace.script.read_text()
    script.write_text(text.replace("ticks=150\n", f"ticks={2**63 - 1}\n", 1))
    out = tmp_path / "show.h5"
    argv = ["composite", str(script), "--bsr-results", str(composite_workspace.bsr_results)]
    assert main([*argv, "-o", str(out)]) == 2
    assert last_line(capsys).startswith(
        f"{script}:9:59: expected at most 10,000,000 integration steps per run, found "
        f"9.22e+18 (the phases' {215 + 2**63 - 1:,} ticks to the end of this one)"
    )
    assert_nothing_written(out)


def test_a_stale_dynamics_module_is_refused(tmp_path, pendulum, capsys):
    """A module compiled before the bounds (reproducer 2): its zero inertia would divide by zero
    in the DP's kernels."""
    dynamics = tmp_path / "dynamics"
    dynamics.mkdir()
    source = (pendulum / "dynamics" / "link1.py").read_text()
    assert source.count("ROD_LENGTH = (1.0,)") == 1
    source = source.replace("ROD_LENGTH = (1.0,)", "ROD_LENGTH = (1e-300,)")
    (dynamics / "link1.py").write_text(source)
    out = tmp_path / "A.h5"
    spec = SPECS / "controllers" / "pendulum" / "A.ssc"
    assert main(["dp", str(spec), "--dynamics-dir", str(dynamics), "-o", str(out)]) == 2
    assert last_line(capsys) == (
        f"mosys: {dynamics / 'link1.py'}: rod link's length is 1e-300 m, outside the figure "
        "spec's 1e-06..1e+06: fix the figure spec and compile it again"
    )
    assert_nothing_written(out)


def test_a_dp_segment_that_diverges_is_reported(link1):
    """An unsound control sample (nan) makes every segment's state non-finite: the DP stops with
    the spec's dyn line, the first node and the control."""
    spec = parse_controller_spec(SPECS / "controllers" / "pendulum" / "A.ssc")
    problem = build_problem(spec, link1)
    problem.control_samples[3] = np.nan
    with pytest.raises(SimulationError) as raised:
        solve(problem, link1, spec.tolerance, spec.max_iterations, spec.dt, quiet=True)
    assert str(raised.value).startswith(
        f"{spec.path}:6:5: the state became non-finite in the segment from node angle=-180, "
        "omega=-500 under torque=nan (756 of 8,316 segments): "
    )


def test_a_huge_bsr_population_is_refused_before_it_is_drawn(tmp_path, capsys):
    """``search controllers=2000000000`` parses (a count the kernels index) but its population
    (the senses of each controller's last run) would take about 300 TB."""
    text = (SPECS / "bsr" / "starman_jump.bsr").read_text()
    spec = tmp_path / "jump.bsr"
    spec.write_text(text.replace("controllers=10 ", "controllers=2000000000 "))
    out = tmp_path / "seed1.h5"
    argv = ["bsr-search", str(spec), "--seed", "1", "--generations", "1"]
    assert main([*argv, "--figures", str(SPECS / "figures"), "-o", str(out)]) == 2
    message = last_line(capsys)
    assert message.startswith(f"{spec}:5:1: expected a job that fits in ")
    assert (
        "(2,000,000,000 controllers of 10 rules, 400 steps a run); raise MOSYS_MAX_MEMORY_GIB"
        in message
    )
    assert_nothing_written(out)


def test_a_composite_search_of_too_many_arrays_is_refused(composite_workspace, capsys, tmp_path):
    out = tmp_path / "show.h5"
    argv = ["composite", str(composite_workspace.script), "--bsr-results"]
    argv += [str(composite_workspace.bsr_results), "--q", "2147483647", "-o", str(out)]
    assert main(argv) == 2  # 2^31 - 1 arrays of 3 phases: about 192 GiB
    message = last_line(capsys)
    assert message.startswith(f"{composite_workspace.script}:4:8: expected a job that fits in ")
    assert "found about 192.00 GiB (a transition search of 2,147,483,647 arrays)" in message
    assert_nothing_written(out)
