"""Borrowed views: arrays (and tuples of them) that numba's runtime does not count references of.

Every array numba binds to a new variable, slices, or unpacks from a tuple has its reference count
raised and lowered, each an atomic instruction; numba's reference-count pruning removes the pairs
it can prove redundant, but not those of a long loop body with many branches, such as a
simulator's step inlined in its run (in a 3-D BSR run they were 9 % of the time). A borrowed view
is the same array with no owner: its counts are never touched. It is valid only while the array
it was made from is alive, which its maker must see to (an argument of the function that made
it, or a local used again after the view's last use), and it must not leave the kernels: returned
to Python, an array that numba allocated would have no owner at all.
"""

from __future__ import annotations

from typing import TypeVar

from numba import types
from numba.core import cgutils
from numba.extending import intrinsic, overload

Value = TypeVar("Value")


def borrowed(value: Value) -> Value:
    """``value`` (an array, a tuple or named tuple of arrays and scalars, nested) with every array
    replaced by a view of the same data that no reference count covers (the module's docstring
    says when that is safe). In Python (``NUMBA_DISABLE_JIT``, or called from Python) it is
    ``value`` itself."""
    return value


def _borrow(context, builder, typ, value):
    if isinstance(typ, types.Array):
        array = context.make_array(typ)(context, builder, value)
        array.meminfo = cgutils.get_null_value(array.meminfo.type)
        return array._getvalue()
    if isinstance(typ, types.BaseTuple):
        out = value
        for index, member in enumerate(typ):
            item = builder.extract_value(value, index)
            out = builder.insert_value(out, _borrow(context, builder, member, item), index)
        return out
    return value


@intrinsic
def _borrowed(typingctx, value):
    def codegen(context, builder, signature, args):
        return _borrow(context, builder, signature.args[0], args[0])

    return value(value), codegen


# (not inline="always": numba then compiles writes through arrays in the borrowed tuple wrongly,
# numba/numba#10037; called, the function is inlined by LLVM anyway)
@overload(borrowed)
def _borrowed_in_numba(value):
    return lambda value: _borrowed(value)


def keep_alive(value: object) -> None:
    """Nothing: a use of ``value`` (an array or a tuple of them) at this point, so that numba
    keeps it, and the memory of the borrowed views made from it, alive to here."""


@intrinsic
def _keep_alive(typingctx, value):
    def codegen(context, builder, signature, args):
        return context.get_dummy_value()

    return types.none(value), codegen


@overload(keep_alive)
def _keep_alive_in_numba(value):
    return lambda value: _keep_alive(value)
