"""Arrays for kernels: borrowed views, cache-line rows and read-only inputs."""

from __future__ import annotations

import numpy as np
from numba import njit

from hairtool.kernel_arrays import aligned_rows, borrowed, readonly


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


def test_a_readonly_input_is_a_view_of_a_c_ordered_array_and_a_c_ordered_copy_of_another():
    """The brush's hot paths pass their live points through ``readonly`` at every move: a
    C-contiguous array (writable or not, or a contiguous slice) is viewed, never copied."""
    a = np.arange(24, dtype=np.float32).reshape(8, 3)
    for held in (a, a[2:6], readonly(a)):
        view = readonly(held)
        assert view.ctypes.data == held.ctypes.data and np.shares_memory(view, a)
        assert not view.flags.writeable and view.flags.c_contiguous
    assert a.flags.writeable  # the caller's array keeps its flag
    fortran = np.asfortranarray(a)
    copy = readonly(fortran)
    assert copy.flags.c_contiguous and not copy.flags.writeable and not np.shares_memory(copy, fortran)
    np.testing.assert_array_equal(copy, a)
