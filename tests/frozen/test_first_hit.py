"""A ray's first hit on the head through its face grid
(:mod:`hairtool.frozen.brushes.first_hit`) equals the numpy twin that tries every face with the
same watertight test: the same nearest ``t`` bit for bit, a face met there, and the same point
from :meth:`~hairtool.guides.surface.MeshSurface.ray_hit`. Rays come from random eyes (outside
the head, inside it, on the cube's exact lattice) toward the head's vertices, points on its
edges, its grid's cell corners, random points of its faces, along the surface (grazing) and
past it (misses), on the ball, the cube, Sintel's head and random soups of triangles.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.frozen.brushes.first_hit import face_ts_reference, first_hit, first_hit_reference
from hairtool.guides.planting import HeadSurface
from hairtool.io.obj import Mesh, read_mesh

from .test_sight import HEAD as BALL
from .test_sight_watertight import CUBE, _corner_grid

DATA = Path(__file__).resolve().parent.parent / "data"
SINTEL = HeadSurface(read_mesh(DATA / "grooms" / "sintel_head.obj"))


def soup(seed: int, count: int) -> HeadSurface:
    """``count`` random triangles in the unit box, some tiny, some long and thin."""
    rng = np.random.default_rng(seed)
    centre = rng.random((count, 1, 3))
    spread = rng.choice([0.01, 0.1, 0.5], size=(count, 1, 1))
    v = (centre + spread * rng.normal(size=(count, 3, 3))).reshape(-1, 3).astype(np.float32)
    return HeadSurface(Mesh(v, np.arange(3 * count, dtype=np.int32).reshape(count, 3), v))


def _same(head: HeadSurface, eye: np.ndarray, d: np.ndarray) -> float:
    """The walk's hit equals the twin's; its t."""
    g = head.face_grid
    t, f = first_hit(g, eye, d)
    t_ref, f_ref = first_hit_reference(g, eye, d)
    assert t == t_ref
    if np.isfinite(t):
        corners = g.vertices[g.faces[[f]]]
        assert face_ts_reference(tuple(corners[:, j] for j in range(3)), eye, d)[0] == t  # met there
    else:
        assert f == f_ref == -1
    hit, hit_ref = head.ray_hit(eye, d), head.ray_hit_reference(eye, d)
    assert (hit is None) == (hit_ref is None) == (not np.isfinite(t))
    if hit is not None:
        np.testing.assert_array_equal(hit, hit_ref)
    return t


def _target(head: HeadSurface, kind: str, pick: int, share: float, rng: np.random.Generator) -> np.ndarray:
    g = head.face_grid
    f = g.faces[pick % len(g.faces)]
    a, b, c = g.vertices[f]
    if kind == "vertex":
        return a
    if kind == "edge":
        return a + share * (b - a)
    if kind == "face":
        u, v = rng.random(2)
        u, v = (1 - u, 1 - v) if u + v > 1 else (u, v)
        return a + u * (b - a) + v * (c - a)
    corners = g.lo + np.argwhere(np.ones(tuple(g.dims + 1), bool)) * g.cell
    near = corners[np.linalg.norm(corners - a, axis=1) < 2 * g.cell]
    return near[pick % len(near)] if len(near) else a


HEADS = {"ball": BALL, "cube": CUBE, "sintel": SINTEL}


@settings(max_examples=120, deadline=None)
@given(head=st.sampled_from(sorted(HEADS)), kind=st.sampled_from(["vertex", "edge", "face", "corner"]),
       pick=st.integers(0, 10**6), share=st.sampled_from([0.0, 0.5, 1.0, 0.25, 1.0 / 3.0]),
       eye=st.sampled_from(["outside", "inside", "grazing", "miss"]), seed=st.integers(0, 2**32 - 1),
       far=st.floats(0.6, 20.0))  # fmt: skip
def test_the_walks_first_hit_is_the_twins(head, kind, pick, share, eye, seed, far):
    """From an eye ``far`` head sizes from the head's centre (or inside it) toward a vertex, an
    edge point, a face point or a cell corner; a grazing ray runs through the target across the
    face; a missing one points away from the head."""
    surface = HEADS[head]
    g = surface.face_grid
    rng = np.random.default_rng(seed)
    target = _target(surface, kind, pick, share, rng)
    lo, hi = g.vertices.min(axis=0), g.vertices.max(axis=0)
    centre, size = 0.5 * (lo + hi), float((hi - lo).max())
    out = rng.normal(size=3)
    out /= np.linalg.norm(out)
    if eye == "inside":
        origin = centre + 0.1 * size * out
    elif eye == "grazing":  # along the face through the target, from outside
        a, b, c = g.vertices[g.faces[pick % len(g.faces)]]
        along = (b - a) if share < 0.5 else (c - b)
        origin = target - far * size * along / np.linalg.norm(along)
    else:
        origin = centre + far * size * out
    d = target - origin if eye != "miss" else origin - centre
    if not d.any():
        d = out
    t = _same(surface, origin, d)
    if eye == "miss":
        assert t == np.inf
    if eye == "inside" and head in ("ball", "cube"):  # a closed head: a ray from inside leaves it
        assert np.isfinite(t)


lattice = st.integers(-10, 10).map(lambda k: k * 0.125)


@settings(max_examples=40, deadline=None)
@given(inside=st.tuples(lattice, lattice, lattice), outside=st.integers(13, 40),
       toward=st.tuples(*[st.sampled_from([-2, -1, 0, 1, 2])] * 3).filter(any))  # fmt: skip
def test_rays_along_the_cubes_lattice_hit_its_edges_and_corners_as_the_twin(inside, outside, toward):
    """The cube's corners, edges and cells are exact in floating point: these rays run exactly
    through its vertices, along its edges and through its cells' corners, from inside and from
    an eye ``outside`` lattice steps away (always outside the cube)."""
    d = np.array(toward, np.float64)
    p = np.array(inside, np.float64)
    assert np.isfinite(_same(CUBE, p, d))
    eye = p + outside * 0.125 * 2 * d
    _same(CUBE, eye, -d)
    _same(CUBE, eye, d)  # away from the cube: a miss
    assert first_hit(CUBE.face_grid, eye, d)[0] == np.inf


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), count=st.integers(1, 60), rays=st.integers(1, 6))
def test_rays_through_a_soup_of_triangles_meet_the_twins_first(seed, count, rays):
    """Random triangles (overlapping, crossing, tiny and long) and random rays through them."""
    surface = soup(seed, count)
    rng = np.random.default_rng(seed + 1)
    for _ in range(rays):
        origin = rng.random(3) * 3.0 - 1.0
        d = rng.random(3) - origin
        _same(surface, origin, d if d.any() else np.ones(3))


@settings(max_examples=30, deadline=None)
@given(corner=st.tuples(*[st.integers(16, 32)] * 3), far=st.integers(1, 4),
       toward=st.tuples(*[st.sampled_from([-1, 0, 1])] * 3).filter(lambda d: min(d) < 0 < max(d)),
       steps=st.integers(1, 8))  # fmt: skip
def test_a_ray_through_a_cell_corner_hits_the_face_only_the_cell_beyond_holds(corner, far, toward, steps):
    """A face with a corner on a cell corner, binned only in the cell beyond it; the ray runs
    exactly through that corner (mixed signs: the walk steps past the corner one axis at a
    time) and meets the face there."""
    c = np.array(corner, np.float64) / 16.0
    head = _corner_grid(c, far / 16.0)
    d = np.array(toward, np.float64)
    assert _same(head, c - steps / 16.0 * d, d) == steps / 16.0


def test_a_ray_without_a_direction_meets_nothing():
    for d in ([0.0, 0.0, 0.0], [np.nan, 0.0, 1.0], [np.inf, 0.0, 0.0]):
        assert first_hit(BALL.face_grid, [0.0, 0.0, 3.0], d) == (np.inf, -1)
        assert BALL.ray_hit([0.0, 0.0, 3.0], d) is None
        assert BALL.ray_hit_reference([0.0, 0.0, 3.0], d) is None


def test_a_ray_down_onto_the_ball_hits_its_top_first():
    """From above, straight down through its pole: the top of the unit ball, not its bottom."""
    hit = BALL.ray_hit([0.0, 5.0, 0.0], [0.0, -2.0, 0.0])
    assert abs(hit[1] - 1.0) < 1e-12 and hit[0] == 0.0 and hit[2] == 0.0
