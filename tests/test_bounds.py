import numpy as np
import pytest

from hairtool.bounds import box, box_reference, moved_box
from hairtool.errors import GroomError
from hairtool.groom import Groom


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("n", [1, 2, 7, 1000])
def test_box_matches_numpy(dtype, n):
    p = (np.random.default_rng(n).normal(size=(n, 3)) * [1.0, 100.0, 1e-3]).astype(dtype)
    lo, hi = box(p)
    rlo, rhi = box_reference(p)
    assert lo.dtype == dtype and hi.dtype == dtype
    np.testing.assert_array_equal(lo, rlo)
    np.testing.assert_array_equal(hi, rhi)


def test_box_nan_column_is_nan_like_numpy():
    p = np.zeros((5, 3), np.float32)
    p[3, 1] = np.nan
    p[0, 0] = -2.0
    lo, hi = box(p)
    np.testing.assert_array_equal(lo, box_reference(p)[0])
    np.testing.assert_array_equal(hi, box_reference(p)[1])
    assert np.isnan(lo[1]) and lo[0] == -2.0


def test_box_refuses_empty_and_wrong_shape():
    with pytest.raises(GroomError, match="V ≥ 1"):
        box(np.zeros((0, 3)))
    with pytest.raises(GroomError, match="shape"):
        box(np.zeros((4, 2)))


def test_groom_bounds_is_the_box_and_read_only():
    g = Groom(np.random.default_rng(0).normal(size=(12, 3)), [4, 8])
    lo, hi = g.bounds
    np.testing.assert_array_equal(lo, g.points.min(axis=0))
    np.testing.assert_array_equal(hi, g.points.max(axis=0))
    with pytest.raises(ValueError):
        lo[0] = 0.0


def test_a_moved_box_is_the_box_of_the_moved_points_or_unknown_where_an_extreme_moved():
    rng = np.random.default_rng(3)
    p = rng.normal(size=(400, 3)).astype(np.float32)
    raw = tuple(b.astype(np.float64) for b in box(p))
    lo_at = int(np.argmin(p[:, 0]))
    for k in range(20):
        rows = np.sort(rng.choice(400, size=5, replace=False))
        rows = rows[rows != lo_at] if k % 2 else np.union1d(rows, [lo_at])
        q = p.copy()
        q[rows] += rng.normal(scale=3.0 if k % 3 else 0.1, size=(rows.size, 3)).astype(np.float32)
        got = moved_box(raw, p[rows], q[rows])
        held = np.any(p[rows] == raw[0]) or np.any(p[rows] == raw[1])
        assert (got is None) == held  # (with lo_at moved, always unknown)
        if got is not None:
            want = box_reference(q)
            np.testing.assert_array_equal(got[0], want[0].astype(np.float64))
            np.testing.assert_array_equal(got[1], want[1].astype(np.float64))
    assert moved_box(raw, p[:0], p[:0]) == raw
