"""The guides' kernels against their numpy twins: frames, nearest guides, farthest-point
sampling, surface distances."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.guides.frames import guide_tables, guide_tables_reference, resampled, root_tangents
from hairtool.guides.nearest import (
    euclidean_nearest,
    euclidean_nearest_reference,
    farthest_point_sampling,
    farthest_point_sampling_reference,
    weights,
)
from hairtool.guides.surface import closest_points, nearest_sources, nearest_sources_reference
from hairtool.io.obj import Mesh


def sphere(rings: int = 10, segments: int = 16, radius: float = 1.0, jitter: float = 0.02) -> Mesh:
    """A UV sphere (poles included), corners jittered so no two paths are of equal length."""
    rng = np.random.default_rng(7)
    th = np.linspace(0, np.pi, rings + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    t, p = np.meshgrid(th, ph, indexing="ij")
    v = np.column_stack(
        [np.sin(t).ravel() * np.cos(p).ravel(), np.cos(t).ravel(), np.sin(t).ravel() * np.sin(p).ravel()]
    )
    v = np.vstack([[0, 1, 0], v, [0, -1, 0]]) * radius
    v = v + rng.normal(scale=jitter, size=v.shape)
    top, bottom = 0, len(v) - 1
    idx = lambda r, s: 1 + r * segments + s % segments  # noqa: E731
    f = [[top, idx(0, s + 1), idx(0, s)] for s in range(segments)]
    for r in range(rings - 2):
        for s in range(segments):
            f += [
                [idx(r, s), idx(r, s + 1), idx(r + 1, s)],
                [idx(r, s + 1), idx(r + 1, s + 1), idx(r + 1, s)],
            ]
    f += [[bottom, idx(rings - 2, s), idx(rings - 2, s + 1)] for s in range(segments)]
    faces = np.array(f, np.int32)
    return Mesh(v.astype(np.float32), faces, np.zeros_like(v, dtype=np.float32))


@pytest.mark.parametrize("n", [9, 5, 14])  # the guides' own count, fewer, more
def test_guide_tables_match_their_twin_and_frames_are_orthonormal(n):
    g = samples.scalp(40, 9, seed=4)
    p = np.array(g.points)
    p[3 * 9 + 4] = p[3 * 9 + 3]  # a zero-length segment
    p[5 * 9 + 5] = p[5 * 9 + 3]  # a hairpin: the segment turns back on itself
    g = g.with_points(p)
    t = root_tangents(resampled(g, n), n)
    got = guide_tables(g, n, t)
    want = guide_tables_reference(g, n, t)
    np.testing.assert_array_equal(got[0], want[0])  # the same resampling and differences
    np.testing.assert_array_equal(got[1], want[1])
    np.testing.assert_allclose(got[2], want[2], atol=1e-12)
    f = got[2].reshape(-1, 3, 3)
    np.testing.assert_allclose(f @ f.transpose(0, 2, 1), np.broadcast_to(np.eye(3), f.shape), atol=1e-9)
    # into given tables at a row offset, as the children's tables for several counts are
    out = (np.zeros((len(p) * 3, 3)), np.zeros(len(p) * 3), np.zeros((len(p) * 3, 9)))
    rows = g.strand_count * n
    guide_tables(g, n, t, out, row0=7)
    for a, b in zip(out, got, strict=True):
        np.testing.assert_array_equal(a[7 : 7 + rows], b)


def test_resampling_keeps_a_guide_of_the_same_count_and_interpolates_others():
    g = samples.scalp(5, 7, seed=1)
    np.testing.assert_array_equal(resampled(g, 7), g.points.astype(np.float64))
    r = resampled(g, 13).reshape(5, 13, 3)
    np.testing.assert_allclose(r[:, ::2], g.points.reshape(5, 7, 3), atol=1e-6)


def test_nearest_guides_and_farthest_points_match_their_twins():
    rng = np.random.default_rng(3)
    guides = rng.normal(size=(50, 3))
    children = rng.normal(size=(300, 3))
    ids, d = euclidean_nearest(guides, children, 4)
    rid, rd = euclidean_nearest_reference(guides, children, 4)
    np.testing.assert_array_equal(ids, rid)
    np.testing.assert_allclose(d, rd, rtol=1e-12)
    _k_ids, w = weights(ids, d, 4)
    np.testing.assert_allclose(w.sum(axis=1), 1.0)
    assert np.all(np.diff(w, axis=1) <= 1e-15)  # nearest first, heaviest first
    roots = rng.normal(size=(400, 3))
    np.testing.assert_array_equal(
        farthest_point_sampling(roots, 60, 5), farthest_point_sampling_reference(roots, 60, 5)
    )
    few_ids, few_d = euclidean_nearest(guides[:3], children, 3)  # k = G: no (k+1)-th guide
    assert np.all(few_ids[:, 3] == -1)
    assert np.all(np.isfinite(weights(few_ids, few_d, 3)[1]))


def test_surface_distances_match_one_dijkstra_per_guide():
    mesh = sphere()
    rng = np.random.default_rng(2)
    pts = rng.normal(size=(12, 3))
    pts /= np.linalg.norm(pts, axis=1, keepdims=True)
    on, faces = closest_points(mesh, pts * 1.05)
    got_g, got_d = nearest_sources(mesh, on, faces, 3)
    ref_g, ref_d = nearest_sources_reference(mesh, on, faces, 3)
    np.testing.assert_array_equal(got_g, ref_g)
    np.testing.assert_allclose(got_d, ref_d, rtol=1e-12)
    # The closest points lie on their faces: inside the triangle's plane.
    v = mesh.vertices.astype(np.float64)[mesh.faces[faces]]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    assert np.abs(np.einsum("ij,ij->i", on - v[:, 0], n)).max() < 1e-9


def test_weights_where_fewer_guides_are_reached():
    ids = np.array([[3, 1, -1, -1], [2, 0, 5, 4]])
    dist = np.array([[0.5, 1.0, np.inf, np.inf], [0.1, 0.2, 0.3, 0.4]])
    got_ids, w = weights(ids, dist, 3)
    np.testing.assert_array_equal(got_ids, [[3, 1, 3], [2, 0, 5]])
    assert w[0, 2] == 0.0 and w[0, 0] > w[0, 1] > 0
    np.testing.assert_allclose(w.sum(axis=1), 1.0)
