"""The numeric kernels (numba, ``cache=True``).

numba checks a cached function against its own source file only: a kernel that calls a kernel of
another file (``bsr3d_controller.run_lockstep`` calls ``bsr3d_simulate.step_motion``) would keep
running the callee as it was compiled. So the cache stands for the whole package: importing it
compares a digest of every kernel source file with the one the cache was built from and, if they
differ, removes the package's cached machine code (numba's ``.nbi``/``.nbc`` files, beside the
sources and, when ``NUMBA_CACHE_DIR`` is set, in numba's directory for them there) before anything
is compiled. And cold compilation happens once per machine, not once
per parallel job (``compile_lock``): importing the package puts numba's compilations after a
cache miss under a machine-wide lock.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from mosys.kernels.compile_lock import serialize_cold_compilation


def machine_code_directories(directory: Path) -> list[Path]:
    """Where numba keeps the machine code of the ``cache=True`` functions of the sources in
    ``directory``: ``__pycache__`` beside them and, when ``NUMBA_CACHE_DIR`` is set (numba
    then writes there), numba's directory for them under it."""
    from numba.core import config
    from numba.core.caching import UserProvidedCacheLocator

    places = [directory / "__pycache__"]
    if config.CACHE_DIR:
        source = str(directory / "__init__.py")
        subpath = UserProvidedCacheLocator.get_suitable_cache_subpath(source)
        places.append(Path(config.CACHE_DIR) / subpath)
    return places


def _forget_stale_machine_code(directory: Path) -> None:
    """Remove the cached machine code of the kernels in ``directory`` (in every one of
    ``machine_code_directories``) if any source changed since it was built (recorded in that
    directory's ``kernels.sha256``); nothing where it is unwritable."""
    digest = hashlib.sha256()
    for source in sorted(directory.glob("*.py")):
        digest.update(source.name.encode())
        digest.update(source.read_bytes())
    for cache in machine_code_directories(directory):
        stamp = cache / "kernels.sha256"
        try:
            if stamp.read_text(encoding="ascii") == digest.hexdigest():
                continue
        except OSError:
            pass
        try:
            cache.mkdir(parents=True, exist_ok=True)
            for pattern in ("*.nbi", "*.nbc"):
                for stale in cache.glob(pattern):
                    stale.unlink(missing_ok=True)
            stamp.write_text(digest.hexdigest(), encoding="ascii")
        except OSError:
            continue


_forget_stale_machine_code(Path(__file__).parent)
serialize_cold_compilation()
