"""Brush samples by sight under a perspective camera (a sample's ``eye``): on the round head of
``test_sight``, a wide mask dab seen from an eye close by keeps exactly the strands each
vertex's own ray to the eye says are hidden (the numpy twin), which the view's one direction
gets wrong toward the edge of the view; Add and Density plant around the point where the line
from the eye through the cursor meets the head, never on roots the eye cannot see; a sample
without an eye judges and plants as before; an align sample judges by its eye as a brush sample
does; and a log or a project names the eye only where a sample has one."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.errors import ParameterError
from hairtool.frozen.brushes import BrushSample, check_sample, root_normals
from hairtool.frozen.brushes.align import AlignSample
from hairtool.frozen.brushes.sight import hidden_strands, hidden_strands_reference
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.replay import StrokeSetting
from hairtool.frozen.sample_columns import read_columns, write_columns
from hairtool.frozen.strokes import stroke_from_dict, strokes_from_log

from .test_sight import HEAD, LUT, hair, views
from .test_sight_box_perspective import truth_from

PLAIN = FrozenParams(freeze=False, clump=False)
SAG = 0.05  # beyond the farthest a face of the ball lies inside the unit sphere


def _unit(v) -> np.ndarray:
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v)


def _aside(f: np.ndarray, turn: float) -> np.ndarray:
    """A unit direction ``turn`` radians off ``f`` (toward a fixed side of it)."""
    u = _unit(np.cross(f, np.eye(3)[int(np.argmin(np.abs(f)))]))
    return np.cos(turn) * f + np.sin(turn) * u


def _strands_under(groom, cursor, radius):
    """Per strand: some vertex within ``radius`` of ``cursor``; some vertex on the radius."""
    dist = np.linalg.norm(groom.points.astype(np.float64) - np.asarray(cursor), axis=1)
    starts = groom.offsets[:-1]
    near = np.logical_or.reduceat(dist <= radius, starts)
    return near, np.logical_or.reduceat(np.abs(dist - radius) < 1e-6, starts)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**16), view=views, dist=st.floats(1.6, 3.0), turn=st.floats(0.2, 0.6),
       radius=st.floats(0.3, 1.2))  # fmt: skip
def test_a_wide_dab_near_the_edge_of_a_perspective_view_keeps_what_each_vertex_ray_sees(
    seed, view, dist, turn, radius
):
    """The dab's cursor where a line of sight ``turn`` off the view's axis meets the ball (or
    passes it): the strands the mask paints are exactly those under it with a vertex the twin
    finds in sight along its own ray to the eye, and agree with the sphere's geometry."""
    groom, f = hair(seed), _unit(view)
    eye = -dist * f
    line = _aside(f, turn)
    cursor = eye + (dist - 0.2) * line  # about the ball's depth, toward the edge of the view
    dab = BrushSample("mask", tuple(cursor.tolist()), (0.0, 0.0, 0.0), radius, 1.0, LUT,
                      tuple(f.tolist()), visible=True, eye=tuple(eye.tolist()))  # fmt: skip
    pipe = FrozenPipeline(groom, PLAIN, HEAD)
    pipe.brush(dab)
    near, edge = _strands_under(groom, cursor, radius)
    hid = hidden_strands_reference(groom.points, groom.offsets, cursor, radius, f, HEAD.face_grid, eye)
    np.testing.assert_array_equal(pipe.locked[~edge], (near & ~hid)[~edge])
    kernel = hidden_strands(groom.points, groom.offsets, cursor, radius, f, HEAD.face_grid, eye)
    np.testing.assert_array_equal(kernel, hid)
    p = groom.points.astype(np.float64)
    inside = np.linalg.norm(p - cursor, axis=1) < radius
    seen, blocked = truth_from(p, eye)
    starts = groom.offsets[:-1]
    any_seen = np.logical_or.reduceat(inside & seen, starts)
    unsure = np.logical_or.reduceat(inside & ~seen & ~blocked, starts) | edge
    assert pipe.locked[any_seen & ~edge].all()
    assert not pipe.locked[np.logical_or.reduceat(inside, starts) & ~any_seen & ~unsure].any()


def test_at_the_side_of_the_head_the_eye_hides_what_the_view_would_keep():
    """From an eye 2 units in front of the ball, hair on its side just behind z = 0 is behind
    the ball's rim (a root's ray to the eye passes about 0.9 from the centre), though a ray
    along the view from it misses the ball: the eye's rule and the view's differ there, and the
    eye is right."""
    groom = hair(5, 1000)
    eye, f = np.array([0.0, 0.0, 2.0]), (0.0, 0.0, -1.0)
    cursor, radius = (1.1, 0.0, -0.1), 0.25
    dab = BrushSample("mask", cursor, (0.0, 0.0, 0.0), radius, 1.0, LUT, f, visible=True, eye=(0.0, 0.0, 2.0))
    by_eye, by_view = FrozenPipeline(groom, PLAIN, HEAD), FrozenPipeline(groom, PLAIN, HEAD)
    by_eye.brush(dab)
    by_view.brush(replace(dab, eye=None))  # every log before the eye: the view's direction
    near, _ = _strands_under(groom, cursor, radius)
    seen, blocked = truth_from(groom.points.astype(np.float64), eye)
    hid_from_eye = near & ~np.logical_or.reduceat(seen, groom.offsets[:-1])
    assert (by_view.locked & hid_from_eye).sum() >= 3  # the view keeps hair the eye cannot see
    assert not by_eye.locked[np.logical_and.reduceat(blocked, groom.offsets[:-1])].any()
    assert (by_eye.locked != by_view.locked).any()


def test_an_align_sample_judges_by_its_eye_as_a_brush_sample_does():
    groom, f, eye = hair(5, 1000), (0.0, 0.0, -1.0), (0.0, 0.0, 2.0)
    cursor, radius = (1.1, 0.0, -0.1), 0.25
    setting = StrokeSetting(lambda: root_normals(groom), lambda: np.zeros(3), HEAD, None)
    dab = AlignSample(cursor, radius, 1.0, "paper", f, visible=True, eye=eye)
    want = hidden_strands_reference(groom.points, groom.offsets, cursor, radius, f, HEAD.face_grid, eye)
    np.testing.assert_array_equal(setting.away(dab, groom, lambda: None), want)
    old = hidden_strands_reference(groom.points, groom.offsets, cursor, radius, f, HEAD.face_grid)
    np.testing.assert_array_equal(setting.away(dab._replace(eye=None), groom, lambda: None), old)
    assert (want != old).any()


def _sphere_hit(eye: np.ndarray, through: np.ndarray) -> np.ndarray:
    """Where the line from ``eye`` through ``through`` first meets the unit sphere."""
    d = _unit(through - eye)
    b = float(eye @ d)
    t = -b - np.sqrt(b * b - (float(eye @ eye) - 1.0))
    return eye + t * d


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2**16), view=views, dist=st.floats(2.0, 4.0), turn=st.floats(0.0, 0.6),
       depth=st.floats(0.6, 1.6), brush=st.sampled_from(["add", "density"]))  # fmt: skip
def test_add_and_density_under_perspective_plant_where_the_eye_ray_meets_the_head(
    seed, view, dist, turn, depth, brush
):
    """The cursor anywhere along a line of sight that meets the ball well inside its rim
    (before the ball or past it): every root planted lies within the brush of that line's hit,
    and none where the eye cannot see; without the eye the brush works around the head's point
    nearest the cursor, elsewhere."""
    groom, f = hair(seed, 30), _unit(view)
    eye = -dist * f
    rim = np.arcsin(1.0 / dist)  # the angle off the axis where lines of sight graze the ball
    line = _aside(f, turn * rim)
    hit = _sphere_hit(eye, eye + line)
    cursor = eye + depth * float((hit - eye) @ line) * line
    radius = 0.15
    dab = BrushSample(brush, tuple(cursor.tolist()), (0.0, 0.0, 0.0), radius, 1.0, LUT, tuple(f.tolist()),
                      count=8, seed=seed, spacing=0.05, visible=True, eye=tuple(eye.tolist()))  # fmt: skip
    pipe = FrozenPipeline(groom, PLAIN, HEAD)
    pipe.brush(dab)
    planted = pipe.aligned.roots[pipe.origin < 0].astype(np.float64)
    assert len(planted) > 0
    assert np.linalg.norm(planted - hit, axis=1).max() < radius + SAG
    _, blocked = truth_from(planted, eye)
    assert not blocked.any()
    if np.linalg.norm(_unit(cursor) - hit) > 2.0 * (radius + SAG):  # the cursor's nearest point elsewhere
        old = FrozenPipeline(groom, PLAIN, HEAD)
        old.brush(replace(dab, eye=None))
        roots = old.aligned.roots[old.origin < 0].astype(np.float64)
        assert len(roots) == 0 or np.linalg.norm(roots - hit, axis=1).max() >= radius + SAG


@pytest.mark.parametrize("brush", ["add", "density"])
def test_near_the_rim_seen_from_a_close_eye_no_root_goes_beyond_it(brush):
    """Aimed at the ball's side just inside the rim an eye 2 units away sees (z = 0.55; its
    rim is at z = 0.5, the view's at z = 0), a wide brush plants no root the eye cannot see,
    though the view's one direction would see the roots down to z = 0."""
    groom, eye = hair(3, 30), np.array([0.0, 0.0, 2.0])
    target = np.array([np.sqrt(1.0 - 0.55**2), 0.0, 0.55])
    cursor = tuple((eye + 1.2 * (target - eye)).tolist())
    dab = BrushSample(brush, cursor, (0.0, 0.0, 0.0), 0.5, 1.0, LUT, (0.0, 0.0, -1.0), count=60, seed=4,
                      spacing=0.04, visible=True, eye=tuple(eye.tolist()))  # fmt: skip
    pipe = FrozenPipeline(groom, PLAIN, HEAD)
    pipe.brush(dab)
    planted = pipe.aligned.roots[pipe.origin < 0].astype(np.float64)
    assert len(planted) >= 5
    _, blocked = truth_from(planted, eye)
    assert not blocked.any()


def test_a_log_and_a_project_name_the_eye_only_where_a_sample_has_one():
    old = BrushSample("mask", (1.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.3, 1.0, LUT, (0.0, 0.0, -1.0), visible=True)
    new = replace(old, eye=(0.0, 0.0, 2.0))
    (stroke,) = strokes_from_log([old, new])
    written = stroke.to_dict()
    assert "eye" not in written["samples"][0] and written["samples"][1]["eye"] == [0.0, 0.0, 2.0]
    assert stroke_from_dict(json.loads(json.dumps(written))).pipeline_samples(0.0) == [old, new]
    mirrored = stroke_from_dict({**written, "symmetry": "x", "mirror_x": 0.5}).pipeline_samples(0.0)
    assert mirrored[3].eye == (1.0, 0.0, 2.0) and mirrored[1].eye is None  # the eye mirrored too
    bad = {**written, "samples": [{**written["samples"][1], "eye": [0.0, "a", 2.0]}]}
    with pytest.raises(ParameterError, match="eye"):
        stroke_from_dict(bad)
    with pytest.raises(ParameterError, match="eye"):
        check_sample(replace(new, eye=(0.0, float("nan"), 2.0)))
    for log, stored in (([old], False), ([old, new], True)):
        arrays: dict[str, np.ndarray] = {}
        info = write_columns(log, arrays)
        assert ("strokes/eye.npy" in arrays) is stored and ("eye" in info) is stored
        back = read_columns(info, lambda name, ndim, kinds, a=arrays: a[name])
        assert back == log
