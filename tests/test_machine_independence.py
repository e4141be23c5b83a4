"""What the same spec and seed store does not depend on the SIMD instructions the processor
has: nothing a search stores is computed by NumPy's processor-dependent SIMD code (on AVX-512,
NumPy's exp differs from libm's in the last bit for about 5 % of arguments; a search drew its
rules' sides with it, so the same seed stored other sides on a machine without AVX-512). Here
such a machine is emulated by switching NumPy's dispatched code off
(``NPY_DISABLE_CPU_FEATURES``: the processor then runs NumPy's baseline code, as one without
those features would; the numba kernels are compiled for the processor either way)."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from mosys.composite.evaluate import falloff
from mosys.kernels.libm import arctan2_each, exp_each

ROOT = Path(__file__).resolve().parents[1]


def libm_exp(value: float) -> float:
    try:
        return math.exp(value)
    except OverflowError:
        return math.inf


def dispatched_features() -> list[str]:
    """The processor features NumPy chooses code for at run time (beyond its baseline)."""
    try:
        from numpy._core import _multiarray_umath
    except ImportError:  # NumPy 1
        from numpy.core import _multiarray_umath
    return list(_multiarray_umath.__cpu_dispatch__)


@settings(deadline=None)  # the first call may compile the kernel
@given(arrays(np.float64, st.integers(0, 40), elements=st.floats(allow_subnormal=True)))
def test_exp_each_is_libms_exp(values: np.ndarray) -> None:
    expected = np.array([libm_exp(v) for v in values])
    np.testing.assert_array_equal(exp_each(values), expected)
    assert exp_each(values.reshape(-1, 1)).shape == (values.size, 1)


@settings(deadline=None)
@given(
    st.integers(0, 40).flatmap(
        lambda n: st.tuples(*(arrays(np.float64, n, elements=st.floats()) for _ in range(2)))
    )
)
def test_arctan2_each_is_libms_atan2(points: tuple[np.ndarray, np.ndarray]) -> None:
    y, x = points
    expected = np.array([math.atan2(a, b) for a, b in zip(y, x, strict=True)])
    np.testing.assert_array_equal(arctan2_each(y, x), expected)
    assert arctan2_each(y.reshape(1, -1), x.reshape(1, -1)).shape == (1, y.size)


def test_arctan2_each_refuses_points_of_two_shapes() -> None:
    with pytest.raises(ValueError, match=r"y \(2,\) and x \(3,\) differ in shape"):
        arctan2_each(np.zeros(2), np.zeros(3))


@settings(deadline=None)
@given(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3))
def test_the_falloff_is_computed_by_libm(a: float, b: float) -> None:
    width = 0.2 * max(abs(b), 1.0)
    got = falloff(np.array([[a]]), np.array([[b]]))
    assert got.shape == (1, 1)
    z = (a - b) / width
    assert got[0, 0] == libm_exp(-(z * z))  # z ** 2 is libm's pow, an ulp off at times


TIMES = ("compile_seconds", "steps_per_second", "wall_seconds")  # how long it took, not what


def contents(path: Path) -> dict[str, np.ndarray]:
    """Every dataset of the HDF5 file at ``path`` by its name, and every root attribute but
    TIMES by ``@`` and its name."""
    found = {}

    def keep(name: str, item) -> None:
        if isinstance(item, h5py.Dataset):
            found[name] = item[()]

    with h5py.File(path) as h5:
        h5.visititems(keep)
        found.update({f"@{k}": np.asarray(v) for k, v in h5.attrs.items() if k not in TIMES})
    return found


def run_twice(arguments: list[str], out: Path) -> tuple[dict, dict]:
    """``mosys ARGUMENTS -o out/NAME.h5`` with NumPy's dispatched code (``simd``) and without
    it (``baseline``): each file's ``contents``."""
    features = " ".join(dispatched_features())
    runs = {"simd": {}, "baseline": {"NPY_DISABLE_CPU_FEATURES": features}}
    for name, extra in runs.items():
        command = [sys.executable, "-m", "mosys.cli", *arguments, "-o", str(out / f"{name}.h5")]
        done = subprocess.run(
            command, cwd=ROOT, env={**os.environ, **extra}, capture_output=True, text=True
        )
        assert done.returncode == 0, done.stderr
    simd, baseline = contents(out / "simd.h5"), contents(out / "baseline.h5")
    assert simd.keys() == baseline.keys()
    return simd, baseline


@pytest.mark.parametrize("search", ["starman_shuffle", "bob_walk"])
def test_a_search_stores_the_same_numbers_without_numpys_simd_code(
    search: str, tmp_path: Path
) -> None:
    # sense-based searches (rules with sides, drawn and crept), 2-D and 3-D
    simd, baseline = run_twice(
        ["bsr-search", f"specs/bsr/{search}.bsr", "--seed", "1", "--figures", "specs/figures",
         "--generations", "15", "--threads", "1"],
        tmp_path,
    )  # fmt: skip
    assert "best/controller/side" in simd
    for name in simd:
        np.testing.assert_array_equal(simd[name], baseline[name], err_msg=name)


def test_a_composite_search_stores_the_same_numbers_without_numpys_simd_code(
    composite_workspace, tmp_path: Path
) -> None:
    # the script's ?= (an exponential) in every score; the phases' measures (an arctan2)
    simd, baseline = run_twice(
        ["composite", str(composite_workspace.script), "--bsr-results",
         str(composite_workspace.bsr_results), "--q", "4", "--g", "3", "--h", "2"],
        tmp_path,
    )  # fmt: skip
    assert {"search/best_score", "@scores_after", "@ticks_after"} <= simd.keys()
    for name in simd:
        np.testing.assert_array_equal(simd[name], baseline[name], err_msg=name)
