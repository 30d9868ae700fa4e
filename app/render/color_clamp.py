"""Vertex colours checked and clamped to [0, 1] in one pass.

The studio hands the renderer the colours of every drawn vertex whenever the drawn strands
change (3.2 million of them when a stroke of render hair is released): numpy's finiteness test
and clip are three passes and two temporaries over them. :func:`clamp_colors` is the kernel,
:func:`clamp_colors_reference` its numpy twin.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import NDArray


@njit(cache=True, nogil=True, parallel=True)
def _clamp_kernel(c, out):
    """``out`` = c clamped to [0, 1]; returns how many rows hold a non-finite value."""
    bad = 0
    for i in prange(c.shape[0]):
        row_bad = 0
        for k in range(c.shape[1]):
            x = c[i, k]
            if not np.isfinite(x):
                row_bad = 1
            out[i, k] = min(max(x, np.float32(0.0)), np.float32(1.0))
        bad += row_bad
    return bad


def clamp_colors(colors: NDArray[np.float32], out: NDArray[np.float32]) -> bool:
    """Write ``colors`` ``(V, 3)`` float32 clamped to [0, 1] into ``out``; False (``out`` then
    undefined) when one of them is not finite."""
    return _clamp_kernel(colors, out) == 0


def clamp_colors_reference(colors: NDArray[np.float32], out: NDArray[np.float32]) -> bool:
    """Numpy twin of :func:`clamp_colors`."""
    np.clip(colors, 0.0, 1.0, out=out)
    return bool(np.all(np.isfinite(colors)))
