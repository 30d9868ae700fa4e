"""Playback, the transport shortcuts, recording a drag, and opening animations (USD time
samples, .npz, BVH as a skeleton) in a real window."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtTest import QTest

from app.ui.animation_io import skeleton_animation
from hairtool import io, samples
from hairtool.mocap.bvh import read_bvh
from hairtool.simulate.sway import sway_animation

pytestmark = pytest.mark.gui


@pytest.fixture
def studio(qtbot, make_window):
    w = make_window(groom=samples.comb(strands=10, vertices=6))
    anim = sway_animation(w.scene.result, 30, 24.0, flick_frame=20)
    w.animation.load_animation(anim, "sway")
    w.activateWindow()  # shortcuts go to the active window
    w.viewport.setFocus()
    qtbot.waitActive(w)
    return w, anim


class FakeClock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def test_playback_advances_frames_in_real_time(qtbot, studio):
    w, _ = studio
    m = w.animation
    QTest.keyClick(w.viewport, Qt.Key.Key_Space)
    assert m.playing
    qtbot.waitUntil(lambda: m.frame >= 3, timeout=3000)
    assert w.viewport.shown_frame is not None
    qtbot.waitUntil(lambda: w.animation_ui.measured_fps() > 0, timeout=3000)
    assert "▶" in w.animation_ui.fps_label.text() and "fps (of 24)" in w.animation_ui.fps_label.text()
    QTest.keyClick(w.viewport, Qt.Key.Key_Space)
    assert not m.playing
    stopped = m.frame
    qtbot.wait(120)
    assert m.frame == stopped
    assert f"frame {stopped}/29" in w.animation_ui.fps_label.text()


def test_playback_follows_the_clock_and_drops_frames(studio):
    w, _ = studio
    m = w.animation
    clock = FakeClock()
    m.clock = clock
    m.play()
    clock.t += 0.5  # a slow frame: 12 frames at 24 fps have passed, the frames between are dropped
    m._tick()
    assert m.frame == 12
    clock.t += 1.0  # past the end: loops
    m._tick()
    assert m.frame == (12 + 24) % 30
    m.set_loop(False)
    assert not w.animation_ui.actions["loop"].isChecked()
    m.pause()
    m.play()
    clock.t += 10.0
    m._tick()
    assert m.frame == 29 and not m.playing  # without loop it stops on the last frame


def test_transport_keys_step_jump_to_keys_and_ends(studio):
    w, _ = studio
    m, v = w.animation, w.viewport
    keys = m.dp_keys.tolist()
    QTest.keyClick(v, Qt.Key.Key_Right)
    QTest.keyClick(v, Qt.Key.Key_Right)
    assert m.frame == 2
    QTest.keyClick(v, Qt.Key.Key_Left)
    assert m.frame == 1
    QTest.keyClick(v, Qt.Key.Key_Up)
    assert m.frame == keys[1]
    QTest.keyClick(v, Qt.Key.Key_Up)
    assert m.frame == keys[2]
    QTest.keyClick(v, Qt.Key.Key_Down)
    assert m.frame == keys[1]
    QTest.keyClick(v, Qt.Key.Key_End)
    assert m.frame == 29
    QTest.keyClick(v, Qt.Key.Key_Home)
    assert m.frame == 0
    QTest.keyClick(v, Qt.Key.Key_Left)  # loop is on: wraps to the end
    assert m.frame == 29
    w.timeline.buttons["first"].click()
    assert m.frame == 0


def test_recording_a_drag_makes_an_animation_of_the_expected_length(ui, make_window):
    w = make_window(groom=samples.portrait(strands=30, vertices=12))
    v, scene = w.viewport, w.scene
    clock = FakeClock()
    w.animation_ui.clock = clock
    w.animation.set_fps(24.0)
    before = scene.result.points.copy()
    w.animation_ui.actions["record"].trigger()
    assert w.animation_ui.recording
    start = v.project(scene.result.tips[5:6])[0]
    end = start + np.array([80.0, -30.0])
    left = Qt.MouseButton.LeftButton
    ui.send_mouse(v, "press", start, left, left)
    for f in np.linspace(0.0, 1.0, 9)[1:]:
        clock.t += 0.1
        ui.send_mouse(v, "move", (1 - f) * start + f * end, None, left)
        scene.moves.drain()  # the engine's result lands before the next tick, as it does at 10 Hz
    clock.t += 0.2  # held still for 0.2 s, then released: 1.0 s of recording
    ui.send_mouse(v, "release", end, left, None)
    w.animation_ui.actions["record"].trigger()
    assert not w.animation_ui.recording
    anim = w.animation.animation
    assert anim.n_frames == 25 and anim.fps == 24.0  # floor(1.0 s · 24) + 1
    assert w.animation.source == "recording"
    np.testing.assert_array_equal(anim.frames[0], before)
    np.testing.assert_array_equal(anim.frames[-1], scene.result.points)
    np.testing.assert_array_equal(anim.frames[-1], anim.frames[-5])  # the 0.2 s hold: 5 frames
    assert w.animation.dp_keys is not None  # keys are solved for the recording
    # the drag itself is still one undo step, and the recording, a new animation, the next
    assert w.undo_stack.count() == 2 and w.undo_stack.undoText() == "New animation (recording)"


def test_recording_nothing_says_so(make_window):
    w = make_window(groom=samples.comb(strands=5, vertices=4))
    w.animation_ui.set_recording(True)
    w.animation_ui.set_recording(False)
    assert not w.errors  # a status-bar line, not an error dialog
    assert w.statusBar().currentMessage().startswith("Nothing recorded: hold Record and drag")
    assert w.animation.animation is None


def test_bvh_opens_as_a_skeleton_of_bones(ui, make_window, motion_dir):
    w = make_window()
    path = motion_dir / "freebvh.bvh"
    assert w.open_path(path)
    motion = read_bvh(path)
    anim = w.animation.animation
    bones = motion.n_joints - 1 + len(motion.end_parents)
    assert anim.n_frames == motion.n_frames and anim.fps == pytest.approx(motion.fps)
    assert anim.strand_count == bones and np.all(anim.counts == 2)
    pos = motion.joint_positions(end_sites=True)
    # every joint (and End Site) but the root is the tip of exactly one bone, at its FK position
    tips = anim.frames[:, anim.topology.tip_indices]
    np.testing.assert_allclose(np.sort(tips[5], axis=0), np.sort(pos[5, 1:], axis=0), atol=1e-3)
    np.testing.assert_array_equal(skeleton_animation(motion).frames, anim.frames)
    assert w.scene.result.strand_count == bones and w.animation.dp_keys is not None
    w.animation.set_frame(40)
    ui.grab(w.viewport)
    assert w.viewport.shown_frame == 40
    assert ui.hair_mask(ui.grab(w.viewport)).mean() > 0.001  # the skeleton is on screen


@pytest.mark.parametrize("suffix", [".usda", ".npz"])
def test_animations_open_from_usd_time_samples_and_npz(tmp_path, make_window, suffix):
    w = make_window()
    anim = sway_animation(samples.comb(strands=6, vertices=5), 12, 30.0)
    path = tmp_path / f"sway{suffix}"
    io.write(path, anim)
    assert w.open_path(path)
    got = w.animation.animation
    assert got.n_frames == 12 and got.fps == 30.0 and w.animation.fps == 30.0
    np.testing.assert_allclose(got.frames, anim.frames, atol=1e-6)
    assert w.animation.source == str(path)
    w.new_from_sample("comb")  # a plain groom closes the animation
    assert w.animation.animation is None and w.viewport.frame_points is None


def test_a_broken_bvh_shows_one_error_and_keeps_the_scene(tmp_path, make_window):
    w = make_window()
    bad = tmp_path / "bad.bvh"
    bad.write_text("HIERARCHY\nROOT hips {\n")
    groom = w.scene.result
    assert not w.open_path(bad)
    assert len(w.errors) == 1 and w.errors[0][0] == "Cannot open file" and "bad.bvh" in w.errors[0][1]
    assert w.scene.result is groom and w.animation.animation is None
