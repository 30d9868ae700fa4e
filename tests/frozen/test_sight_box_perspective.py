"""Box selection by sight under a perspective camera (:mod:`hairtool.frozen.selection`): a box
that says ``to_eye`` traces each point's ray to the camera's eye, so a wide box close to the
round head of ``test_sight`` selects every strand with a point in the box in sight from the eye
and none whose points there the eye cannot see; a box without it keeps tracing along ``view``
(logs and projects before it replay as they did), and a log or project names it only where a
box says it."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.sight import hidden_points
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.sample_columns import read_columns, write_columns
from hairtool.frozen.selection import SelectionSample, check_selection, in_box, matrix_eye
from hairtool.frozen.strokes import stroke_from_dict, strokes_from_log

from .test_sight import HEAD, INNER, MARGIN, hair, views
from .test_sight_box_plant import camera

PLAIN = FrozenParams(freeze=False, clump=False)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v)


def perspective(view, dist: float, zoom: float = 1.4) -> tuple[np.ndarray, np.ndarray]:
    """``(4, 4)`` world-to-clip of a perspective camera ``dist`` from the ball's centre looking
    at it along ``view`` (``zoom``: 1 / tan of half the field of view), and its eye."""
    f = _unit(view)
    eye = -dist * f
    r = _unit(np.cross(f, np.eye(3)[int(np.argmin(np.abs(f)))]))
    look = np.eye(4)
    look[0, :3], look[1, :3], look[2, :3] = r, np.cross(r, f), -f
    look[:3, 3] = -look[:3, :3] @ eye
    near, far = 0.1, 10.0
    proj = np.zeros((4, 4))
    proj[0, 0] = proj[1, 1] = zoom
    proj[2, 2], proj[2, 3], proj[3, 2] = (far + near) / (near - far), 2 * far * near / (near - far), -1.0
    return proj @ look, eye


def truth_from(points: np.ndarray, eye: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per vertex, (clearly in sight, clearly hidden) from ``eye``: the segment to the eye
    misses the unit sphere by MARGIN, or passes within INNER of its centre."""
    d = eye - points
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    t = -(points * d).sum(axis=1)  # the nearest approach to the centre, along the ray
    closest = np.linalg.norm(points + np.maximum(t, 0.0)[:, None] * d, axis=1)
    return closest > 1.0 + MARGIN, (t > 0) & (closest < INNER)


wide = st.tuples(st.floats(-1.0, -0.3), st.floats(-1.0, -0.3), st.floats(0.3, 1.0), st.floats(0.3, 1.0))


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**16), view=views, dist=st.floats(2.2, 4.0), rect=wide)
def test_a_wide_box_under_perspective_selects_what_the_eye_sees_and_nothing_it_cannot(seed, view, dist, rect):
    groom = hair(seed)
    m, eye = perspective(view, dist)
    box = SelectionSample("box", tuple(m.ravel().tolist()), rect, "set", view, visible=True, to_eye=True)
    pipe = FrozenPipeline(groom, PLAIN, HEAD)
    pipe.apply_samples([box])
    p = groom.points.astype(np.float64)
    clip = np.column_stack([p, np.ones(len(p))]) @ m.T
    x, y = clip[:, 0] / clip[:, 3], clip[:, 1] / clip[:, 3]
    x0, y0, x1, y1 = rect
    inside = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
    edge = np.minimum.reduce([np.abs(x - x0), np.abs(x - x1), np.abs(y - y0), np.abs(y - y1)]) < 1e-6
    seen, hid = truth_from(p, eye)
    starts = groom.offsets[:-1]
    any_seen = np.logical_or.reduceat(inside & seen, starts)
    unsure = np.logical_or.reduceat(inside & ~seen & ~hid, starts) | np.logical_or.reduceat(edge, starts)
    all_hidden = np.logical_or.reduceat(inside, starts) & ~any_seen & ~unsure
    assert not pipe.selected[all_hidden].any()  # never through the head
    assert pipe.selected[any_seen & ~unsure].all()  # everything the eye sees in the box


@settings(max_examples=10, deadline=None)
@given(view=views, dist=st.floats(1.5, 50.0))
def test_the_eye_of_a_perspective_matrix_and_none_for_an_orthographic_one(view, dist):
    m, eye = perspective(view, dist)
    np.testing.assert_allclose(matrix_eye(m.ravel()), eye, rtol=1e-9, atol=1e-9 * dist)
    assert matrix_eye(camera(view).ravel()) is None


def test_to_eye_on_an_orthographic_camera_traces_along_the_view_and_without_it_a_box_keeps_the_view():
    groom, view = hair(3, 200), (0.3, -0.4, -1.0)
    rect = (-0.9, -0.9, 0.9, 0.9)
    ortho = tuple(camera(view).ravel().tolist())
    np.testing.assert_array_equal(
        in_box(groom, ortho, rect, view, HEAD.face_grid, to_eye=True),
        in_box(groom, ortho, rect, view, HEAD.face_grid),
    )
    m, _ = perspective(view, 2.5)
    old = SelectionSample("box", tuple(m.ravel().tolist()), rect, "set", view, visible=True)
    pipe = FrozenPipeline(groom, PLAIN, HEAD)
    pipe.apply_samples([old])
    p = groom.points.astype(np.float64)  # the rule before to_eye: every ray along the view
    clip = np.column_stack([p, np.ones(len(p))]) @ m.T
    x, y = clip[:, 0] / clip[:, 3], clip[:, 1] / clip[:, 3]
    inside = (clip[:, 3] > 1e-12) & (np.abs(x) <= 0.9) & (np.abs(y) <= 0.9)
    inside[np.flatnonzero(inside)[hidden_points(p[inside], view, HEAD.face_grid)]] = False
    np.testing.assert_array_equal(pipe.selected, np.logical_or.reduceat(inside, groom.offsets[:-1]))
    new = FrozenPipeline(groom, PLAIN, HEAD)
    new.apply_samples([old._replace(to_eye=True)])
    assert (new.selected != pipe.selected).any()  # this close, the eye's lines differ


def test_a_log_and_a_project_name_to_eye_only_where_a_box_says_it():
    m, _ = perspective((0.0, 0.0, -1.0), 2.5)
    old = SelectionSample(
        "box", tuple(m.ravel().tolist()), (-1.0, -1.0, 1.0, 1.0), "set", (0.0, 0.0, -1.0), True
    )
    new = old._replace(to_eye=True)
    written = [s.to_dict() for s in strokes_from_log([old, new])]
    assert "to_eye" not in written[0] and written[1]["to_eye"] is True
    assert [stroke_from_dict(json.loads(json.dumps(d))).sample for d in written] == [old, new]
    with pytest.raises(ParameterError, match="to_eye"):
        stroke_from_dict({**written[1], "to_eye": "yes"})
    with pytest.raises(ParameterError, match="to_eye"):
        check_selection(new._replace(to_eye=1))
    for log, stored in (([old], False), ([old, new], True)):
        arrays: dict[str, np.ndarray] = {}
        info = write_columns(log, arrays)
        assert ("strokes/to_eye.npy" in arrays) is stored and ("to_eye" in info) is stored
        back = read_columns(info, lambda name, ndim, kinds, a=arrays: a[name])
        assert back == log
