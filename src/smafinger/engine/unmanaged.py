"""Array views without reference counting, for the compiled kernel's per-sub-step path.

Numba counts references to every array it passes to a function that is not inlined: an atomic
increment and decrement per call. The kernel passes each wire's reversal-point stack to the
memory update at every sub-step and its output arrays to the sample writer, and ``perf`` put
about a quarter of a long-step run's samples in ``NRT_incref``/``NRT_decref`` (docs/speed.md).
:func:`unmanaged` gives a view of the same memory that carries no reference (a NULL meminfo,
like :func:`numba.carray` on a raw pointer), so passing it costs nothing.

The caller must keep the array itself alive while the view is in use: the kernel takes arrays
its Python caller owns (the outputs, the memory stacks) and makes the views once, at its start.
In Python (the interpreted engine) the view is the array itself.
"""

from numba import carray, types
from numba.core import cgutils
from numba.core.errors import TypingError
from numba.extending import intrinsic, overload


def unmanaged(a):
    """A view of the C-contiguous array ``a`` without reference counting (compiled code); ``a`` in Python."""
    return a


@intrinsic
def _void_pointer(typingctx, address):
    """The integer ``address`` as a ``void*``."""
    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], cgutils.voidptr_t)

    return types.voidptr(address), codegen


@overload(unmanaged)
def _unmanaged_compiled(a):
    if not isinstance(a, types.Array) or a.layout != "C":
        raise TypingError(f"unmanaged takes a C-contiguous array, not {a}")
    dtype = a.dtype

    def impl(a):
        return carray(_void_pointer(a.ctypes.data), a.shape, dtype)

    return impl
