"""The kernels' arithmetic, written in numpy for their twins: a length or a dot product of
3-vectors as three products summed left to right, and a running total summed in order.

numpy's ``dot``, ``@`` and the 1-D ``linalg.norm`` go through BLAS, whose kernels fuse
multiply-adds and so round differently from a kernel's ``x*x + y*y + z*z`` (numba does not
contract); ``ndarray.sum`` adds pairwise from 8 values on. Either moves a twin's last bits
off the kernel's, which a later cancellation (a length restore) can make visible.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def dot3(a: F64, b: F64) -> F64:
    """``a · b`` over the last axis (of size 3), as ``a0*b0 + a1*b1 + a2*b2`` in that order.

    Parameters
    ----------
    a, b : numpy.ndarray, ``(..., 3)`` float64
        Vectors (broadcast against each other).

    Returns
    -------
    numpy.ndarray
        ``(...)`` the dot products (a 0-d array for two single vectors).
    """
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def norm3(v: F64) -> F64:
    """``|v|`` over the last axis (of size 3): ``sqrt(x*x + y*y + z*z)`` as a kernel writes it.

    Parameters
    ----------
    v : numpy.ndarray, ``(..., 3)`` float64
        Vectors.

    Returns
    -------
    numpy.ndarray
        ``(...)`` their lengths.
    """
    return np.sqrt(dot3(v, v))


def running_sum(x: F64) -> F64:
    """``(n + 1,)`` 0 then the running total of ``x`` added left to right (its last entry is
    the total a kernel's loop adds up, which ``x.sum()`` need not be).

    Parameters
    ----------
    x : numpy.ndarray, ``(n,)`` float64
        The values.

    Returns
    -------
    numpy.ndarray
        ``(n + 1,)`` float64.
    """
    return np.concatenate([[0.0], np.cumsum(np.asarray(x, np.float64))])
