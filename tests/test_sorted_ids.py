"""The sorted id sets a brush move asks for (:mod:`hairtool.sorted_ids`) are numpy's, value and
dtype, on generated integer arrays (empty, repeated, negative, already sorted or not)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.sorted_ids import distinct, distinct_sorted, union

ids = st.lists(st.integers(-5, 40), max_size=60).map(lambda v: np.array(v, np.int64))
small = st.lists(st.integers(0, 200), max_size=30).map(lambda v: np.array(v, np.int32))


def same(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@settings(max_examples=200, deadline=None)
@given(a=ids, b=st.one_of(ids, small))
def test_the_sets_are_numpys(a, b):
    assert same(distinct(a), np.unique(a))
    assert same(distinct(b), np.unique(b))
    assert same(distinct_sorted(np.sort(a)), np.unique(a))
    assert same(union(a, b), np.union1d(a, b))
    out = distinct_sorted(a)
    if a.size:
        out[0] += 1  # a new array: the caller's stays as it was
    assert not np.shares_memory(out, a)
