"""Atomic output (``io.atomic``): two writers of one path at once each finish whole, and the file
left is one of theirs, never a mix; a writer that fails leaves neither its partial file nor a
change at the path."""

from __future__ import annotations

import threading
import time
from pathlib import Path

import pytest

from mosys.io.atomic import write_atomically


def slow_writer(letter: str, started: threading.Barrier):
    def write(partial: Path) -> None:
        with partial.open("w") as out:
            started.wait()  # both writers are inside write() at once
            for _ in range(20):
                out.write(letter * 1000)
                out.flush()
                time.sleep(0.001)

    return write


def test_two_writers_of_one_path_at_once_leave_one_whole_file(tmp_path):
    path = tmp_path / "table.csv"
    started = threading.Barrier(2)
    errors = []

    def run(letter: str) -> None:
        try:
            write_atomically(path, slow_writer(letter, started))
        except Exception as error:  # noqa: BLE001 - reported below
            errors.append(error)

    threads = [threading.Thread(target=run, args=(letter,)) for letter in "AB"]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not errors
    assert path.read_text() in ("A" * 20_000, "B" * 20_000)
    assert [p.name for p in tmp_path.iterdir()] == ["table.csv"]


def test_a_failed_write_leaves_the_old_file_and_no_partial(tmp_path):
    path = tmp_path / "plot.png"
    path.write_text("old")

    def fail(partial: Path) -> None:
        partial.write_text("half")
        raise ValueError("bad input")

    with pytest.raises(ValueError, match="bad input"):
        write_atomically(path, fail)
    assert path.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["plot.png"]
