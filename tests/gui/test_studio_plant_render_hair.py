"""Delete, Add and Density on the bundled Sintel sample with her render hair: the brushes remove
and plant guides, the children follow (a removed guide's go, a planted one gets its own), undo
and redo give the render hair back bit for bit, and a still and a project still work."""

from __future__ import annotations

import imageio.v3 as iio
import numpy as np
import pytest

pytestmark = pytest.mark.gui


def front_root(w) -> np.ndarray:
    s, v = w.scene, w.viewport
    facing = s.pipeline.strand_normals @ v.camera.forward()
    return v.project(s.result.roots[int(np.argmin(facing))])[0]


@pytest.mark.slow(seconds=13)
def test_sintel_with_render_hair_takes_delete_add_and_density_and_undo_gives_it_back(
    ui, make_window, tmp_path
):
    w = make_window(size=(640, 480))
    assert w.open_bundled_sample(), w.errors
    s, v = w.scene, w.viewport
    b = s.binding
    guides, children = s.result.strand_count, b.child_count
    per = round(children / guides)
    start_hair = s.render_hair().points.copy()
    states = [(s.result.strand_count, s.children_binding().child_count, start_hair)]

    def stroke(brush, offset=(0.0, 0.0), steps=2):
        w.brush_actions[brush].trigger()
        assert s.stroke_refusal() is None  # render hair no longer refuses them
        pos = front_root(w) + np.asarray(offset)
        ui.drag(v, pos, pos + np.array([6.0, 0.0]), steps=steps)
        assert not w.errors
        hair = s.render_hair().points.copy()
        states.append((s.result.strand_count, s.children_binding().child_count, hair))

    s.set_radius(3.0)
    stroke("delete")
    removed = guides - s.result.strand_count
    assert removed >= 2 and s.children_binding().child_count < children
    gone = np.setdiff1d(np.arange(guides), s.pipeline.origin)
    assert s.children_binding().child_count == children - int(np.isin(b.guide_ids[:, 0], gone).sum())
    assert f"{s.result.strand_count:,} guides · {s.children_binding().child_count:,} children" in (
        w.counts_label.text()
    )
    ui.grab(v)  # the view draws the children that follow, then the guides
    assert v.renderer.topology.strand_count == s.children_binding().child_count + s.result.strand_count

    s.set_radius(1.0)
    s.set_add_count(2)
    stroke("add", offset=(0.0, -12.0))
    planted = int((s.pipeline.origin < 0).sum())
    assert planted >= 2 and s.result.strand_count == guides - removed + planted
    assert states[-1][1] == states[-2][1] + planted * per

    s.set_spacing(1.0)
    stroke("density", offset=(10.0, 8.0))
    assert states[-1][0] != states[-2][0] or states[-1][1] == states[-2][1]

    still = tmp_path / "sintel.png"  # a still of what the view draws
    assert w.export_still(still), w.errors
    assert iio.imread(still).shape[:2] == w.viewport_pixel_size()[::-1]
    path = tmp_path / "edited.hairproj"  # a project gives the same render hair back
    assert w.project.save_to(path)

    for i in range(len(states) - 1, 0, -1):  # undo, stroke by stroke: the hair as it was, to the bit
        w.undo_stack.undo()
        count, kids, hair = states[i - 1]
        assert s.result.strand_count == count and s.children_binding().child_count == kids
        np.testing.assert_array_equal(s.render_hair().points, hair)
    assert s.children_binding() is s.binding
    for i in range(1, len(states)):  # … and redo
        w.undo_stack.redo()
        np.testing.assert_array_equal(s.render_hair().points, states[i][2])

    w2 = make_window(size=(320, 240))
    assert w2.project.open_project(path), w2.errors
    np.testing.assert_array_equal(w2.scene.render_hair().points, states[-1][2])
