"""Delete, pinch, snake hook, slide, add and density through the studio: toolbar, Brush menu
and tool dock entries with keys that clash with no other action; each drag is one undo step;
delete removes the strands under the brush and undo brings them back bit for bit (the view
redraws either way); snake hook drags the tips it hooked; slide, add and density wait for a head
mesh; the brushes keep strands out of the head unless told not to; exported stroke logs replay
in the CLI to the studio's bytes; with render hair a delete takes the children of the guides it
removes with them, and while an animation holds the strands it is refused with a message."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtGui import QAction

from hairtool import samples
from hairtool.frozen.brushes import facing_away

pytestmark = pytest.mark.gui


def plain(make_window, groom=None):
    w = make_window(groom=groom if groom is not None else samples.scalp(strands=200, vertices=12))
    w.scene.set_params(w.scene.params.replace(freeze=False, clump=False))
    w.undo_stack.clear()  # (the window as opened on these parameters: only the strokes are steps)
    return w




def front_strand(w) -> int:
    from hairtool.frozen.brushes import root_normals

    return int(np.argmin(root_normals(w.scene.rest) @ w.viewport.camera.forward()))


def test_the_new_brushes_have_entries_and_keys_that_clash_with_nothing(make_window):
    w = plain(make_window)
    keys = {"delete": "X", "pinch": "Shift+P", "snake_hook": "K", "slide": "G"}
    keys |= {"add": "Shift+A", "density": "D"}
    combo = [w.dock.brush.itemData(i) for i in range(w.dock.brush.count())]
    for name, key in keys.items():
        a = w.brush_actions[name]
        assert a.shortcut().toString() == key and a in w.brush_bar.actions() and name in combo
        a.trigger()
        assert w.scene.brush == name and w.dock.brush.currentData() == name
    w.scene.set_brush("pinch")
    assert w.dock.sign.isVisibleTo(w.dock) and w.dock.sign.currentText() == "Gather"
    seen: dict[str, str] = {}
    for a in w.findChildren(QAction):
        for k in a.shortcuts():
            text = k.toString()
            assert text not in seen or seen[text] == a.text(), f"{text}: {seen.get(text)} and {a.text()}"
            seen[text] = a.text()


def test_delete_removes_the_strands_under_the_brush_and_undo_brings_them_back(ui, make_window):
    """(By the root rule, chosen in the dock; Blender's rule is the next test's.)"""
    w = plain(make_window)
    s, v = w.scene, w.viewport
    rest = s.result
    w.brush_actions["delete"].trigger()
    assert w.dock.delete_rule.isVisibleTo(w.dock) and s.tool.delete_any_segment
    w.dock.delete_rule.setCurrentIndex(w.dock.delete_rule.findData(False))
    assert not s.tool.delete_any_segment
    s.set_radius(0.25)
    s_front = front_strand(w)
    pos = v.project(rest.roots[s_front])[0]
    ui.grab(v)
    ui.drag(v, pos, pos + np.array([10.0, 0.0]), steps=2)
    after = s.result
    assert 0 < after.strand_count < rest.strand_count
    gone = np.setdiff1d(np.arange(rest.strand_count), s.pipeline.origin)
    assert s_front in gone
    under = np.zeros(rest.strand_count, bool)  # roots under some move's brush, facing its camera
    for x in s.pipeline.strokes:
        near = np.linalg.norm(rest.roots - np.array(x.cursor), axis=1) / x.radius < 1.0
        under |= near & ~facing_away(s.pipeline.root_normals, x.view)
    np.testing.assert_array_equal(gone, np.flatnonzero(under))
    np.testing.assert_array_equal(after.points, rest.subset(s.pipeline.origin).points)
    assert f"{after.strand_count:,} strands" in w.counts_label.text()
    assert ui.hair_mask(ui.grab(v)).any()  # drawn with the new strands
    assert w.undo_stack.count() == 1 and w.undo_stack.undoText() == "Delete stroke"
    w.undo_stack.undo()
    assert s.result.topology == rest.topology
    np.testing.assert_array_equal(s.result.points, rest.points)
    assert f"{rest.strand_count:,} strands" in w.counts_label.text()
    ui.grab(v)
    w.undo_stack.redo()
    np.testing.assert_array_equal(s.result.points, after.points)
    s.set_colour_mode("displacement")  # colours over the kept strands
    ui.grab(v)


def test_pinch_and_snake_hook_strokes_replay_in_the_cli_to_the_studios_bytes(ui, make_window, tmp_path):
    from hairtool import io
    from hairtool.cli import main

    rest = samples.scalp(strands=200, vertices=12)
    w = make_window(groom=rest)  # noise, clumps and lengths kept: the studio's own parameters
    s, v = w.scene, w.viewport
    s.set_symmetry(True)
    f = front_strand(w)
    pos = v.project(s.result.tips[f])[0]
    w.brush_actions["snake_hook"].trigger()
    s.set_radius(0.1)
    aligned = s.pipeline.aligned
    ui.drag(v, pos, pos + np.array([30.0, -20.0]), steps=5)
    hooked = s.pipeline.aligned
    assert np.linalg.norm(hooked.tips[f] - aligned.tips[f]) > 0.05  # the hooked tip followed
    np.testing.assert_array_equal(hooked.roots, aligned.roots)
    np.testing.assert_allclose(hooked.strand_lengths, aligned.strand_lengths, rtol=1e-5)
    w.brush_actions["pinch"].trigger()
    ui.drag(v, pos, pos + np.array([5.0, 5.0]), steps=3)
    w.brush_actions["delete"].trigger()
    s.set_radius(0.2)
    at = v.project(s.result.roots[f])[0]
    ui.drag(v, at, at + np.array([3.0, 0.0]), steps=1)
    assert s.result.strand_count < rest.strand_count
    assert w.undo_stack.count() == 3
    assert w.stroke_files.export(tmp_path / "strokes.json")
    io.write(tmp_path / "rest.npz", rest)
    args = ["freeze", str(tmp_path / "rest.npz"), str(tmp_path / "out.npz"), "--keep-lengths"]
    assert main([*args, "--strokes", str(tmp_path / "strokes.json")]) == 0
    np.testing.assert_array_equal(io.read_groom(tmp_path / "out.npz").points, s.result.points)


def test_delete_by_default_removes_the_strands_with_any_segment_under_the_brush(ui, make_window):
    """Blender's rule, the studio's default: a brush over a tip removes its strand though its
    root is not under the brush, and the stroke log says which rule each move used."""
    w = plain(make_window)
    s, v = w.scene, w.viewport
    rest = s.result
    w.brush_actions["delete"].trigger()
    s.set_radius(0.1)
    tip = rest.points[rest.topology.tip_indices[front_strand(w)]]
    pos = v.project(tip)[0]
    ui.grab(v)
    ui.drag(v, pos, pos + np.array([4.0, 0.0]), steps=2)
    assert all(x.any_segment for x in s.pipeline.strokes)
    gone = np.setdiff1d(np.arange(rest.strand_count), s.pipeline.origin)
    rooted = np.zeros(rest.strand_count, bool)  # roots under some move's brush
    for x in s.pipeline.strokes:
        rooted |= np.linalg.norm(rest.roots - np.array(x.cursor), axis=1) / x.radius < 1.0
    assert gone.size and not rooted[gone].all()  # taken by a segment, its root elsewhere
    w.scene.set_brush("comb")
    assert not w.dock.delete_rule.isVisibleTo(w.dock)


def test_delete_takes_the_children_of_its_guides_and_waits_while_an_animation_holds_them(ui, make_window):
    from hairtool.guides.binding import bind_roots

    w = plain(make_window, groom=samples.scalp(strands=60, vertices=12, seed=4))
    s, v = w.scene, w.viewport
    s.set_binding(bind_roots(s.rest, count=300, seed=2))
    messages = ui.record(s.refused)
    w.brush_actions["delete"].trigger()
    pos = v.project(s.result.roots[front_strand(w)])[0]
    ui.drag(v, pos, pos + np.array([5.0, 0.0]), steps=2)
    assert s.result.strand_count < 60 and w.undo_stack.count() == 1 and not messages
    gone = np.setdiff1d(np.arange(60), s.pipeline.origin)
    kept = ~np.isin(s.binding.guide_ids[:, 0], gone)
    assert s.children_binding().child_count == kept.sum() < 300
    w.undo_stack.undo()
    assert s.result.strand_count == 60 and s.children_binding() is s.binding
    s.strand_holders.append(lambda: "the timeline holds an animation of them")
    ui.drag(v, pos, pos + np.array([5.0, 0.0]), steps=2)
    assert s.result.strand_count == 60 and w.undo_stack.count() == 1
    assert messages and "animation" in messages[0][0]
    assert "animation" in w.statusBar().currentMessage()


def test_slide_moves_roots_along_the_head_and_waits_for_a_head_mesh(ui, make_window, tmp_path):
    from hairtool import io
    from hairtool.cli import main
    from hairtool.io.obj import read_mesh

    data = Path(__file__).resolve().parents[1] / "data" / "grooms"
    rest = io.read_groom(data / "sintel_hair.tfx")
    w = plain(make_window, groom=rest)
    s, v = w.scene, w.viewport
    messages = ui.record(s.refused)
    w.brush_actions["slide"].trigger()
    assert w.brush_actions["slide"].shortcut().toString() == "G"
    k = front_strand(w)
    pos = v.project(rest.roots[k])[0]
    ui.drag(v, pos, pos + np.array([25.0, 0.0]), steps=3)
    assert w.undo_stack.count() == 0 and messages and "head mesh" in messages[-1][0]
    s.set_mesh(read_mesh(data / "sintel_head.obj"))
    w.undo_stack.clear()  # (opened on this head)
    s.set_radius(2.0)
    ui.drag(v, pos, pos + np.array([25.0, 0.0]), steps=3)
    out = s.result
    moved = np.flatnonzero(np.any(out.roots != rest.roots, axis=1))
    assert moved.size >= 1 and w.undo_stack.count() == 1 and w.undo_stack.undoText() == "Slide stroke"
    on, _ = s.pipeline.surface.project(out.roots[moved].astype(np.float64))
    np.testing.assert_allclose(out.roots[moved], on, atol=1e-4)
    np.testing.assert_allclose(out.strand_lengths, rest.strand_lengths, rtol=1e-5)
    assert w.stroke_files.export(tmp_path / "strokes.json")
    io.write(tmp_path / "rest.npz", rest)
    args = ["freeze", str(tmp_path / "rest.npz"), str(tmp_path / "out.npz"), "--no-freeze", "--no-clump"]
    args += ["--scalp", str(data / "sintel_head.obj")]
    assert main([*args, "--strokes", str(tmp_path / "strokes.json")]) == 0
    np.testing.assert_array_equal(io.read_groom(tmp_path / "out.npz").points, out.points)
    w.undo_stack.undo()
    np.testing.assert_array_equal(s.result.points, rest.points)


def test_brushes_keep_strands_out_of_the_head_unless_told_not_to(ui, make_window):
    from hairtool import io
    from hairtool.io.obj import read_mesh

    data = Path(__file__).resolve().parents[1] / "data" / "grooms"
    rest = io.read_groom(data / "sintel_hair.tfx")
    w = plain(make_window, groom=rest)
    s, v = w.scene, w.viewport
    s.set_mesh(read_mesh(data / "sintel_head.obj"))
    w.undo_stack.clear()  # (opened on this head)
    w.brush_actions["comb"].trigger()
    assert w.dock.collide.isVisibleTo(w.dock) and w.dock.collide.isChecked()
    s.set_radius(6.0)
    s.set_intensity(1.0)
    k = front_strand(w)
    centre = v.project(s.pipeline.surface.mesh.vertices.mean(axis=0).astype(np.float64))[0]
    pos = v.project(rest.points[rest.offsets[k] + 16])[0]
    ui.drag(v, pos, pos + 0.6 * (centre - pos), steps=4)  # toward the middle of the head
    moved = np.any(s.result.points != rest.points, axis=1) & (rest.topology.index_in_strand > 0)
    assert moved.sum() > 20
    sd, _, _ = s.pipeline.surface.signed_distance(s.result.points[moved].astype(np.float64))
    assert np.all(sd >= 0)
    assert all(x.collide for x in s.pipeline.strokes)
    w.dock.collide.setChecked(False)  # this brush only
    assert not s.tool.collide["comb"] and s.tool.collide["pinch"]
    ui.drag(v, pos, pos + 0.6 * (centre - pos), steps=2)
    assert not s.pipeline.strokes[-1].collide
    s.set_brush("mask")
    assert not w.dock.collide.isVisibleTo(w.dock)  # the mask moves nothing


def test_add_plants_strands_on_the_head_and_undo_takes_them_away(ui, make_window):
    from hairtool import io
    from hairtool.io.obj import read_mesh

    data = Path(__file__).resolve().parents[1] / "data" / "grooms"
    rest = io.read_groom(data / "sintel_hair.tfx")
    w = plain(make_window, groom=rest)
    s, v = w.scene, w.viewport
    w.brush_actions["add"].trigger()
    assert w.brush_actions["add"].shortcut().toString() == "Shift+A"
    assert w.dock.add_count.isVisibleTo(w.dock)
    pos = v.project(rest.roots[front_strand(w)])[0]
    messages = ui.record(s.refused)
    ui.drag(v, pos, pos + np.array([10.0, 0.0]), steps=2)
    assert s.result.strand_count == rest.strand_count and "head" in messages[-1][0]
    s.set_mesh(read_mesh(data / "sintel_head.obj"))
    w.undo_stack.clear()  # (opened on this head)
    w.dock.add_count.setValue(3)
    s.set_radius(1.5)
    eye, ray = v.camera.ray(pos[0], pos[1], v.width(), v.height())
    hit = s.pipeline.surface.ray_hit(eye, ray)  # the head under the mouse
    assert hit is not None and np.allclose(s.pipeline.surface.project(hit[None])[0], hit, atol=1e-6)
    ui.drag(v, pos, pos + np.array([10.0, 0.0]), steps=2)  # press + 2 moves: 3 samples
    assert s.result.strand_count == rest.strand_count + 9
    planted = s.result.roots[rest.strand_count :].astype(np.float64)
    assert np.linalg.norm(planted - hit, axis=1).max() < 1.5 + 1.0  # under the brush, near the mouse
    assert f"{rest.strand_count + 9:,} strands" in w.counts_label.text()
    ui.grab(v)
    assert w.undo_stack.count() == 1 and w.undo_stack.undoText() == "Add stroke"
    w.undo_stack.undo()
    np.testing.assert_array_equal(s.result.points, rest.points)


def test_density_thins_under_the_brush_to_the_spacing_in_one_undo_step(ui, make_window):
    from hairtool import io
    from hairtool.io.obj import read_mesh

    data = Path(__file__).resolve().parents[1] / "data" / "grooms"
    rest = io.read_groom(data / "sintel_hair.tfx")
    w = plain(make_window, groom=rest)
    s, v = w.scene, w.viewport
    s.set_mesh(read_mesh(data / "sintel_head.obj"))
    w.undo_stack.clear()  # (opened on this head)
    w.brush_actions["density"].trigger()
    assert w.dock.spacing.isVisibleTo(w.dock) and not w.dock.add_count.isVisibleTo(w.dock)
    w.dock.spacing.setValue(2.5)  # wider than Sintel's guides are apart: thinning
    s.set_radius(4.0)
    pos = v.project(rest.roots[front_strand(w)])[0]
    ui.drag(v, pos, pos + np.array([5.0, 0.0]), steps=2)
    assert s.result.strand_count < rest.strand_count
    assert all(x.spacing == 2.5 for x in s.pipeline.strokes)
    assert w.undo_stack.count() == 1
    ui.grab(v)
    w.undo_stack.undo()
    np.testing.assert_array_equal(s.result.points, rest.points)


def test_a_project_keeps_the_new_brush_settings(make_window, tmp_path):
    w = plain(make_window, groom=samples.scalp(strands=50, vertices=8))
    s = w.scene
    s.set_add_count(5)
    s.set_spacing(0.07)
    s.set_brush("pinch")
    s.set_collide(False)
    s.set_delete_any_segment(False)
    assert w.project.save_to(tmp_path / "p.hairproj")
    w2 = plain(make_window, groom=samples.scalp(strands=50, vertices=8))
    assert w2.project.open_project(tmp_path / "p.hairproj")
    t = w2.scene.tool
    assert (t.add_count, t.spacing, t.collide["pinch"], t.collide["comb"]) == (5, 0.07, False, True)
    assert not t.delete_any_segment
