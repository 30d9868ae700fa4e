"""Arrays for kernels that slice in hot loops: borrowed views and cache-line rows."""

from __future__ import annotations

import numpy as np
from numba import njit

from hairtool.kernel_arrays import aligned_rows, borrowed


@njit(cache=True)
def _write_through_borrowed_views(a, lo, hi):
    b = borrowed(a)
    for k in range(lo, hi):
        v = b[k : k + 2]  # a view of the borrowed array: the same memory
        v[0] += k
    return b[lo:hi].sum()


def test_views_of_a_borrowed_array_are_the_owners_memory():
    a = np.zeros(10)
    total = _write_through_borrowed_views(a, 2, 6)
    np.testing.assert_array_equal(a, [0, 0, 2, 3, 4, 5, 0, 0, 0, 0])
    assert total == 14.0


@njit(cache=True)
def _rows(n, length):
    return aligned_rows(n, length)


def test_aligned_rows_start_on_cache_lines():
    for length in (1, 9, 1307):
        rows = _rows(5, length)
        assert rows.shape[0] == 5 and rows.shape[1] >= length and not rows.any()
        assert all(rows[c].ctypes.data % 64 == 0 for c in range(5))
