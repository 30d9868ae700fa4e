"""Front faces only by sight (:mod:`hairtool.frozen.brushes.sight`): on a round head, a mask
dab never paints a strand the head hides from the camera and paints every one in sight under
the brush, whichever way the camera looks; a sample without ``visible`` keeps the root-normal
rule (older logs replay as they did) and a stroke log names the rule only where it is by sight;
the kernels equal their numpy twins."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.frozen.brushes import BrushSample, facing_away, falloff_lut, root_normals
from hairtool.frozen.brushes.sight import (
    hidden_points,
    hidden_points_reference,
    hidden_strands,
    hidden_strands_reference,
)
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.strokes import stroke_from_dict, strokes_from_log
from hairtool.groom import Groom
from hairtool.guides.planting import HeadSurface
from hairtool.io.obj import Mesh

LUT = tuple(falloff_lut("constant").tolist())
RINGS, SIDES = 12, 16


def ball() -> HeadSurface:
    """A unit UV sphere at the origin: every face lies inside the unit sphere, and the sphere
    of radius INNER lies inside every face's plane."""
    theta = np.linspace(0.0, np.pi, RINGS + 1)[1:-1]
    phi = np.linspace(0.0, 2.0 * np.pi, SIDES, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    t, p = t.ravel(), p.ravel()
    v = np.column_stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)])
    v = np.vstack([[0.0, 1.0, 0.0], v, [0.0, -1.0, 0.0]])
    ring = lambda i, j: 1 + i * SIDES + j % SIDES  # noqa: E731
    faces = [(0, ring(0, j + 1), ring(0, j)) for j in range(SIDES)]
    for i in range(RINGS - 2):
        for j in range(SIDES):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            faces += [(a, b, c), (b, d, c)]
    last = len(v) - 1
    faces += [(last, ring(RINGS - 2, j), ring(RINGS - 2, j + 1)) for j in range(SIDES)]
    mesh = Mesh(v.astype(np.float32), np.array(faces, np.int32), v.astype(np.float32))
    return HeadSurface(mesh)


HEAD = ball()
INNER = 0.9  # below the smallest distance from the centre to a face's plane (about 0.95)
MARGIN = 0.02


def hair(seed: int, strands: int = 60) -> Groom:
    """Three-vertex strands rooted just off the ball, pointing out and a little aside."""
    rng = np.random.default_rng(seed)
    root = rng.normal(size=(strands, 3))
    root /= np.linalg.norm(root, axis=1, keepdims=True)
    out = root + 0.3 * rng.normal(size=(strands, 3))
    out /= np.linalg.norm(out, axis=1, keepdims=True)
    out = np.where((out * root).sum(axis=1, keepdims=True) > 0.2, out, root)
    pts = [root * 1.05, root * 1.05 + 0.1 * out, root * 1.05 + 0.2 * out]
    return Groom(np.stack(pts, axis=1).reshape(-1, 3).astype(np.float32), np.full(strands, 3, np.int32))


def truth(points: np.ndarray, view: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per vertex, (clearly in sight, clearly hidden) from the eye along −view: the ray toward
    the eye misses the unit sphere by MARGIN, or passes within INNER of its centre ahead of
    the vertex (a vertex between is left undecided: the mesh is not the sphere)."""
    eye = -view / np.linalg.norm(view)
    p = points.astype(np.float64)
    t = -(p @ eye)  # the ray's nearest approach to the centre
    closest = np.linalg.norm(p + np.maximum(t, 0.0)[:, None] * eye, axis=1)
    return closest > 1.0 + MARGIN, (t > 0) & (closest < INNER)


views = st.tuples(*[st.floats(-1.0, 1.0)] * 3).filter(lambda v: np.linalg.norm(v) > 0.1)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**16), view=views, cursor=st.tuples(*[st.floats(-1.4, 1.4)] * 3),
       radius=st.floats(0.2, 2.5))  # fmt: skip
def test_a_mask_dab_paints_the_strands_in_sight_under_it_and_none_the_head_hides(seed, view, cursor, radius):
    groom = hair(seed)
    dab = BrushSample("mask", cursor, (0.0, 0.0, 0.0), radius, 1.0, LUT, view, visible=True)
    pipe = FrozenPipeline(groom, FrozenParams(freeze=False, clump=False), HEAD)
    pipe.brush(dab)
    v = np.asarray(view, np.float64)
    p = groom.points.astype(np.float64)
    dist = np.linalg.norm(p - np.asarray(cursor), axis=1)
    near = dist < radius
    seen, hid = truth(p, v)
    starts = groom.offsets[:-1]
    any_seen = np.logical_or.reduceat(near & seen, starts)
    unsure = np.logical_or.reduceat(near & ~seen & ~hid, starts)
    edge = np.logical_or.reduceat(np.abs(dist - radius) < 1e-6, starts)
    all_hidden = np.logical_or.reduceat(near, starts) & ~any_seen & ~unsure & ~edge
    assert not pipe.locked[all_hidden].any()  # never through the head
    assert pipe.locked[any_seen & ~edge].all()  # everything in sight under the brush


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**16), view=views, cursor=st.tuples(*[st.floats(-1.4, 1.4)] * 3),
       radius=st.floats(0.05, 2.5), inside=st.floats(0.0, 1.0))  # fmt: skip
def test_the_sight_kernel_equals_its_twin(seed, view, cursor, radius, inside):
    groom = hair(seed, 40)
    rng = np.random.default_rng(seed)
    p = groom.points.astype(np.float64)
    sunk = rng.random(len(p)) < inside  # some vertices inside the head, some on its faces
    p[sunk] *= rng.uniform(0.0, 1.0, size=(int(sunk.sum()), 1))
    on = HEAD.face_grid.vertices[rng.integers(0, len(HEAD.face_grid.vertices), size=5)]
    p[: len(on)] = on
    grid = HEAD.face_grid
    for pts in (p, p.astype(np.float32)):
        got = hidden_strands(pts, groom.offsets, cursor, radius, view, grid)
        want = hidden_strands_reference(pts, groom.offsets, cursor, radius, view, grid)
        np.testing.assert_array_equal(got, want)
        np.testing.assert_array_equal(
            hidden_points(pts, view, grid), hidden_points_reference(pts, view, grid)
        )


def test_a_sample_without_visible_keeps_the_root_normal_rule():
    groom, view = hair(7, 200), (0.0, -0.4, -1.0)
    dab = BrushSample("mask", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 3.0, 1.0, LUT, view)
    old = FrozenPipeline(groom, FrozenParams(freeze=False, clump=False), HEAD)
    old.brush(dab)
    np.testing.assert_array_equal(old.locked, ~facing_away(root_normals(groom), view))
    new = FrozenPipeline(groom, FrozenParams(freeze=False, clump=False), HEAD)
    new.brush(replace(dab, visible=True))
    # on a round head a root facing the camera is in sight; by sight, the silhouette's too
    assert not (old.locked & ~new.locked).any() and new.locked.sum() > old.locked.sum()


def test_a_stroke_log_says_visible_only_where_a_stroke_judges_by_sight():
    dab = BrushSample("mask", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.5, 1.0, LUT, (0.0, 0.0, -1.0))
    old, new = strokes_from_log([dab]), strokes_from_log([replace(dab, visible=True)])
    assert "visible" not in old[0].to_dict()  # a log without it writes as before the field
    assert new[0].to_dict()["visible"] is True
    back = stroke_from_dict(json.loads(json.dumps(new[0].to_dict())))
    assert [s.visible for s in back.pipeline_samples(0.0)] == [True]
    assert [s.visible for s in stroke_from_dict(old[0].to_dict()).pipeline_samples(0.0)] == [False]
