"""The compiler keeps each generated text in the dynamics cache (``compile.cached_source``):
compiling a figure again reads the text back, without sympy, and any change to the spec or to
the compiler's code makes a new one."""

from __future__ import annotations

import copy
import json
import subprocess
import sys
from pathlib import Path

import pytest

from mosys.dynamics import compile as compiler
from mosys.dynamics.compile import COMPILER_MODULES, compile_figure, generate_source, source_key
from mosys.dynamics.load import write_once
from mosys.parsing.tokens import SpecError

FIGURES = Path(__file__).resolve().parents[1] / "specs" / "figures"


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    monkeypatch.setenv("MOSYS_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache" / "sources"


def test_a_second_compile_reads_the_kept_text(tmp_path, cache, monkeypatch):
    spec = tmp_path / "link1.fig"
    spec.write_text((FIGURES / "link1.fig").read_text())
    compile_figure(spec, tmp_path / "first.py")
    assert [p.name for p in cache.iterdir()] == [f"{source_key(spec)}.py"]

    def derive_again(path):
        raise AssertionError("derived again")

    monkeypatch.setattr(compiler, "generate_source", derive_again)
    compile_figure(spec, tmp_path / "second.py")
    assert (tmp_path / "second.py").read_text() == (tmp_path / "first.py").read_text()
    assert (tmp_path / "first.py").read_text() == generate_source(spec)


def test_an_edited_spec_is_compiled_anew(tmp_path, cache):
    spec = tmp_path / "link1.fig"
    text = (FIGURES / "link1.fig").read_text()
    spec.write_text(text)
    compile_figure(spec, tmp_path / "before.py")
    key = source_key(spec)
    spec.write_text(text + "\n# a comment\n")
    assert source_key(spec) != key
    compile_figure(spec, tmp_path / "after.py")
    assert (tmp_path / "after.py").read_text() == generate_source(spec)
    assert len(list(cache.iterdir())) == 2


def test_the_key_covers_the_compilers_code(tmp_path, monkeypatch):
    spec = FIGURES / "link1.fig"
    key = source_key(spec)
    edited = tmp_path / "emit.py"
    edited.write_text(Path(compiler.__file__).with_name("emit.py").read_text() + "\n# edited\n")
    found = compiler.importlib.util.find_spec

    def find_edited(name):
        spec = copy.copy(found(name))  # not the imported module's own spec
        if name == "mosys.dynamics.emit":
            spec.origin = str(edited)
        return spec

    monkeypatch.setattr(compiler.importlib.util, "find_spec", find_edited)
    assert source_key(spec) != key


def test_deriving_reads_no_mosys_code_outside_the_key():
    """Every mosys module that deriving a text imports is in COMPILER_MODULES, or cannot change
    the text (packages, errors, the atomic write and its checks, the cache's directory)."""
    program = (
        "import json, sys\n"
        "from mosys.dynamics.compile import generate_source\n"
        f"for name in {['link1', 'double_pendulum', 'luxo', 'car']!r}:\n"
        f"    generate_source({str(FIGURES)!r} + '/' + name + '.fig')\n"
        "print(json.dumps(sorted(m for m in sys.modules if m.startswith('mosys'))))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", program], capture_output=True, text=True, check=True
    )
    loaded = set(json.loads(done.stdout.splitlines()[-1]))
    inert = {
        "mosys",
        "mosys.dynamics",
        "mosys.dynamics.load",
        "mosys.errors",
        "mosys.files",
        "mosys.io",
        "mosys.io.atomic",
        "mosys.parsing",
    }
    assert loaded - inert == set(COMPILER_MODULES)


def test_a_bad_spec_is_neither_compiled_nor_kept(tmp_path, cache):
    spec = tmp_path / "bad.fig"
    spec.write_text("rod r1 mass\n")
    with pytest.raises(SpecError):
        compile_figure(spec, tmp_path / "bad.py")
    assert not (tmp_path / "bad.py").exists()
    assert not cache.exists() or not list(cache.iterdir())


def test_a_kept_text_is_written_once_and_whole(tmp_path):
    kept = tmp_path / "sources" / "key.py"
    write_once(kept, b"first\n")
    write_once(kept, b"second\n")  # another process was first: its text stays
    assert kept.read_bytes() == b"first\n"
    assert [p.name for p in kept.parent.iterdir()] == ["key.py"]  # no partial file left


def test_a_controller_is_not_made_from_a_module_its_spec_has_outgrown(
    tmp_path, monkeypatch, capsys
):
    """A .fig edited after `mosys compile` (a heavier rod): `mosys dp` used the old module and
    said nothing; a run would too. Now both name the spec and the command that brings the
    module up to date. The pipeline recompiles first, so it never sees this."""
    from mosys.cli import main

    root = Path(__file__).resolve().parents[1]
    monkeypatch.chdir(tmp_path)
    (tmp_path / "specs").mkdir()
    figure = tmp_path / "specs" / "link1.fig"
    figure.write_bytes((root / "specs/figures/link1.fig").read_bytes())
    spec = root / "specs/controllers/pendulum/A.ssc"
    assert main(["compile", "specs/link1.fig", "-o", "dyn/link1.py"]) == 0
    assert main(["dp", str(spec), "--dynamics-dir", "dyn", "-o", "a.h5", "--quiet"]) == 0
    figure.write_text(figure.read_text().replace("mass=1", "mass=2"))
    capsys.readouterr()
    assert main(["dp", str(spec), "--dynamics-dir", "dyn", "-o", "b.h5", "--quiet"]) == 2
    assert (
        capsys.readouterr()
        .err.strip()
        .endswith(
            "expected a figure compiled from its spec as it is (dyn/link1.py was compiled from an "
            "earlier specs/link1.fig: run 'mosys compile specs/link1.fig -o dyn/link1.py', or "
            "snakemake), found 'link1'"
        )
    )
    assert not (tmp_path / "b.h5").exists()
