"""Sight rays never slip between faces (:mod:`hairtool.frozen.brushes.sight`): a ray through a
mesh vertex, across an edge or through a corner of the face grid's cells still meets the closed
head, so a point inside it or behind it is always hidden, from an orthographic camera (rays
against ``view``) or a perspective one (rays to the eye).

The cube's corners, edges and cells are exact in floating point (every coordinate a multiple of
1/16, every face corner on a cell side, every camera direction with components 0, ±1 and ±2), so
the generated rays pass exactly through vertices, along edge lines and through cell corners; on
the ball (irrational corners) they pass within rounding of them. The kernels equal their numpy
twins on all of them.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from hairtool.frozen.brushes.sight import _edge, _edge_numpy, hidden_points, hidden_points_reference
from hairtool.guides.planting import HeadSurface
from hairtool.io.obj import Mesh

from .test_sight import HEAD as BALL

HALF, SPLITS = 1.5, 6  # the cube [-1.5, 1.5]³, each side 6 × 6 squares of 0.5 (grid cell 1/16)


def cube() -> HeadSurface:
    """A closed cube of 6 × 6 squares a side, two triangles each (the diagonal alternating), its
    faces wound outwards."""
    ticks = np.linspace(-HALF, HALF, SPLITS + 1)
    verts: list[tuple[float, float, float]] = []
    faces: list[tuple[int, int, int]] = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            u, w = (axis + 1) % 3, (axis + 2) % 3
            base = len(verts)
            for a in ticks:
                for b in ticks:
                    p = [0.0, 0.0, 0.0]
                    p[axis], p[u], p[w] = sign * HALF, a, b
                    verts.append(tuple(p))
            for i in range(SPLITS):
                for j in range(SPLITS):
                    q = tuple(
                        base + (i + di) * (SPLITS + 1) + j + dj for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1))
                    )
                    tris = [(q[0], q[1], q[2]), (q[0], q[2], q[3])]
                    if (i + j) % 2:
                        tris = [(q[0], q[1], q[3]), (q[1], q[2], q[3])]
                    faces += tris if sign > 0 else [t[::-1] for t in tris]
    v = np.array(verts, np.float32)
    return HeadSurface(Mesh(v, np.array(faces, np.int32), np.sign(v)))


CUBE = cube()
STEP = 0.125  # inside points and eyes on this lattice: every ray through lattice points exactly


def test_the_cube_sits_on_the_cells_sides():
    g = CUBE.face_grid
    assert g.cell == 1.0 / 16.0 and (g.lo == -HALF - g.cell).all()
    off = (g.vertices[g.faces] - g.lo) / g.cell
    np.testing.assert_array_equal(off, np.round(off))


lattice = st.integers(-10, 10).map(lambda k: k * STEP)  # inside, at least 0.25 from every side
inside = st.tuples(lattice, lattice, lattice)
directions = st.tuples(*[st.sampled_from([-2, -1, 0, 1, 2])] * 3).filter(any)


finite = st.floats(-4.0, 4.0, allow_subnormal=False).filter(lambda x: x == 0.0 or abs(x) > 1e-30)


@settings(max_examples=300, deadline=None)
@given(ax=finite, by=finite, bx=finite, nudge=st.sampled_from([0.0, 1.0, -1.0]))
def test_an_edge_function_has_the_exact_sign_and_its_twin_the_same_value(ax, by, bx, nudge):
    """ay is drawn so that ay·bx rounds to ax·by's double (the float difference 0) or its
    neighbours: the sign still equals the exact one (fractions)."""
    ay = (ax * by) / bx if bx else nudge
    ay = float(np.nextafter(ay, np.inf * nudge)) if nudge and bx else ay
    # the exact sign holds where no product underflows (Dekker's split needs normal numbers):
    # coordinates of a head are never within 1e-30 of 0 unless they are 0 (a nudge off 0 is not)
    assume(ay == 0.0 or abs(ay) > 1e-30)
    exact = Fraction(ax) * Fraction(by) - Fraction(ay) * Fraction(bx)
    got = _edge(ax, ay, bx, by)
    assert np.sign(got) == (exact > 0) - (exact < 0)
    assert _edge(bx, by, ax, ay) == -got
    twin = _edge_numpy(*(np.array([x]) for x in (ax, ay, bx, by)))
    assert twin[0] == got


def _both(points, view, grid, eye=None) -> np.ndarray:
    got = hidden_points(points, view, grid, eye)
    np.testing.assert_array_equal(got, hidden_points_reference(points, view, grid, eye))
    return got


@settings(max_examples=40, deadline=None)
@given(points=st.lists(inside, min_size=1, max_size=8), view=directions, back=st.integers(0, 30))
def test_a_point_inside_or_behind_the_cube_is_hidden_however_the_rays_meet_its_corners(points, view, back):
    """A lattice point inside, or moved ``back`` lattice steps away from the camera along the
    view (the ray toward the eye runs back through the inside point), with an orthographic
    camera and with a perspective one whose eye lies on the line, in front of the cube."""
    p = np.array(points, np.float64)
    v = np.array(view, np.float64)
    assert _both(p, view, CUBE.face_grid).all()
    assert _both(p + back * STEP * v, view, CUBE.face_grid).all()
    for q in p:  # the eye ahead of the cube on each point's line
        eye = q - 32 * STEP * v
        assert _both(q[None] + back * STEP * v, None, CUBE.face_grid, eye).all()


@settings(max_examples=25, deadline=None)
@given(p=st.tuples(*[st.integers(-24, 24).map(lambda k: k * STEP)] * 3), view=directions)
def test_a_point_whose_ray_misses_the_cube_is_in_sight(p, view):
    """A lattice point outside the cube whose ray toward the eye misses the closed cube by a
    lattice step or more is in sight (the kernels do not hide everything)."""
    o, d = np.array(p, np.float64), -np.array(view, np.float64)
    t0, t1 = 0.0, np.inf
    for a in range(3):  # the slab test against the cube grown by one lattice step
        if d[a] == 0.0:
            if abs(o[a]) < HALF + STEP:
                continue
            t0, t1 = np.inf, -np.inf
            break
        ta, tb = sorted(((-HALF - STEP - o[a]) / d[a], (HALF + STEP - o[a]) / d[a]))
        t0, t1 = max(t0, ta), min(t1, tb)
    misses = t0 > t1
    got = _both(o[None], view, CUBE.face_grid)
    if misses:
        assert not got.any()


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _targets(kind: str, pick: int, share: float) -> np.ndarray:
    """A point the ray passes: a ball vertex, a point of a face's edge, or a grid cell corner
    near the ball's surface."""
    g = BALL.face_grid
    if kind == "vertex":
        return g.vertices[pick % len(g.vertices)]
    if kind == "edge":
        f = g.faces[pick % len(g.faces)]
        a, b = g.vertices[f[pick % 3]], g.vertices[f[(pick + 1) % 3]]
        return a + share * (b - a)
    return RING[pick % len(RING)]


_grid = BALL.face_grid
_corners = _grid.lo + np.argwhere(np.ones(tuple(_grid.dims + 1), bool)) * _grid.cell
RING = _corners[np.abs(np.linalg.norm(_corners, axis=1) - 1.0) < 0.1]  # cell corners about the surface


@settings(max_examples=40, deadline=None)
@given(kind=st.sampled_from(["vertex", "edge", "corner"]), pick=st.integers(0, 10**6),
       share=st.sampled_from([0.0, 0.5, 1.0, 0.25, 1.0 / 3.0]), start=st.tuples(*[st.floats(-0.5, 0.5)] * 3),
       back=st.floats(0.0, 3.0))  # fmt: skip
def test_a_point_inside_or_behind_the_ball_is_hidden_through_its_vertices_edges_and_cell_corners(
    kind, pick, share, start, back
):
    """The ray from a point well inside the ball (or ``back`` behind it on the same line) toward
    the eye passes through a vertex, an edge or a cell corner of the grid."""
    target = _targets(kind, pick, share)
    inner = np.array(start, np.float64)
    toward = _unit(target - inner)
    p = np.array([inner, inner - back * toward])
    assert _both(p, -toward, BALL.face_grid).all()
    eye = target + 2.0 * toward  # a perspective eye outside, on the line
    assert _both(p, None, BALL.face_grid, eye).all()


def test_the_view_hypothesis_found_hides_the_vertex_behind_the_ball():
    """View (1, −1, 0): the ray from the ball's vertex (√½, 0, √½) toward the eye runs inside the
    ball and leaves it exactly through the vertex (0, √½, √½); it slipped between the faces
    there and called a hidden vertex visible."""
    g = BALL.face_grid
    k = int(np.argmin(np.linalg.norm(g.vertices - np.array([0.5**0.5, 0.0, 0.5**0.5]), axis=1)))
    exit_ = int(np.argmin(np.linalg.norm(g.vertices - np.array([0.0, 0.5**0.5, 0.5**0.5]), axis=1)))
    np.testing.assert_allclose(g.vertices[exit_] - g.vertices[k], [-(0.5**0.5), 0.5**0.5, 0.0], atol=1e-7)
    p = g.vertices[[k]]
    assert _both(p, (1.0, -1.0, 0.0), g).all()
    assert _both(p.astype(np.float32), (1.0, -1.0, 0.0), g).all()


def _corner_grid(corner: np.ndarray, far: np.ndarray) -> HeadSurface:
    """One small face with a corner on a cell corner, wholly on the far side of that corner in
    every axis (so binned only in the cell beyond it), and two faces that set the grid's box to
    [0, 3]³ (cell 1/16) out of the rays' way."""
    frame = [(0, 0, 0), (3, 0, 0), (3, 0, 3), (0, 3, 0), (0, 3, 3), (3, 3, 3)]
    v = np.array(
        [*frame, corner, corner + far * np.array([2, 0, 1]), corner + far * np.array([0, 1, 2])], np.float32
    )
    return HeadSurface(Mesh(v, np.array([(0, 1, 2), (3, 4, 5), (6, 7, 8)], np.int32), v))


@settings(max_examples=30, deadline=None)
@given(corner=st.tuples(*[st.integers(16, 32)] * 3), far=st.integers(1, 4),
       toward=st.tuples(*[st.sampled_from([-1, 0, 1])] * 3).filter(lambda d: min(d) < 0 < max(d)),
       steps=st.integers(1, 8))  # fmt: skip
def test_a_ray_through_a_cell_corner_meets_the_face_only_the_cell_beyond_holds(corner, far, toward, steps):
    """The walk steps one axis at a time through a corner it meets exactly; the cell it leaves
    out there still has its faces tried (a ray toward the eye along ``toward``, mixed signs)."""
    c = np.array(corner, np.float64) / 16.0
    head = _corner_grid(c, far / 16.0)
    d = np.array(toward, np.float64)
    p = (c - steps / 16.0 * d)[None]
    _both(p, -d, head.face_grid)


def test_the_ray_the_walk_once_left_out():
    """(1.5, 0.5, 1) toward the eye along (−1, 1, 0) passes the corner (1, 1, 1) of four cells
    and steps to x first: the face beyond that corner is met there."""
    head = _corner_grid(np.array([1.0, 1.0, 1.0]), 0.25)
    assert _both(np.array([[1.5, 0.5, 1.0]]), (1.0, -1.0, 0.0), head.face_grid).all()


def test_a_point_at_the_eye_is_in_sight():
    """Nothing stands between a point and an eye at the point itself (inside the cube too)."""
    p = np.array([[0.0, 0.0, 0.0], [0.5, 0.25, -0.125]])
    for q in p:
        assert not _both(q[None], None, CUBE.face_grid, q).any()
