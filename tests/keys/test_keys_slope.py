"""A hair key's handle turned (a graph editor's handle drag on hair): one component changes,
between the neighbouring keys only, and the key tangents read back from the edited frames are
the slope asked for, so the handle stays where it was dropped."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.keys.edit import key_slope_block
from hairtool.keys.reconstruct import key_poses
from hairtool.simulate.sway import sway_animation

KEYS = np.array([0, 9, 20, 31, 39])


@pytest.fixture(scope="module")
def frames():
    return sway_animation(samples.portrait(30, 10, seed=4), 40, flick_frame=20).frames


@pytest.mark.parametrize("interp", ["hermite", "hermite-fit"])
@pytest.mark.parametrize("key", [9, 20, 39])
def test_the_edited_frames_own_tangent_at_the_key_is_the_slope(frames, interp, key):
    index = 7 * 3 + 1  # vertex 7, y
    before = key_poses(frames, KEYS, interp)
    slope = float(before.tangents.reshape(5, -1)[list(KEYS).index(key), index]) + 0.04
    start, block = key_slope_block(frames, KEYS, interp, key, index, slope)
    out = np.array(frames)
    out[start : start + len(block)] = block
    kp = key_poses(out, KEYS, interp)
    a = list(KEYS).index(key)
    arriving = kp.tangents if kp.tangents_in is None else kp.tangents_in
    np.testing.assert_allclose(
        [kp.tangents.reshape(5, -1)[a, index], arriving.reshape(5, -1)[a, index]], slope, atol=1e-6
    )
    changed = np.flatnonzero(np.any(out != frames, axis=0).reshape(-1))
    assert changed.tolist() == [index]  # that vertex's axis alone
    lo = int(KEYS[a - 1]) if a > 0 else key
    hi = int(KEYS[a + 1]) if a < 4 else key
    outside = np.r_[0 : lo + 1, hi : 40]
    assert np.array_equal(out[outside], frames[outside])  # the key poses and beyond: untouched
    assert np.array_equal(out[KEYS], frames[KEYS])


def test_linear_keys_have_no_handles(frames):
    with pytest.raises(ParameterError, match="no handles"):
        key_slope_block(frames, KEYS, "linear", 20, 0, 1.0)
