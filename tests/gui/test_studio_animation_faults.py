"""The animation-side faults of issue 43, each as the artist met it: pose edits lost to an
interpolation switch, an unsaved animation replaced without a question and its undo steps left
doing nothing (now replacing is one step, and Undo brings the old animation back), the key
mode carried to the next animation, the keys record's count, and the Animation menu offering
work on no animation."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hairtool import samples
from hairtool.anime.settings import AnimeSettings
from hairtool.keys import session as ks
from hairtool.mocap.bvh import read_bvh
from hairtool.mocap.pose_edit import PoseEdit

HAND = "mixamorig:LeftHand"


def test_pose_edits_survive_an_interpolation_switch_and_reach_the_bvh(make_window, motion_dir, tmp_path):
    path = motion_dir / "freebvh.bvh"
    w = make_window(path)
    c, m = w.capture, w.animation
    hermite = ks.solve(m.key_source, m.settings.replace(interp="hermite")).keys_for(
        m.settings.replace(interp="hermite")
    )
    frame = next(int(k) for k in c.editor.keys[1:-1] if k not in hermite)  # a key Hermite drops
    m.set_frame(frame)
    motion = read_bvh(path)
    j = motion.joint_names.index(HAND)
    target = tuple(float(v) for v in motion.joint_positions()[frame, j] + [0.05, 0.02, 0.0])
    assert c.commit(PoseEdit(frame, HAND, target, 2), "pose")
    edited = c.motion().values.copy()
    assert not np.array_equal(edited, motion.values)
    m.set_settings(interp="hermite")
    # the document solves with the edit's frame pinned: a key still, without a pin of the artist's
    assert c.applied == [True] and frame in c.editor.keys and frame not in m.settings.pins
    out = tmp_path / "edited.bvh"
    assert c.export_bvh(out)
    back = read_bvh(out).values
    assert not np.allclose(back, motion.values, atol=1e-4)  # the edit is in the file
    np.testing.assert_allclose(back[frame], c.motion().values[frame], atol=1e-4)
    m.set_key_count(4)  # fewer keys: the pinned frame stays one, the edit stays
    assert c.applied == [True] and frame in c.editor.keys


def _cycle(w, seed=0):
    return w.sources.apply_anime(AnimeSettings(cycles=1, seed=seed))


def test_a_new_cycle_asks_before_it_replaces_unsaved_work_and_undo_brings_the_old_one_back(make_window):
    w = make_window(groom=samples.portrait(strands=8, vertices=6))
    m = w.animation
    assert _cycle(w)
    first = m.animation
    assert w.animation_ui.steer_keys("Pin", pin=3)
    assert w.undo_stack.count() == 2  # the cycle, the pin
    asked = []
    w.ask_save_changes = lambda: asked.append(1) or "cancel"
    assert not _cycle(w, seed=5)
    assert asked == [1] and m.animation is first and w.undo_stack.count() == 2
    w.ask_save_changes = lambda: asked.append(2) or "discard"
    assert _cycle(w, seed=5)
    assert asked == [1, 2] and m.animation is not first
    # replacing is one step: Undo brings the old cycle back with its pin, whose step works
    assert w.undo_stack.count() == 3 and w.project.has_unsaved_changes()
    w.undo_stack.undo()
    assert m.animation is first and 3 in m.settings.pins
    w.undo_stack.undo()
    assert m.animation is first and 3 not in m.settings.pins


def test_close_animation_asks_and_the_menu_needs_an_animation(make_window):
    w = make_window(groom=samples.portrait(strands=8, vertices=6))
    a = w.animation_ui.actions
    assert not a["resolve"].isEnabled() and not a["clear"].isEnabled()
    assert _cycle(w)
    assert a["resolve"].isEnabled() and a["clear"].isEnabled()
    w.ask_save_changes = lambda: "cancel"
    a["clear"].trigger()
    assert w.animation.animation is not None
    w.ask_save_changes = lambda: "discard"
    a["clear"].trigger()
    assert w.animation.animation is None
    assert not a["resolve"].isEnabled() and not a["clear"].isEnabled()


def test_the_keys_record_counts_the_keys_chosen(make_window, tmp_path):
    w = make_window(groom=samples.portrait(strands=8, vertices=6))
    assert _cycle(w)
    m = w.animation
    m.set_settings(mode="tau", tau=0.001)
    out = tmp_path / "keys.json"
    assert w.exporter.export_keys(out)
    record = json.loads(out.read_text())
    assert record["params"]["count"] == len(record["keys"]) == m.dp_keys.size


@pytest.mark.parametrize("how", ["fresh", "project"])
def test_a_capture_opens_at_frame_0(make_window, motion_dir, tmp_path, how):
    w = make_window(motion_dir / "freebvh.bvh")
    if how == "project":
        w.project.save_to(tmp_path / "p.hairproj")
        w.animation.set_frame(40)
        w.ask_save_changes = lambda: "discard"
        assert w.project.open_project(tmp_path / "p.hairproj")
    else:
        w.animation.set_frame(40)
        assert w.open_path(motion_dir / "mocapbank_walk.bvh")
    assert w.animation.frame == 0


def test_the_error_budget_stays_with_its_animation(qapp):
    from app.ui.animation_model import AnimationModel
    from hairtool.simulate.sway import sway_animation

    m = AnimationModel()
    m.load_animation(sway_animation(samples.comb(strands=6, vertices=5), 30, 12.0, flick_frame=20), "a")
    m.set_settings(mode="budget", budget=float(m.key_errors()[0]) * 2)
    m.load_animation(sway_animation(samples.comb(strands=6, vertices=5), 22, 24.0, flick_frame=9), "b")
    d = ks.KeySettings()
    assert (m.settings.mode, m.settings.budget) == (d.mode, d.budget)
    assert m.dp_keys.size < 20
