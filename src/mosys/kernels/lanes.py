"""Four-lane float64 vectors for numba kernels: what the 3-D BSR runs compute for four
controllers at once in lockstep (``bsr3d_lanes``; README, "3-D figures", Measured).

numba's LLVM does not vectorise a loop over controllers by itself (the arrays may alias, and
numba ships LLVM's SLP vectoriser switched off), so these functions write the vector operations
out: a value is a 4-tuple of float64 to numba (``Lanes``), and each operation is an intrinsic
that emits one LLVM ``<4 x double>`` instruction between conversions that LLVM folds away. In
Python (``NUMBA_DISABLE_JIT``, or called from Python) each is the same operation on tuples.

Arrays hold lanes last and contiguous: ``load(array, offset)`` reads the 4 float64 from flat
element ``offset`` of a C-contiguous array on, ``store`` writes them.
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic, overload

LANES = 4
Lanes = tuple[float, float, float, float]

_LANES_TYPE = types.UniTuple(types.float64, LANES)
_VECTOR = ir.VectorType(ir.DoubleType(), LANES)


def _vector(builder, value):
    vector = ir.Constant(_VECTOR, ir.Undefined)
    for lane in range(LANES):
        item = builder.extract_value(value, lane)
        vector = builder.insert_element(vector, item, ir.Constant(ir.IntType(32), lane))
    return vector


def _lanes(context, builder, vector):
    value = ir.Constant(context.get_value_type(_LANES_TYPE), ir.Undefined)
    for lane in range(LANES):
        item = builder.extract_element(vector, ir.Constant(ir.IntType(32), lane))
        value = builder.insert_value(value, item, lane)
    return value


def _binary(instruction):
    @intrinsic
    def operation(typingctx, a, b):
        if a != _LANES_TYPE or b != _LANES_TYPE:
            return None

        def codegen(context, builder, signature, args):
            x, y = (_vector(builder, value) for value in args)
            return _lanes(context, builder, getattr(builder, instruction)(x, y))

        return _LANES_TYPE(_LANES_TYPE, _LANES_TYPE), codegen

    return operation


_add, _subtract, _multiply, _divide = (_binary(name) for name in ("fadd", "fsub", "fmul", "fdiv"))


def add(a: Lanes, b: Lanes) -> Lanes:
    """a + b, lane by lane."""
    return tuple(x + y for x, y in zip(a, b, strict=True))


def subtract(a: Lanes, b: Lanes) -> Lanes:
    """a - b, lane by lane."""
    return tuple(x - y for x, y in zip(a, b, strict=True))


def multiply(a: Lanes, b: Lanes) -> Lanes:
    """a * b, lane by lane."""
    return tuple(x * y for x, y in zip(a, b, strict=True))


def divide(a: Lanes, b: Lanes) -> Lanes:
    """a / b, lane by lane (IEEE: inf or NaN on a zero, no exception)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return tuple(float(np.float64(x) / np.float64(y)) for x, y in zip(a, b, strict=True))


def splat(x: float) -> Lanes:
    """x in every lane."""
    return (float(x),) * LANES


def load(array: np.ndarray, offset: int) -> Lanes:
    """The LANES float64 of a C-contiguous array's data from flat element ``offset`` on."""
    flat = array.reshape(-1)
    return tuple(float(flat[offset + lane]) for lane in range(LANES))


def store(array: np.ndarray, offset: int, value: Lanes) -> None:
    """Write ``value`` to the LANES float64 of a C-contiguous array from flat element ``offset``."""
    flat = array.reshape(-1)
    for lane in range(LANES):
        flat[offset + lane] = value[lane]


@intrinsic
def _splat(typingctx, x):
    if x != types.float64:
        return None

    def codegen(context, builder, signature, args):
        vector = ir.Constant(_VECTOR, ir.Undefined)
        for lane in range(LANES):
            vector = builder.insert_element(vector, args[0], ir.Constant(ir.IntType(32), lane))
        return _lanes(context, builder, vector)

    return _LANES_TYPE(types.float64), codegen


def _is_float_array(array) -> bool:
    return isinstance(array, types.Array) and array.dtype == types.float64 and array.layout == "C"


@intrinsic
def _load(typingctx, array, offset):
    if not _is_float_array(array) or not isinstance(offset, types.Integer):
        return None

    def codegen(context, builder, signature, args):
        data = context.make_array(signature.args[0])(context, builder, args[0]).data
        pointer = builder.bitcast(builder.gep(data, [args[1]]), _VECTOR.as_pointer())
        return _lanes(context, builder, builder.load(pointer, align=8))

    return _LANES_TYPE(array, types.intp), codegen


@intrinsic
def _store(typingctx, array, offset, value):
    if not _is_float_array(array) or not isinstance(offset, types.Integer):
        return None
    if value != _LANES_TYPE:
        return None

    def codegen(context, builder, signature, args):
        data = context.make_array(signature.args[0])(context, builder, args[0]).data
        pointer = builder.bitcast(builder.gep(data, [args[1]]), _VECTOR.as_pointer())
        builder.store(_vector(builder, args[2]), pointer, align=8)
        return context.get_dummy_value()

    return types.void(array, types.intp, _LANES_TYPE), codegen


@overload(splat, inline="always")
def _splat_in_numba(x):
    return lambda x: _splat(np.float64(x))


@overload(load, inline="always")
def _load_in_numba(array, offset):
    return lambda array, offset: _load(array, offset)


@overload(store)
def _store_in_numba(array, offset, value):
    return lambda array, offset, value: _store(array, offset, value)


def _binary_overload(intrinsic_function):
    def typer(a, b):
        return lambda a, b: intrinsic_function(a, b)

    return typer


for _function, _intrinsic in (
    (add, _add),
    (subtract, _subtract),
    (multiply, _multiply),
    (divide, _divide),
):
    overload(_function, inline="always")(_binary_overload(_intrinsic))
