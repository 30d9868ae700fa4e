"""The numba pose kernel against its numpy reference, and its independence from the thread count."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from hairtool import samples
from hairtool.anime.schedule import schedule
from hairtool.anime.wave import WaveParams, make_bunches, pose_pictures
from hairtool.groom import Groom


def mixed() -> Groom:
    """A zero-length strand, a bent 3-vertex one and a long random walk (odd lengths and counts)."""
    walk = np.random.default_rng(0).normal(size=(40, 3))
    return Groom.from_strands([np.zeros((3, 3)), np.eye(3), walk])


CASES = [
    ("portrait", lambda: samples.portrait(50, 20), WaveParams()),
    ("scalp", lambda: samples.scalp(80, 24, seed=3), WaveParams(1.5, 0.4, -0.9, 2.5, 0.8)),
    ("comb", lambda: samples.comb(30, 7), WaveParams(0.3, 2.0, 3.0, 0.0, 0.2)),
    ("mixed", mixed, WaveParams()),
]


@pytest.mark.parametrize(("name", "make", "params"), CASES, ids=[c[0] for c in CASES])
def test_kernel_matches_numpy_reference(name, make, params):
    g = make()
    b = make_bunches(g, seed=11, amplitude_spread=0.5, phase_spread=1.0)
    times = schedule(params.period, 24, 2).picture_times
    fast = pose_pictures(g, params, times, b)
    ref = pose_pictures(g, params, times, b, use_numba=False)
    assert np.all(np.isfinite(fast))
    np.testing.assert_allclose(fast, ref, rtol=0, atol=1e-11)


def test_real_groom_kernel_matches_reference(grooms_dir):
    from hairtool.io import read_groom

    g = read_groom(grooms_dir / "ponytail_tail.tfx")
    b = make_bunches(g, seed=1)
    t = schedule(0.45).picture_times
    fast = pose_pictures(g, WaveParams(), t, b)
    np.testing.assert_allclose(fast, pose_pictures(g, WaveParams(), t, b, use_numba=False), atol=1e-9)


def test_same_bits_for_any_thread_count():
    g = samples.scalp(300, 16)
    b = make_bunches(g, seed=2)
    t = schedule(0.45).picture_times
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = pose_pictures(g, WaveParams(), t, b)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = pose_pictures(g, WaveParams(), t, b)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(one, many)
