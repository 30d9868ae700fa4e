"""A key moved in time (a graph editor's sideways drag): the key curve takes the new knot and the
frames between the neighbouring keys show the residuals retimed with it (seed 003 §5)."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.keys.edit import retime_key, time_warp
from hairtool.simulate.sway import sway_animation

KEYS = np.array([0, 9, 20, 31, 39])


@pytest.fixture(scope="module")
def frames():
    return sway_animation(samples.portrait(30, 10, seed=4), 40, flick_frame=20).frames


def _whole(frames, start, block):
    out = np.array(frames)
    out[start : start + len(block)] = block
    return out


@pytest.mark.parametrize("interp", ["linear", "hermite", "hermite-fit"])
@pytest.mark.parametrize("to", [14, 25])
def test_the_moved_key_holds_its_pose_and_only_the_frames_between_its_neighbours_change(frames, interp, to):
    start, block, keys = retime_key(frames, KEYS, interp, 20, to)
    assert (start, len(block)) == (10, 21) and keys.tolist() == [0, 9, to, 31, 39]
    out = _whole(frames, start, block)
    outside = np.r_[0:10, 31:40]
    assert np.array_equal(out[outside], frames[outside])
    np.testing.assert_allclose(out[to], frames[20], atol=1e-6)  # the key pose, at its new frame
    assert not np.allclose(out[to], frames[to], atol=1e-4)


def test_linear_keys_retime_the_motion_itself(frames):
    """With linear keys the key curve stretched is the old one at the warped frame, so the edit
    is the old motion resampled at w(t) (linear between frames): nothing of it is lost."""
    x = frames.astype(np.float64)
    start, block, keys = retime_key(x, KEYS, "linear", 20, 14)
    t = np.arange(start, start + len(block))
    u = time_warp(t, keys, KEYS)
    i0 = np.floor(u).astype(int)
    s = (u - i0)[:, None, None]
    resampled = x[i0] * (1 - s) + x[np.minimum(i0 + 1, 39)] * s
    np.testing.assert_allclose(block, resampled, atol=1e-9)
    # the stretched side is slower, the squeezed side faster: w runs from 9 to 20 over 9..14
    assert u[14 - start] == 20.0 and np.all(np.diff(u) > 0)


def test_a_key_moved_back_to_its_frame_gives_the_frames_back(frames):
    start, block, _ = retime_key(frames, KEYS, "hermite", 20, 20)
    np.testing.assert_allclose(block, frames[start : start + len(block)], atol=1e-5)


@pytest.mark.parametrize(
    "key, to, words",
    [(0, 3, "inner key"), (39, 35, "inner key"), (20, 9, "between the keys 9 and 31"),
     (20, 31, "between"), (20, 40, "between"), (21, 22, "one of the keys")],
)  # fmt: skip
def test_a_key_does_not_pass_its_neighbours_nor_leave_the_ends(frames, key, to, words):
    with pytest.raises(ParameterError, match=words):
        retime_key(frames, KEYS, "linear", key, to)
