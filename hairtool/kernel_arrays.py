"""Arrays for numba kernels whose hot loops slice: views without reference counting, rows on
cache lines; and read-only views that keep a kernel to one compiled signature.

Every view numba makes of an array (``a[lo:hi]``, ``g[k]``) takes a reference to the array's
buffer and drops it again, two atomic operations, and when two threads slice the same array they
fight over the counter's cache line. A kernel that slices per pass (to hand the compiler plain
0-based indices that it vectorises) pays that per pass: the seed-003 cost table had spent a third
of its time on it. Views of a :func:`borrowed` array count nothing.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numba.core import types
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array


@njit(cache=True, nogil=True, inline="always")
def aligned_rows(n_rows, length):
    """``(n_rows, ≥ length)`` zeros whose rows start on 64-byte boundaries (one cache line, one
    512-bit vector), so that vector loads along a row never straddle two lines."""
    stride = (length + 7) // 8 * 8
    buf = np.zeros(n_rows * stride + 8)
    start = ((-buf.ctypes.data) % 64) // 8
    return buf[start : start + n_rows * stride].reshape((n_rows, stride))


@intrinsic
def borrowed(typingctx, arr):
    """``arr`` as a view that holds no reference to its buffer, nor do views of it: the caller
    keeps ``arr`` itself alive (in use) for as long as the borrowed view is used."""
    if not isinstance(arr, types.Array):
        return None

    def codegen(context, builder, sig, args):
        owner = make_array(sig.args[0])(context, builder, args[0])
        view = make_array(sig.return_type)(context, builder)
        populate_array(view, owner.data, owner.shape, owner.strides, owner.itemsize, meminfo=None)
        return view._getvalue()

    return arr(arr), codegen


def readonly(a: np.ndarray) -> np.ndarray:
    """``a`` as a read-only, C-ordered view (a copy only where ``a`` is not C-contiguous). numba
    types an array's write flag and memory order: a kernel given a groom's read-only points once
    and a writable (or Fortran-ordered) copy of them another time compiles twice, each a compile
    of its own (seconds for a parallel kernel, on a studio's first run and in every fresh test
    run). Inputs passed through this compile one signature per dtype whatever the caller holds.
    """
    view = np.ascontiguousarray(a).view()
    view.flags.writeable = False
    return view
