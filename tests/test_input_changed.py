"""An input edited while a command runs (a spec edited during a build) stops its outputs from
being written: made from the file as it was, they would be newer than the file as it is, and
Snakemake would never make them again."""

from __future__ import annotations

import io
import shutil
import sys
from pathlib import Path

import pytest

import mosys.dynamics.compile
from mosys.cli import error_code, main, stopped_code
from mosys.errors import InputError
from mosys.files import command_files, input_problem
from mosys.io.atomic import outputs_together, write_text_atomically

SPECS = Path(__file__).resolve().parents[1] / "specs"


def test_an_input_changed_before_the_outputs_are_renamed_writes_nothing(tmp_path):
    spec = tmp_path / "a.spec"
    spec.write_text("as read\n")
    out = tmp_path / "out" / "a.txt"
    changed = pytest.raises(InputError, match="changed while this command ran")
    with changed, command_files(), outputs_together():
        assert input_problem(spec) is None  # read: recorded as it was
        write_text_atomically(out, "made from the spec as read")
        spec.write_text("edited meanwhile\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.spec"]  # no output, no folder


def test_an_unchanged_input_and_the_editors_save_write_as_before(tmp_path):
    spec = tmp_path / "a.spec"
    spec.write_text("as read\n")
    with command_files(), outputs_together():
        assert input_problem(spec) is None
        write_text_atomically(spec, "saved by the command itself\n", saves_opened_file=True)
        write_text_atomically(tmp_path / "b.txt", "another output")
    assert (tmp_path / "b.txt").read_text() == "another output"


def test_a_spec_edited_while_compile_runs_is_one_line_and_exit_2(tmp_path, monkeypatch, capsys):
    spec = tmp_path / "link1.fig"
    shutil.copy(SPECS / "figures" / "link1.fig", spec)
    real = mosys.dynamics.compile.cached_source

    def source_then_edit(path):
        text = real(path)
        with Path(path).open("a") as edited:
            edited.write("# edited during the build\n")
        return text

    monkeypatch.setattr(mosys.dynamics.compile, "cached_source", source_then_edit)
    monkeypatch.chdir(tmp_path)
    assert main(["compile", "link1.fig", "-o", "link1.py"]) == 2
    assert capsys.readouterr().err == (
        "mosys: link1.fig: changed while this command ran (it read the file as it was "
        "before); nothing written: run it again\n"
    )
    assert not (tmp_path / "link1.py").exists()


@pytest.mark.parametrize(
    "stop", [lambda: error_code(InputError("A.ssc: changed")), lambda: stopped_code(2)]
)
def test_what_the_command_printed_is_put_out_before_its_error(monkeypatch, stop):
    """In the job server's fork stdout is a buffered file until the command ends: ``mosys dp``'s
    summary (which names its output) came after the error saying nothing was written."""
    events = []

    class Stream(io.StringIO):
        def __init__(self, name):
            super().__init__()
            self.name = name

        def write(self, text):
            events.append((self.name, text))
            return len(text)

        def flush(self):
            events.append((self.name, "flush"))

    monkeypatch.setattr(sys, "stdout", Stream("out"))
    monkeypatch.setattr(sys, "stderr", Stream("err"))
    assert stop() in (2, 130)
    first_error = next(k for k, (name, text) in enumerate(events) if name == "err")
    assert ("out", "flush") in events[:first_error]
