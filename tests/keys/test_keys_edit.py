"""Key edits that propagate through stored residuals (seed 003 §5)."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.keys.edit import KeyEditor, edit_animation
from hairtool.simulate.sway import sway_animation


@pytest.fixture(scope="module")
def anim():
    return sway_animation(samples.portrait(30, 10, seed=4), 40, flick_frame=20)


KEYS = np.array([0, 9, 20, 31, 39])


@pytest.mark.parametrize("interp", ["linear", "hermite"])
def test_no_edit_gives_back_the_original_exactly(anim, interp):
    editor = KeyEditor(anim.frames, KEYS, interp)
    np.testing.assert_array_equal(editor.frames(), anim.frames)
    assert np.abs(editor.residual[KEYS]).max() == 0.0


@pytest.mark.parametrize("interp", ["linear", "hermite"])
@pytest.mark.parametrize("edited", [0, 20, 39])
def test_an_edit_changes_only_frames_between_neighbouring_keys(anim, interp, edited):
    editor = KeyEditor(anim.frames, KEYS, interp)
    pose = anim.frames[edited] + np.array([0.0, 0.2, 0.0], dtype=np.float32)
    editor.set_key_pose(edited, pose)
    out = editor.frames()
    np.testing.assert_allclose(out[edited], pose, atol=1e-6)
    lo, hi = editor.affected_frames(edited)
    changed = np.flatnonzero(np.any(out != anim.frames, axis=(1, 2)))
    assert changed.size > 1
    assert changed.min() > lo and changed.max() < hi
    outside = np.ones(anim.n_frames, bool)
    outside[lo + 1 : hi] = False
    np.testing.assert_array_equal(out[outside], anim.frames[outside])


def test_residual_detail_rides_on_the_edit(anim):
    # a uniform shift of one key moves the in-between frames by the interpolation weight
    editor = KeyEditor(anim.frames, KEYS, "linear")
    editor.set_key_pose(20, anim.frames[20] + np.float32(1.0))
    out = editor.frames(np.float64)
    for f, w in ((14, 5 / 11), (25, 6 / 11)):
        np.testing.assert_allclose(out[f] - anim.frames[f], w, atol=1e-5)
    editor.reset()
    np.testing.assert_array_equal(editor.frames(), anim.frames)


def test_edit_animation_and_bad_edits(anim):
    new = edit_animation(anim, KEYS, {9: anim.frames[9] * 1.1})
    assert new.n_frames == anim.n_frames and new.topology == anim.topology
    editor = KeyEditor(anim.frames, KEYS)
    with pytest.raises(ParameterError):
        editor.set_key_pose(10, anim.frames[10])  # not a key
    with pytest.raises(ParameterError):
        editor.set_key_pose(9, anim.frames[9][:5])
