"""Groom ▸ Grow render hair…: children grown from the strands on the head mesh (over the region
the artist picks), or guides picked among a dense groom's strands; undoable where the groom
stays, the dialog's choices kept."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from app.ui.render_hair_dialog import (
    DENSE,
    NEAR_GUIDES,
    NEAR_MASKED,
    WHOLE_MESH,
    GrowDialog,
    GrowOptions,
    grow,
)
from hairtool import io, samples
from hairtool.errors import ParameterError
from hairtool.io.obj import read_mesh

pytestmark = pytest.mark.gui

RESOURCES = Path(__file__).resolve().parents[2] / "resources"


@pytest.fixture(scope="module")
def sintel():
    return io.read_groom(RESOURCES / "sintel_hair.tfx"), read_mesh(RESOURCES / "sintel_head.obj")


def test_grow_roots_the_children_where_the_artist_chose(sintel):
    guides, head = sintel
    name = sorted(head.groups)[0]
    for region, allowed in (
        (NEAR_GUIDES, None),
        (WHOLE_MESH, np.arange(len(head.faces))),
        (name, head.groups[name]),
    ):
        same, b = grow(GrowOptions(count=500, region=region, seed=3), guides, head)
        assert same is guides and b.child_count == 500
        if allowed is not None:
            assert np.isin(b.faces, allowed).all()
    with pytest.raises(ParameterError, match="region"):
        grow(GrowOptions(count=10, region="no such set"), guides, head)


def test_children_grow_near_the_guides_the_mask_brush_painted(sintel):
    from hairtool.guides.scatter import default_region

    guides, head = sintel
    painted = guides.roots[:, 0] > np.median(guides.roots[:, 0])  # one side of her head
    _, b = grow(GrowOptions(count=800, region=NEAR_MASKED, seed=2), guides, head, painted)
    near_painted = default_region(head, guides, near=painted)
    assert near_painted.sum() < default_region(head, guides).sum()
    assert np.all(near_painted[b.faces])
    with pytest.raises(ParameterError, match="region"):  # nothing painted
        grow(GrowOptions(count=10, region=NEAR_MASKED), guides, head, np.zeros(guides.strand_count, bool))


def test_the_dialog_offers_the_meshs_face_sets_and_round_trips_its_options(qtbot, sintel):
    guides, head = sintel
    chosen = GrowOptions(count=1234, guides_per_child=3, seed=9, length_variation=0.2, frizz=0.05,
                         region=sorted(head.groups)[-1])  # fmt: skip
    dialog = GrowDialog(None, chosen, guides, head)
    qtbot.addWidget(dialog)
    regions = [dialog.region.itemData(i) for i in range(dialog.region.count())]
    assert regions == [NEAR_GUIDES, WHOLE_MESH, *sorted(head.groups)]
    painted = GrowDialog(None, chosen, guides, head, painted=12)  # guides painted: offered
    qtbot.addWidget(painted)
    assert painted.region.itemData(1) == NEAR_MASKED and "12 masked" in painted.region.itemText(1)
    assert dialog.options() == chosen
    dialog.set_options(GrowOptions(mode=DENSE, guides=40))
    assert dialog.options().mode == DENSE and dialog.options().guides == 40
    assert dialog.guides.isVisibleTo(dialog) and not dialog.count.isVisibleTo(dialog)
    no_mesh = GrowDialog(None, GrowOptions(), guides, None)
    qtbot.addWidget(no_mesh)
    assert not no_mesh.region.isEnabled()


def test_growing_and_removing_render_hair_are_undo_steps(make_window):
    w = make_window(groom=samples.scalp(strands=60, vertices=12, seed=4))
    w.ask_grow_options = lambda options: GrowOptions(count=800, seed=5)
    w.grow_render_hair_dialog()
    assert w.jobs.wait()
    b = w.scene.binding
    assert b is not None and b.child_count == 800 and w.grow_options.count == 800
    assert w.remove_hair_action.isEnabled()
    w.remove_render_hair()
    assert w.scene.binding is None and not w.remove_hair_action.isEnabled()
    w.undo_stack.undo()
    assert w.scene.binding is b
    w.undo_stack.undo()
    assert w.scene.binding is None
    w.undo_stack.redo()
    assert w.scene.binding is b
    w.ask_grow_options = lambda options: None  # Cancel: nothing happens
    assert w.grow_render_hair_dialog() is None and w.scene.binding is b


def test_picking_guides_among_a_dense_groom_keeps_its_strands(make_window):
    dense = samples.scalp(strands=400, vertices=8, seed=2)
    w = make_window(groom=dense)
    w.scene.set_params(w.scene.params.replace(freeze=False, clump=False))
    w.grow_render_hair(GrowOptions(mode=DENSE, guides=30, seed=1))
    assert w.jobs.wait()
    s = w.scene
    assert s.rest.strand_count == 30 and s.binding.child_count == 400
    s.set_params(s.params.replace(freeze=False, clump=False))
    assert not s.clump_children  # an artist's own strands are not clumped by default …
    np.testing.assert_array_equal(s.render_hair().points, dense.points)  # … untouched: itself
    np.testing.assert_array_equal(s.drawn_points[: s.binding.vertex_count], dense.points)
    # one step: Undo gives the dense groom back as it was, Redo the picked guides again
    assert w.undo_stack.undoText() == "Grow render hair (picked guides)" and w.undo_stack.count() == 2
    w.undo_stack.undo()
    assert s.rest is dense and s.binding is None and s.result.strand_count == 400
    w.undo_stack.redo()
    assert s.rest.strand_count == 30 and s.binding.child_count == 400 and not s.clump_children


def test_clump_children_follows_each_render_hairs_kind_and_the_artists_choice_through_undo(make_window):
    w = make_window(groom=samples.scalp(strands=60, vertices=12, seed=4))
    w.ask_grow_options = lambda options: GrowOptions(count=800, seed=5)
    w.grow_render_hair_dialog()
    assert w.jobs.wait()
    s = w.scene
    b = s.binding
    assert s.clump_children  # grown children: clumped
    s.set_clump_children(False)  # the artist's choice …
    w.remove_render_hair()
    w.undo_stack.undo()  # … comes back with the children
    assert s.binding is b and not s.clump_children
    np.testing.assert_array_equal(s.drawn_points[: b.vertex_count], b.build(s.result).points)
    w.undo_stack.redo()
    w.undo_stack.undo()
    assert not s.clump_children
    w.ask_grow_options = lambda options: GrowOptions(count=500, seed=6)
    w.grow_render_hair_dialog()  # new children over them: their own default …
    assert w.jobs.wait() and s.binding is not b and s.clump_children
    w.undo_stack.undo()  # … and the old ones as the artist left them
    assert s.binding is b and not s.clump_children
    w.undo_stack.redo()
    assert s.binding.child_count == 500 and s.clump_children
