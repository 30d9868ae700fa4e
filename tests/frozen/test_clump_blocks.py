"""The runs of vertices of about equal work that ClumpWithGaps' pair and force passes share out."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.frozen.clump import work_blocks, work_blocks_reference


@st.composite
def _lists(draw):
    """Forward counts and backward runs of a few vertices, some dense, some empty."""
    v = draw(st.integers(1, 40))
    acnt = np.array(draw(st.lists(st.integers(0, 60), min_size=v, max_size=v)), np.int64)
    back = np.array(draw(st.lists(st.integers(0, 60), min_size=v, max_size=v)), np.int64)
    bstart = np.concatenate([[0], np.cumsum(back)]).astype(np.int64)
    return acnt, bstart, draw(st.booleans()), draw(st.integers(1, v))


@settings(max_examples=60, deadline=None)
@given(_lists())
def test_work_blocks_match_their_numpy_twin_and_cover_every_vertex_in_order(lists):
    acnt, bstart, both, n = lists
    blocks = np.empty(n + 1, np.int64)
    work_blocks(acnt, bstart, both, n, blocks)
    np.testing.assert_array_equal(blocks, work_blocks_reference(acnt, bstart, both, n))
    assert blocks[0] == 0 and blocks[-1] == acnt.size and np.all(np.diff(blocks) >= 0)


def test_a_groom_dense_at_one_end_is_shared_by_work_not_by_vertices():
    acnt = np.r_[np.zeros(900, np.int64), np.full(100, 90, np.int64)]
    bstart = np.zeros(1001, np.int64)
    blocks = np.empty(3, np.int64)
    work_blocks(acnt, bstart, True, 2, blocks)
    w = acnt + 1
    halves = [w[blocks[0] : blocks[1]].sum(), w[blocks[1] : blocks[2]].sum()]
    assert abs(halves[0] - halves[1]) < 2 * w.max()  # not 900 vertices against 100
