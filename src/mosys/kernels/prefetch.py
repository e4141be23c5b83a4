"""A hint to the processor's cache: fetch the memory that an array element will be read from soon.

The DP's value-iteration sweeps visit the rows of its exit tables in the 2**d orders of
``dp.sweep_order``, half of them with the grid's last axis backwards, where the processor's own
prefetcher falls behind: on the car's table (366,240 rows, 1.2 GB), replaying sweeps on its
near-converged cost-to-go, a sweep took 220–290 ms in those orders against 120–160 ms in memory
order, and asking for the rows a few nodes ahead took every order to 100–140 ms. Over a whole
value iteration, where most rows change in every sweep, the car's 222 sweeps were about 10 %
faster. A hint changes no value (LLVM's ``llvm.prefetch``: a read, kept in every cache level);
the callers only hint at elements that exist.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

_READ = 0  # llvm.prefetch's rw argument
_KEEP_IN_ALL_CACHES = 3  # its locality argument: the strongest
_DATA = 1  # its cache type: data, not instructions


@intrinsic
def prefetch(typingctx, array, indices):
    """``prefetch(array, (i, j, ...))``: ask the cache for the line holding ``array[i, j, ...]``
    (fewer indices than dimensions: the rest 0). No bounds check: give indices inside the array.
    """
    if not isinstance(array, types.Array) or not isinstance(indices, types.BaseTuple):
        return None
    if len(indices) > array.ndim or not all(isinstance(t, types.Integer) for t in indices):
        return None
    signature = types.void(array, indices)

    def codegen(context, builder, sig, args):
        array_type, indices_type = sig.args
        view = context.make_array(array_type)(context, builder, args[0])
        given = cgutils.unpack_tuple(builder, args[1], len(indices_type))
        index = [
            context.cast(builder, value, kind, types.intp)
            for value, kind in zip(given, indices_type, strict=True)
        ]
        index += [context.get_constant(types.intp, 0)] * (array_type.ndim - len(index))
        pointer = cgutils.get_item_pointer2(
            context,
            builder,
            data=view.data,
            shape=cgutils.unpack_tuple(builder, view.shape),
            strides=cgutils.unpack_tuple(builder, view.strides),
            layout=array_type.layout,
            inds=index,
            wraparound=False,
        )
        byte_pointer = ir.IntType(8).as_pointer()
        function_type = ir.FunctionType(
            ir.VoidType(), [byte_pointer, ir.IntType(32), ir.IntType(32), ir.IntType(32)]
        )
        function = cgutils.get_or_insert_function(builder.module, function_type, "llvm.prefetch.p0")
        flags = (_READ, _KEEP_IN_ALL_CACHES, _DATA)
        builder.call(
            function,
            [builder.bitcast(pointer, byte_pointer)]
            + [ir.Constant(ir.IntType(32), flag) for flag in flags],
        )
        return context.get_dummy_value()

    return signature, codegen
