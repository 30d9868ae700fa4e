"""The studio's animation side runs on the document (issue 43): a new, replaced or closed
animation is one undo step that Undo takes back with the old animation's edits and their steps;
key settings and dope-sheet edits are steps; a key edit survives an interpolation switch into
the BVH export; and a project saved and reopened holds the same animation side, byte for byte."""

from __future__ import annotations

import numpy as np
import pytest

from app.document import project_io
from hairtool import samples
from hairtool.anime.settings import AnimeSettings
from hairtool.keys.session import key_edit_block
from hairtool.mocap.bvh import read_bvh
from hairtool.mocap.pose_edit import PoseEdit

pytestmark = pytest.mark.gui

HAND = "mixamorig:LeftHand"


def _cycle(w, seed=0):
    return w.sources.apply_anime(AnimeSettings(cycles=1, seed=seed))


def _edit_a_key(m):
    """The key-edit brush's step at the second key: every tip lifted a little."""
    key = int(m.dp_keys[1])
    pose = np.array(m.animation.frames[key])
    pose[m.animation.topology.tip_indices] += np.float32(0.01)
    start, block = key_edit_block(m.animation.frames, m.dp_keys, m.dp_poses.interp, key, pose)
    m.edit_frames(start, block, f"Edit key {key}")
    return key


def _side(state):
    """The animation side as a project writes it: frames' bytes, source, settings, edits."""
    anim = state.animation
    frames = None if anim is None else (anim.frames.dtype.str, anim.frames.tobytes())
    return frames, state.source, state.settings, project_io.animation_settings(state)


def test_a_replaced_animation_comes_back_with_its_key_edits_and_their_steps(make_window):
    w = make_window(groom=samples.portrait(strands=8, vertices=6))
    m, stack = w.animation, w.undo_stack
    assert _cycle(w)
    key = _edit_a_key(m)
    assert w.animation_ui.steer_keys("Pin", pin=3)
    edited, keys, settings = m.animation, m.dp_keys.copy(), m.settings
    steps = stack.count()
    assert steps == 3 and stack.undoText() == "Pin"
    assert _cycle(w, seed=5)  # (the question answers Discard)
    assert m.animation is not edited and stack.count() == steps + 1
    assert "Undo history cleared" not in w.statusBar().currentMessage()
    stack.undo()  # the old cycle, with its key edit, its pin and the keys they made
    assert m.animation is edited and m.settings == settings
    np.testing.assert_array_equal(m.dp_keys, keys)
    np.testing.assert_array_equal(w.doc.keys, keys)
    stack.undo()  # the pin's step still works on it
    assert 3 not in m.settings.pins
    stack.undo()  # and the key edit's
    assert stack.undoText().startswith("New animation")
    assert not np.array_equal(m.animation.frames[key], edited.frames[key])
    for _ in range(3):
        stack.redo()
    assert m.animation is not edited and stack.count() == steps + 1


def test_close_animation_is_one_step_that_undo_takes_back(make_window):
    w = make_window(groom=samples.portrait(strands=8, vertices=6))
    m, a = w.animation, w.animation_ui.actions
    assert _cycle(w)
    _edit_a_key(m)
    edited = m.animation
    a["clear"].trigger()
    assert m.animation is None and w.undo_stack.undoText() == "Close animation"
    assert not a["clear"].isEnabled() and w.project.has_unsaved_changes()
    w.undo_stack.undo()
    assert m.animation is edited and a["clear"].isEnabled() and m.dp_keys is not None
    w.undo_stack.redo()
    assert m.animation is None


def test_key_settings_are_steps_and_a_slider_drag_is_one(make_window):
    w = make_window(groom=samples.portrait(strands=8, vertices=6))
    m, stack = w.animation, w.undo_stack
    assert _cycle(w)
    slider = w.timeline.controls.count_slider
    before, steps = m.settings, stack.count()
    for drag in ((4, 5, 6), (5, 4)):  # two drags of the key-count slider: a step each
        slider.setSliderDown(True)
        for k in drag:
            slider.setValue(k)
        slider.setSliderDown(False)
    assert stack.count() == steps + 2 and m.dp_keys.size == 4 and stack.undoText() == "Key count"
    m.set_settings(interp="hermite")
    assert stack.count() == steps + 3
    stack.undo()
    stack.undo()
    assert m.dp_keys.size == 6 and slider.value() == 6
    stack.undo()
    assert m.settings == before and slider.value() == m.dp_keys.size


def test_a_pose_edit_survives_hermite_and_the_bvh_reads_it_back(make_window, motion_dir, tmp_path):
    path = motion_dir / "freebvh.bvh"
    w = make_window(path)
    c, m = w.capture, w.animation
    assert w.undo_stack.count() == 0 and not w.project.has_unsaved_changes()  # a file opened
    frame = int(c.editor.keys[len(c.editor.keys) // 2])
    m.set_frame(frame)
    motion = read_bvh(path)
    j = motion.joint_names.index(HAND)
    target = tuple(float(v) for v in motion.joint_positions()[frame, j] + [0.05, 0.02, 0.0])
    assert c.commit(PoseEdit(frame, HAND, target, 2), "pose")
    m.set_settings(interp="hermite")
    assert c.applied == [True] and frame in m.dp_keys
    np.testing.assert_array_equal(m.dp_keys, w.doc.keys)  # the document's keys, shown
    out = tmp_path / "edited.bvh"
    assert c.export_bvh(out)
    np.testing.assert_allclose(read_bvh(out).values[frame], c.motion().values[frame], atol=1e-4)
    np.testing.assert_allclose(read_bvh(out).values, w.doc.keyed().motion.values, atol=1e-4)
    assert _cycle(w)  # replaced, then back: the capture with its edit
    w.undo_stack.undo()
    assert c.attached and c.edits == [PoseEdit(frame, HAND, target, 2)] and c.applied == [True]
    np.testing.assert_allclose(c.motion().values, read_bvh(out).values, atol=1e-4)


def test_a_saved_project_reopens_to_the_same_animation_side(make_window, motion_dir, tmp_path):
    w = make_window(groom=samples.portrait(strands=8, vertices=6))
    assert _cycle(w)
    _edit_a_key(w.animation)
    assert w.animation_ui.steer_keys("Pin", pin=3)
    path = tmp_path / "p.hairproj"
    assert w.project.save_to(path)
    saved = _side(w.doc.state)
    w2 = make_window()
    assert w2.project.open_project(path)
    assert _side(w2.doc.state) == saved and w2.undo_stack.count() == 0
    np.testing.assert_array_equal(w2.animation.dp_keys, w.animation.dp_keys)


def test_a_project_whose_key_settings_no_keys_meet_opens_its_animation_and_says_so(make_window, tmp_path):
    import dataclasses

    from hairtool import project as pf

    w = make_window(groom=samples.portrait(strands=8, vertices=6))
    assert _cycle(w)
    path = tmp_path / "p.hairproj"
    assert w.project.save_to(path)
    project = pf.load(path)  # an error budget no key set reaches with frame 5 excluded
    bad = project.key_settings | {"mode": "budget", "budget": 1e-12, "excludes": [5]}
    pf.save(path, dataclasses.replace(project, key_settings=bad))
    w2 = make_window()
    assert w2.project.open_project(path)
    m = w2.animation
    assert m.animation.frames.tobytes() == w.animation.animation.frames.tobytes()
    assert m.dp_keys is not None and m.settings.mode == "count"
    assert [t for t, _ in w2.errors] == ["Some project settings were not applied"]
    assert w2.undo_stack.count() == 0 and not w2.project.has_unsaved_changes()
