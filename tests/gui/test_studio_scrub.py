"""Scrubbing the timeline of an animation with render hair: while the frame is dragged the
children are drawn at the drag's display share, built in a worker thread that takes only the
latest frame asked for; on release every child is drawn at once, clumped when the worker has
them. No timings here (``python -m app.bench_timeline --sintel`` measures them)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PySide6.QtCore import Qt

from hairtool import samples
from hairtool.guides.root_motion import following
from hairtool.simulate.sway import sway_animation

pytestmark = pytest.mark.gui

FRAMES = 12
CHILDREN = 300
LEFT = Qt.MouseButton.LeftButton


@pytest.fixture
def hair_window(make_window):
    """20 guides with 300 grown children (Clump children on), and a sway of the guides."""
    from hairtool.guides.binding import bind_roots

    guides = samples.scalp(20, 6, seed=4)
    w = make_window(groom=guides, size=(640, 420))
    w.scene.set_binding(bind_roots(guides, count=CHILDREN, seed=1))
    w.animation.load_animation(sway_animation(guides, FRAMES, flick_frame=7), "sway")
    w.jobs.wait()
    assert w.scene.clump_children and w.scene.drag_percent == 10.0
    return w


def _x(view, frame: int) -> float:
    return view.frame_to_x(frame)


def _settle(qtbot, w) -> None:
    frames = w.animation_ui.frames
    qtbot.waitUntil(lambda: not frames.busy, timeout=60_000)


def _share_points(w, frame: int) -> np.ndarray:
    """The drag share's children of ``frame``, then the guides: what a scrubbed frame draws."""
    anim, s = w.animation.animation, w.scene
    share = s.drawn_binding()
    g = anim.frame(frame)  # the children's roots carried by their guides'
    return np.concatenate([following(share, g).build(g).points, anim.frames[frame]])


def test_a_scrub_draws_the_share_the_latest_frame_and_every_child_on_release(ui, qtbot, hair_window):
    from hairtool.guides.render import RenderHair

    w = hair_window
    s, v, view, m = w.scene, w.viewport, w.timeline.view, w.animation
    frames = w.animation_ui.frames
    y = view.height() - 4  # the ruler
    full = s.drawn_topology.strand_count
    assert full == CHILDREN + 20
    frames.delay_s = 0.15  # a slow build: the moves below come faster than it
    ui.send_mouse(view, "press", (_x(view, 1), y), LEFT, LEFT)
    built = frames.built
    for f in range(2, 10):
        ui.send_mouse(view, "move", (_x(view, f), y), None, LEFT)
    assert m.frame == 9 and m.scrubbing
    _settle(qtbot, w)
    # coalesced: at most the build under way at the last move and the latest ask ran after it
    assert frames.built - built <= 3, frames.built - built
    assert v.drawn().strand_count == CHILDREN // 10 + 20  # the drag's share, then the guides
    ui.grab(v)
    assert v.shown_frame == 9  # the latest frame asked, not a stale one
    np.testing.assert_array_equal(v.drawn().points, _share_points(w, 9))
    ui.send_mouse(view, "release", (_x(view, 9), y), LEFT, None)
    # let go: every child at once, interpolated, while the worker clumps them
    assert frames.busy and s.frames_live
    d = v.drawn()
    assert d.strand_count == full
    b, anim = s.binding, m.animation
    np.testing.assert_array_equal(
        d.points[: b.vertex_count], following(b, anim.frame(9)).build(anim.frame(9)).points
    )
    _settle(qtbot, w)
    assert not s.frames_live
    ui.grab(v)
    assert v.shown_frame == 9 and v.drawn().strand_count == full
    clumped = RenderHair(b, s.children_clump(), follow_roots=True).update(anim.frame(9)).points
    np.testing.assert_array_equal(v.drawn().points[: b.vertex_count], clumped)


def test_a_step_after_a_release_is_not_overwritten_by_the_late_clumped_frame(ui, qtbot, hair_window):
    w = hair_window
    v, view, m = w.viewport, w.timeline.view, w.animation
    w.animation_ui.frames.delay_s = 0.3
    y = view.height() - 4
    ui.send_mouse(view, "press", (_x(view, 4), y), LEFT, LEFT)
    ui.send_mouse(view, "release", (_x(view, 4), y), LEFT, None)
    m.step(1)  # an arrow key while frame 4's children are still being clumped
    _settle(qtbot, w)
    ui.grab(v)
    assert m.frame == 5 and v.shown_frame == 5
    np.testing.assert_array_equal(v.drawn().points[-120:], m.animation.frames[5])


@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(path=st.lists(st.integers(0, FRAMES - 1), min_size=1, max_size=6), delay=st.sampled_from([0.0, 0.05]))
def test_any_drag_ends_on_its_last_frame_at_the_share(ui, qtbot, hair_window, path, delay):
    w = hair_window
    v, view, m = w.viewport, w.timeline.view, w.animation
    w.animation_ui.frames.delay_s = delay
    y = view.height() - 4
    ui.send_mouse(view, "press", (_x(view, path[0]), y), LEFT, LEFT)
    for f in path[1:]:
        ui.send_mouse(view, "move", (_x(view, f), y), None, LEFT)
    _settle(qtbot, w)
    ui.grab(v)
    assert v.shown_frame == m.frame == path[-1]
    np.testing.assert_array_equal(v.drawn().points, _share_points(w, path[-1]))
    ui.send_mouse(view, "release", (_x(view, path[-1]), y), LEFT, None)
    _settle(qtbot, w)
    ui.grab(v)
    assert v.shown_frame == path[-1] and v.drawn().strand_count == CHILDREN + 20


def test_the_kernel_preload_waits_while_the_frame_is_dragged(ui, hair_window):
    w = hair_window
    view = w.timeline.view
    y = view.height() - 4
    assert not w.preload_waits()
    ui.send_mouse(view, "press", (_x(view, 2), y), LEFT, LEFT)
    ui.send_mouse(view, "move", (_x(view, 5), y), None, LEFT)
    assert w.animation.scrubbing and w.preload_waits()
    ui.send_mouse(view, "release", (_x(view, 5), y), LEFT, None)
    assert not w.preload_waits()


def test_a_frame_scrubbed_again_lands_at_once_from_its_last_build(ui, qtbot, hair_window):
    w = hair_window
    v, view, m = w.viewport, w.timeline.view, w.animation
    frames = w.animation_ui.frames
    y = view.height() - 4
    ui.send_mouse(view, "press", (_x(view, 2), y), LEFT, LEFT)
    _settle(qtbot, w)  # frame 2 built, and kept
    frames.delay_s = 0.3
    ui.send_mouse(view, "move", (_x(view, 6), y), None, LEFT)  # a slow build of frame 6 starts
    built, reused = frames.built, frames.reused
    ui.send_mouse(view, "move", (_x(view, 2), y), None, LEFT)  # back to 2: its build, at once
    assert frames.reused == reused + 1
    ui.grab(v)
    assert v.shown_frame == 2
    np.testing.assert_array_equal(v.drawn().points, _share_points(w, 2))
    _settle(qtbot, w)  # frame 6 lands for nobody: the view stays on the frame under the mouse
    ui.grab(v)
    assert v.shown_frame == m.frame == 2 and frames.built == built + 1
    np.testing.assert_array_equal(v.drawn().points, _share_points(w, 2))
    ui.send_mouse(view, "move", (_x(view, 6), y), None, LEFT)  # 6 was kept when it landed
    assert frames.reused == reused + 2 and not frames.busy
    ui.grab(v)
    assert v.shown_frame == 6
    np.testing.assert_array_equal(v.drawn().points, _share_points(w, 6))
    m.set_view_mode("reconstruction")  # other guides for frame 6: built again
    _settle(qtbot, w)
    assert frames.built == built + 2
    ui.send_mouse(view, "release", (_x(view, 6), y), LEFT, None)


def test_the_kept_frames_go_with_their_drawn_children(ui, qtbot, hair_window):
    w = hair_window
    view, frames, s = w.timeline.view, w.animation_ui.frames, w.scene
    y = view.height() - 4
    ui.send_mouse(view, "press", (_x(view, 3), y), LEFT, LEFT)
    _settle(qtbot, w)
    assert list(frames._kept) == [3]
    s.set_display_percent(drag=20.0)  # another share: frame 3's build is no one's now
    ui.send_mouse(view, "move", (_x(view, 5), y), None, LEFT)
    _settle(qtbot, w)
    assert list(frames._kept) == [5] and frames._kept[5].binding is s.drawn_binding()
    ui.send_mouse(view, "release", (_x(view, 5), y), LEFT, None)
