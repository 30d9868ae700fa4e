"""Render hair in the studio: children follow a drag of their guides, drawn at the drag display
percentage while the mouse is held and at full density on release, guides shown or hidden,
saved as render hair + guide prim in USD and as a child definition in the project file."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6 import QtWidgets
from PySide6.QtCore import Qt

from app.ui.colouring import GUIDE_RGB, vertex_colors
from hairtool import io, samples
from hairtool import project as pf
from hairtool.guides.binding import bind_roots
from hairtool.guides.files import split_guides

pytestmark = pytest.mark.gui


def _window(make_window, children=2000, percent=10.0):
    w = make_window(groom=samples.scalp(strands=60, vertices=12, seed=4))
    w.scene.set_binding(bind_roots(w.scene.rest, count=children, seed=2))
    w.scene.set_display_percent(drag=percent, release=100.0)
    w.viewport.frame_all()
    return w


def _drag_start(w):
    v = w.viewport
    tips = v.project(w.scene.result.tips)
    centre = np.array([v.width() / 2.0, v.height() / 2.0])
    return tips[np.argmin(np.linalg.norm(tips - centre, axis=1))]


def test_children_follow_a_drag_at_the_drag_percentage_and_come_back_in_full_on_release(ui, make_window):
    w = _window(make_window, children=2000, percent=10.0)
    s, v = w.scene, w.viewport
    b = s.binding
    s.set_clump_children(False)  # the interpolation alone (clumped children: the tests below)
    ui.grab(v)
    assert v.renderer.topology.strand_count == 2000 + 60  # children, then the guides
    assert "60 guides · 2,000 children" in w.counts_label.text()
    s.set_radius(0.35 * float(np.max(s.rest.bounds[1] - s.rest.bounds[0])))
    before = s.result
    rest_children = b.build(before).points
    left = Qt.MouseButton.LeftButton
    start = _drag_start(w)
    ui.send_mouse(v, "press", start, left, left)
    for f in np.linspace(0.0, 1.0, 6)[1:]:
        ui.send_mouse(v, "move", start + f * np.array([60.0, 40.0]), None, left)
        ui.grab(v)
        assert s.dragging and v.renderer.topology.strand_count == 200 + 60
        sub = s.drawn_binding()
        # what is drawn is the subset's children of the guides' current shapes, then the guides
        np.testing.assert_array_equal(s.drawn_points[: sub.vertex_count], sub.build(s.result).points)
        np.testing.assert_array_equal(s.drawn_points[sub.vertex_count :], s.result.points)
        np.testing.assert_array_equal(v.renderer._main.points, s.drawn_points)
    ui.send_mouse(v, "release", start + np.array([60.0, 40.0]), left)
    ui.grab(v)
    assert not s.dragging and v.renderer.topology.strand_count == 2000 + 60
    full = b.build(s.result).points
    np.testing.assert_array_equal(s.drawn_points[: b.vertex_count], full)
    # the guides moved, and the children that follow them moved with them; the others did not
    moved = np.abs(s.result.points - before.points).reshape(60, 12, 3).max(axis=(1, 2)) > 0
    moved_guides = np.flatnonzero(moved)
    assert 0 < moved_guides.size < 60
    child_moved = np.abs(full - rest_children).reshape(2000, -1).max(axis=1) > 0
    weighs_moved = np.isin(b.guide_ids, moved_guides).any(axis=1)
    assert child_moved.any() and not (child_moved & ~weighs_moved).any()
    # the subset drawn while dragging holds the same children, to the byte
    ids = (np.arange(200) * 2000) // 200
    np.testing.assert_array_equal(
        b.subset(ids).build(s.result).points, full.reshape(2000, -1, 3)[ids].reshape(-1, 3)
    )


def test_display_percentages_are_settable_and_checked(make_window):
    w = _window(make_window, children=1000, percent=25.0)
    s = w.scene
    s.set_dragging(True)
    assert s.drawn_binding().child_count == 250
    s.set_display_percent(drag=2.0)
    assert s.drawn_binding().child_count == 20
    s.set_dragging(False)
    s.set_display_percent(release=50.0)
    assert s.drawn_binding().child_count == 500
    from hairtool.errors import ParameterError

    for bad in (0.0, -1.0, 101.0, float("nan")):
        with pytest.raises(ParameterError, match="display percentage"):
            s.set_display_percent(drag=bad)


def test_guides_are_drawn_in_their_own_colour_and_can_be_hidden(ui, make_window):
    w = _window(make_window, children=500)
    s, v = w.scene, w.viewport
    colours = vertex_colors(s)
    g0 = s.drawn_topology.offsets[500]
    np.testing.assert_allclose(colours[g0:], np.tile(GUIDE_RGB, (s.rest.vertex_count, 1)), atol=1e-6)
    assert np.abs(colours[:g0] - np.asarray(GUIDE_RGB, np.float32)).max() > 0.1
    image = ui.grab(v)
    orange = (image[..., 0] > 200) & (image[..., 1] > 120) & (image[..., 1] < 190) & (image[..., 2] < 80)
    assert orange.sum() > 50
    s.set_show_guides(False)
    image = ui.grab(v)
    assert v.renderer.topology.strand_count == 500
    assert vertex_colors(s) is None  # the plain ramp again
    orange = (image[..., 0] > 200) & (image[..., 1] > 120) & (image[..., 1] < 190) & (image[..., 2] < 80)
    assert orange.sum() < 5


def test_shaded_hair_is_a_colour_mode(ui, make_window):
    w = _window(make_window, children=500)
    s, v = w.scene, w.viewport
    ui.leave(v)
    flat = ui.grab(v)
    s.set_colour_mode("hair")
    shaded = ui.grab(v)
    assert v.renderer.hair_shading
    assert np.abs(shaded.astype(int) - flat).max(axis=2).mean() > 1.0
    s.set_colour_mode("strand")
    ui.grab(v)
    assert not v.renderer.hair_shading


def test_export_writes_render_hair_and_guides_as_two_prims(make_window, tmp_path):
    w = _window(make_window, children=300)
    path = tmp_path / "hair.usda"
    assert w.export_groom(path)
    back = io.read(path)
    purposes = [(c.path, c.purpose) for c in back.metadata.curves]
    assert purposes == [("/Groom/Hair", "default"), ("/Groom/Guides", "guide")]
    hair, guides = split_guides(back)
    s = w.scene
    assert s.clump_children  # grown children are clumped by default, and so written
    np.testing.assert_array_equal(hair.points, s.render_hair().points)
    assert np.abs(hair.points - s.binding.build(s.result).points).max() > 1e-4
    np.testing.assert_array_equal(guides.points, w.scene.result.points)
    assert hair.thickness is not None and hair.thickness[0] > hair.thickness[11]  # tapered widths


def test_a_project_keeps_the_guides_and_the_child_definition(make_window, tmp_path):
    w = _window(make_window, children=400, percent=5.0)
    w.scene.set_show_guides(False)
    path = tmp_path / "p.hairproj"
    assert w.project.save_to(path)
    loaded = pf.load(path)
    assert loaded.children is not None and loaded.children.child_count == 400
    assert "children/roots.npy" in pf.manifest_and_arrays(loaded)[1]
    w2 = _window(make_window, children=10)
    assert w2.project.open_project(path)
    s = w2.scene
    assert s.binding.child_count == 400 and not s.show_guides and s.drag_percent == 5.0
    np.testing.assert_array_equal(s.render_hair().points, w.scene.render_hair().points)


def test_a_saved_file_of_render_hair_and_guides_opens_as_guides_the_hair_follows(make_window, tmp_path):
    w = _window(make_window, children=300)
    path = tmp_path / "hair.usda"
    assert w.export_groom(path)
    hair = w.scene.render_hair().points.copy()
    w2 = make_window(groom=samples.scalp(strands=5, vertices=4, seed=1))
    assert w2.open_path(path)
    s = w2.scene
    assert s.rest.strand_count == 60 and s.binding is not None and s.binding.child_count == 300
    s.set_params(s.params.replace(freeze=False, clump=False))  # the guides as the file has them …
    np.testing.assert_array_equal(s.render_hair().points, hair)  # … give its hair back bit for bit
    again = tmp_path / "again.usda"
    assert w2.export_groom(again)
    np.testing.assert_array_equal(io.read(again).points, io.read(path).points)
    s.set_params(s.params.replace(freeze=True))  # the engine moves the guides: the hair follows
    assert np.abs(s.render_hair().points - hair).max() > 1e-4


def test_clumping_the_children_is_a_switch_applied_on_release_and_saved(make_window, tmp_path, monkeypatch):
    from hairtool.guides.render import ChildClump, RenderHair

    w = _window(make_window, children=1500, percent=100.0)
    s = w.scene
    box = w.findChild(QtWidgets.QGroupBox, "RenderHairBox")
    assert s.clump_children and box.clump_children.isChecked()  # on for grown children
    box.clump_children.setChecked(False)
    plain = s.drawn_points[: s.binding.vertex_count].copy()
    np.testing.assert_array_equal(plain, s.binding.build(s.result).points)
    box.clump_children.setChecked(True)  # the artist's switch
    assert s.clump_children
    p = s.params
    clump = ChildClump(iterations=p.clump_iterations, gap_mode=p.gap_mode, keep_lengths=p.keep_lengths)
    want = RenderHair(s.binding, clump)
    clumped = want.update(s.result).points
    assert np.abs(clumped - plain).max() > 1e-3
    np.testing.assert_array_equal(s.drawn_points[: s.binding.vertex_count], clumped)
    np.testing.assert_array_equal(s.render_hair().points, clumped)  # what a save writes
    s.set_dragging(True)  # a brush drags: the preview is unclumped
    np.testing.assert_array_equal(s.drawn_points[: s.binding.vertex_count], plain)
    s.set_dragging(False)
    np.testing.assert_array_equal(s.drawn_points[: s.binding.vertex_count], clumped)
    box.clump_children.setChecked(False)  # switched off: the children as they were
    np.testing.assert_array_equal(s.drawn_points[: s.binding.vertex_count], plain)
    box.clump_children.setChecked(True)
    path = tmp_path / "p.hairproj"
    assert w.project.save_to(path)
    w2 = _window(make_window, children=10)
    assert w2.project.open_project(path) and w2.scene.clump_children
    box.clump_children.setChecked(False)  # saved off: opened off, and never clumped on the way
    assert w.project.save_to(path)
    from hairtool.guides.child_clumps import ChildClumps

    runs = []
    run = ChildClumps.run
    monkeypatch.setattr(ChildClumps, "run", lambda self, *a, **k: runs.append(1) or run(self, *a, **k))
    assert w2.project.open_project(path) and not w2.scene.clump_children
    assert runs == []


def test_a_release_clumps_the_render_hair_once_from_the_settled_guides(ui, make_window, monkeypatch):
    """The release settles the groom (its brush-local moves, already the whole groom's clump
    bytes) before the full-density children are built, so Clump children runs once per
    release, on what is kept."""
    from hairtool.guides.child_clumps import ChildClumps

    w = make_window(groom=samples.scalp(strands=600, vertices=10, seed=4))
    s, v = w.scene, w.viewport
    s.set_binding(bind_roots(s.rest, count=3000, seed=2))
    s.set_display_percent(drag=10.0, release=100.0)
    s.set_clump_children(True)
    v.frame_all()
    lo, hi = s.rest.bounds
    s.set_radius(0.12 * float(np.max(hi - lo)))  # a brush on some strands: brush-local moves
    runs = []
    run = ChildClumps.run
    monkeypatch.setattr(ChildClumps, "run", lambda self, *a, **k: runs.append(1) or run(self, *a, **k))
    start = _drag_start(w)
    left = Qt.MouseButton.LeftButton
    ui.send_mouse(v, "press", start, left, left, None)
    for f in np.linspace(0.0, 1.0, 6)[1:]:
        ui.send_mouse(v, "move", start + f * np.array([30.0, 10.0]), None, left, None)
    s.moves.drain()  # the engine thread's moves landed, still within the drag
    assert s.pipeline.unsettled and not runs  # local moves, drawn unclumped at the drag density
    ui.send_mouse(v, "release", start + np.array([30.0, 10.0]), left, None, None)
    assert w.undo_stack.count() == 1 and not s.dragging and not s.pipeline.unsettled
    assert len(runs) == 1
    np.testing.assert_array_equal(s.drawn_points[: s.binding.vertex_count], s.render_hair().points)


def test_the_bundled_sample_saved_and_opened_again_is_clumped_once(make_window, tmp_path):
    """Sintel's grown children are clumped (on by default), and so saved; the file opened again
    holds authored render hair, which is drawn as written, not clumped a second time."""
    w = make_window(size=(420, 320))
    assert w.open_bundled_sample(), w.errors
    s = w.scene
    box = w.findChild(QtWidgets.QGroupBox, "RenderHairBox")
    assert s.clump_children and box.clump_children.isChecked()
    n = s.binding.vertex_count
    written = s.render_hair().points
    np.testing.assert_array_equal(s.drawn_points[:n], written)  # drawn as saved
    assert np.abs(written - s.binding.build(s.result).points).max() > 1e-3  # and clumped
    path = tmp_path / "sintel.usdc"
    assert w.export_groom(path), w.errors
    w2 = make_window(size=(420, 320))
    assert w2.open_path(path), w2.errors
    s2 = w2.scene
    box2 = w2.findChild(QtWidgets.QGroupBox, "RenderHairBox")
    assert s2.binding.authored and not s2.clump_children and not box2.clump_children.isChecked()
    s2.set_params(s2.params.replace(freeze=False, clump=False))  # the guides as written
    np.testing.assert_array_equal(s2.drawn_points[:n], written)
    np.testing.assert_array_equal(s2.render_hair().points, written)
