"""Front faces only by sight for the box selection and for planting (Add, Density), on the
round head of ``test_sight``: a box that says ``visible`` selects every strand with a point in
the box in sight and none whose points in the box the head hides; an Add or Density sample that
says ``visible`` plants no root the head hides and Add every drawn root in sight, where the
cursor's own surface faces away too; a step or sample without it keeps the normal rule, and a
stroke log names the rule only where it is by sight."""

from __future__ import annotations

import json

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.frozen.brushes import BrushSample, facing_away, root_normals
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.selection import SelectionSample
from hairtool.frozen.strokes import stroke_from_dict, strokes_from_log

from .test_sight import HEAD, LUT, hair, truth, views

PLAIN = FrozenParams(freeze=False, clump=False)
SCALE = 0.5  # the box camera's clip units per groom unit
FACING = 0.3  # a root on the ball this far (cosine) to either side of the silhouette is decided


def _unit(v) -> np.ndarray:
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def camera(view) -> np.ndarray:
    """``(4, 4)`` world-to-clip of an orthographic camera looking along ``view``, the ball in it."""
    f = _unit(view)
    r = _unit(np.cross(f, np.eye(3)[int(np.argmin(np.abs(f)))]))
    u = np.cross(r, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = SCALE * r, SCALE * u, -0.1 * f
    return m


corners = st.tuples(*[st.floats(-1.0, 1.0)] * 4)


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**16), view=views, rect=corners)
def test_a_box_selects_the_strands_in_sight_in_it_and_none_the_head_hides(seed, view, rect):
    groom = hair(seed)
    m = camera(view)
    box = SelectionSample("box", tuple(m.ravel().tolist()), rect, "set", view, visible=True)
    pipe = FrozenPipeline(groom, PLAIN, HEAD)
    pipe.apply_samples([box])
    p = groom.points.astype(np.float64)
    x, y = p @ m[0, :3], p @ m[1, :3]
    (x0, x1), (y0, y1) = sorted(rect[::2]), sorted(rect[1::2])
    inside = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
    edge = np.minimum.reduce([np.abs(x - x0), np.abs(x - x1), np.abs(y - y0), np.abs(y - y1)]) < 1e-6
    seen, hid = truth(p, np.asarray(view))
    starts = groom.offsets[:-1]
    any_seen = np.logical_or.reduceat(inside & seen, starts)
    unsure = np.logical_or.reduceat(inside & ~seen & ~hid, starts) | np.logical_or.reduceat(edge, starts)
    all_hidden = np.logical_or.reduceat(inside, starts) & ~any_seen & ~unsure
    assert not pipe.selected[all_hidden].any()  # never through the head
    assert pipe.selected[any_seen & ~unsure].all()  # everything in sight in the box
    # the same step asked first (the studio's "does it change anything") says the same
    again = FrozenPipeline(groom, PLAIN, HEAD)
    np.testing.assert_array_equal(again.selection_after(box)[0], pipe.selected)


def test_a_box_without_visible_keeps_the_root_normal_rule_and_a_log_names_it_only_where_by_sight():
    groom, view = hair(7, 200), (0.0, -0.4, -1.0)
    m = tuple(camera(view).ravel().tolist())
    old = SelectionSample("box", m, (-1.0, -1.0, 1.0, 1.0), "set", view)
    pipe = FrozenPipeline(groom, PLAIN, HEAD)
    pipe.apply_samples([old])
    np.testing.assert_array_equal(pipe.selected, ~facing_away(root_normals(groom), view))
    new = FrozenPipeline(groom, PLAIN, HEAD)
    new.apply_samples([old._replace(visible=True)])
    # on a round head a root facing the camera is in sight; by sight, the silhouette's too
    assert not (pipe.selected & ~new.selected).any() and new.selected.sum() > pipe.selected.sum()
    written = [s.to_dict() for s in strokes_from_log([old, old._replace(visible=True)])]
    assert "visible" not in written[0] and written[1]["visible"] is True
    back = [stroke_from_dict(json.loads(json.dumps(d))).sample for d in written]
    assert back == [old, old._replace(visible=True)]


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**16), view=views, at=views, radius=st.floats(0.2, 1.5),
       count=st.integers(1, 20))  # fmt: skip
def test_add_plants_every_drawn_root_in_sight_and_none_the_head_hides(seed, view, at, radius, count):
    groom, view = hair(seed, 30), tuple(_unit(view).tolist())
    cursor = tuple((1.05 * _unit(at)).tolist())
    dab = BrushSample(
        "add", cursor, (0.0, 0.0, 0.0), radius, 1.0, LUT, view, count=count, seed=seed, visible=True
    )
    pipe = FrozenPipeline(groom, PLAIN, HEAD)
    pipe.brush(dab)
    planted = pipe.aligned.roots[groom.strand_count :].astype(np.float64)
    drawn = HEAD.plant(groom, cursor, radius, count, seed).roots.astype(np.float64)  # no camera
    eye = -_unit(view)
    assert (_unit(planted) @ eye > -FACING).all()  # never on the far side
    for root in drawn[_unit(drawn) @ eye > FACING]:  # every drawn root in sight
        assert np.abs(planted - root).max(axis=1).min(initial=np.inf) < 1e-5


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2**16), view=views, at=views, radius=st.floats(0.3, 1.0),
       spacing=st.floats(0.1, 0.3))  # fmt: skip
def test_density_plants_in_sight_only_and_leaves_no_gap_there(seed, view, at, radius, spacing):
    groom, view = hair(seed, 30), tuple(_unit(view).tolist())
    cursor = tuple((1.05 * _unit(at)).tolist())
    dab = BrushSample(
        "density", cursor, (0.0, 0.0, 0.0), radius, 1.0, LUT, view, spacing=spacing, seed=seed, visible=True
    )
    pipe = FrozenPipeline(groom, PLAIN, HEAD)
    pipe.brush(dab)
    eye = -_unit(view)
    roots = pipe.aligned.roots.astype(np.float64)
    planted = roots[pipe.origin < 0]
    assert (_unit(planted) @ eye > -FACING).all()  # never on the far side
    # every point of the disc well in sight and well inside it has a root near it
    q, _ = HEAD.project(np.asarray(cursor).reshape(1, 3))
    rng = np.random.default_rng(seed)
    probe, _ = HEAD.project(_unit(rng.normal(size=(400, 3))))
    keep = (np.linalg.norm(probe - q, axis=1) < radius - spacing) & (_unit(probe) @ eye > 2 * FACING)
    for p in probe[keep]:
        assert np.linalg.norm(roots - p, axis=1).min() < 1.5 * spacing
