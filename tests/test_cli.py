"""Bad input through the real command line: file:line:column message, exit 2, no output."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

from conftest import SPECS


def mosys(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "mosys.cli", *args], cwd=cwd, capture_output=True, text=True
    )


def test_broken_controller_spec(tmp_path):
    spec = tmp_path / "B.ssc"
    spec.write_text("dyn link1\nssd omega -500.0 fivehundred 21\n")
    done = mosys("dp", str(spec), "-o", "out.h5", cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr == f"{spec}:2:18: expected a number for max, found 'fivehundred'\n"
    assert list(tmp_path.iterdir()) == [spec]


def test_controller_spec_naming_an_unknown_state_variable(tmp_path, link1):
    dynamics = tmp_path / "dynamics"
    dynamics.mkdir()
    shutil.copy(link1.__file__, dynamics / "link1.py")
    spec = tmp_path / "A.ssc"
    spec.write_text(
        (SPECS / "controllers/pendulum/A.ssc")
        .read_text()
        .replace("ssd omega", "ssd omgea")
        .replace("omega=0", "omgea=0")
    )
    done = mosys("dp", str(spec), "--dynamics-dir", str(dynamics), "-o", "out.h5", cwd=tmp_path)
    assert done.returncode == 2
    line = next(n for n, text in enumerate(spec.read_text().splitlines(), 1) if "omgea" in text)
    assert done.stderr.startswith(f"{spec}:{line}:5: expected a state variable of figure")
    assert done.stderr.rstrip().endswith("found 'omgea'")
    assert not (tmp_path / "out.h5").exists()


def test_broken_figure_spec(tmp_path):
    spec = tmp_path / "bad.fig"
    spec.write_text("gravity lots\n")
    done = mosys("compile", str(spec), "-o", "bad.py", cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr.startswith(f"{spec}:1:9: expected ")
    assert not (tmp_path / "bad.py").exists()


def test_broken_script(tmp_path):
    script = tmp_path / "s.anim"
    script.write_text("state link -135,350\nswapcon link conB.ctab\nsim soon\n")
    done = mosys("run", str(script), "--controllers", str(tmp_path), "-o", "t.h5", cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr.startswith(f"{script}:3:5: expected ")
    assert not (tmp_path / "t.h5").exists()


def test_script_naming_a_missing_controller(tmp_path):
    script = tmp_path / "s.anim"
    script.write_text("state link -135,350\nswapcon link conZ.ctab\nsim 0.4\n")
    done = mosys("run", str(script), "--controllers", str(tmp_path), "-o", "t.h5", cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr.startswith(f"{script}:2:14: expected a controller table")
    assert not (tmp_path / "t.h5").exists()


def test_a_file_that_is_not_a_controller_table(tmp_path):
    table = tmp_path / "A.h5"
    table.write_text("not HDF5\n")
    done = mosys("plot", "controller", str(table), "--torque", "t.png", cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr.startswith("mosys: ")
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "t.png").exists()


def test_dynamics_module_from_an_older_mosys(tmp_path):
    dynamics = tmp_path / "dynamics"
    dynamics.mkdir()
    (dynamics / "link1.py").write_text('Q_NAMES = ("angle",)\n')
    spec = tmp_path / "A.ssc"
    spec.write_text((SPECS / "controllers/pendulum/A.ssc").read_text())
    done = mosys("dp", str(spec), "--dynamics-dir", str(dynamics), "-o", "out.h5", cwd=tmp_path)
    assert done.returncode == 2
    assert "is not a dynamics module of this mosys" in done.stderr
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "out.h5").exists()
