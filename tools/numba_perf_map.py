"""Run a Python script so that ``perf`` can name the numba functions it spends its time in.

    perf record -F 5000 -o run.perf python tools/numba_perf_map.py SCRIPT [ARGS...]
    perf report -i run.perf --no-children --sort dso,sym

numba's machine code lives in anonymous memory, which ``perf report`` shows as bare addresses
(``[JIT] tid N``). When the script ends (also by raising or exiting), this writes
``/tmp/perf-PID.map``, the map ``perf`` reads for such code: the address, size and name
(``module.function``) of every function of every compiled numba dispatcher. The script runs
with a fresh, empty numba cache (a temporary ``NUMBA_CACHE_DIR``): numba keeps a compiled
function's object code, where the map's sizes come from, only when it compiles it in the
process; so the run includes a cold compilation, which the profile shows apart (in
``libllvmlite``). Inlined functions are part of their caller.
"""

from __future__ import annotations

import os
import re
import runpy
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path


def readable(symbol: str) -> str:
    """``module.function`` of a numba-mangled symbol (``_ZN5mosys7kernels...``), else the
    symbol as it is."""
    if not symbol.startswith("_ZN"):
        return symbol
    parts, i = [], 3
    while i < len(symbol) and symbol[i].isdigit():
        digits = re.match(r"\d+", symbol[i:]).group()
        start = i + len(digits)
        parts.append(symbol[start : start + int(digits)])
        i = start + int(digits)
    return ".".join(parts[-2:]) if parts else symbol


def functions() -> list[tuple[int, int, str]]:
    """(address, size, name) of every function in the object code of every numba overload
    compiled in this process, and of numba's reference counting."""
    import gc

    from numba.core.registry import CPUDispatcher
    from numba.core.runtime import nrt

    libraries = {
        id(overload.library): overload.library
        for dispatcher in gc.get_objects()
        if isinstance(dispatcher, CPUDispatcher)
        for overload in dispatcher.overloads.values()
    }
    found = []
    with tempfile.TemporaryDirectory() as scratch:
        for number, library in enumerate(libraries.values()):
            try:
                code = library._get_compiled_object()
            except RuntimeError:  # loaded from a cache: no object code kept
                continue
            path = Path(scratch) / f"{number}.o"
            path.write_bytes(code)
            listing = subprocess.run(
                ["nm", "-S", "--defined-only", str(path)], capture_output=True, text=True
            ).stdout
            for line in listing.splitlines():
                fields = line.split()
                if len(fields) == 4 and fields[2] in "tT":
                    address = library.get_pointer_to_function(fields[3])
                    if address:
                        found.append((address, int(fields[1], 16), readable(fields[3])))
    for name in ("NRT_incref", "NRT_decref"):
        found.append((nrt.rtsys.library.get_pointer_to_function(name), 16, name))
    return sorted(set(found))


def write_map() -> None:
    with open(f"/tmp/perf-{os.getpid()}.map", "w", encoding="ascii") as out:
        for address, size, name in functions():
            out.write(f"{address:x} {size:x} {name}\n")


def main() -> None:
    if len(sys.argv) < 2 or not Path(sys.argv[1]).is_file():
        found = f"{sys.argv[1]!r}, not a file" if len(sys.argv) > 1 else "nothing"
        print(
            f"usage: python tools/numba_perf_map.py SCRIPT [ARGS...]: expected a Python script, "
            f"found {found}",
            file=sys.stderr,
        )
        sys.exit(2)
    if shutil.which("nm") is None:
        print("numba_perf_map: needs binutils' nm (to read the functions' sizes)", file=sys.stderr)
        sys.exit(2)
    os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="numba-perf-map-")
    script = sys.argv[1]
    sys.argv = sys.argv[1:]
    sys.path.insert(0, str(Path(script).resolve().parent))
    try:
        runpy.run_path(script, run_name="__main__")
    finally:
        write_map()


if __name__ == "__main__":
    main()
