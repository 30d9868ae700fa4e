"""The CPU strand rasterizer against its numpy definition: the same bytes, whatever the threads."""

from __future__ import annotations

import itertools

import numba
import numpy as np
import pytest

from app.render import soft_raster
from app.render.camera import Camera
from app.render.ramps import ramp_texture, sample_linear
from app.render.soft_raster import StrandRaster, rasterize, rasterize_reference
from hairtool.errors import ParameterError
from hairtool.groom import Groom
from hairtool.kernel_arrays import readonly

SIZE = (61, 47)


def _perspective(size=SIZE) -> np.ndarray:
    cam = Camera(distance=3.0, yaw=0.3, pitch=-0.2)
    cam.set_scene((-1, -1, -1), (1, 1, 1))
    return cam.view_matrix() @ cam.projection_matrix(size[0] / size[1])


def _ortho(size=SIZE) -> np.ndarray:
    cam = Camera(ortho=True, ortho_height=2.5)
    cam.set_scene((-1, -1, -1), (1, 1, 1))
    return cam.view_matrix() @ cam.projection_matrix(size[0] / size[1])


def _awkward_segments(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random strands plus the cases that need care: cut by the near plane, wholly behind the eye,
    zero length, far off the image, across its border, and exactly horizontal or vertical."""
    rng = np.random.default_rng(seed)
    strands = [rng.normal(scale=0.8, size=(rng.integers(2, 7), 3)) for _ in range(40)]
    eye = np.array([3.0 * np.sin(0.3) * np.cos(0.2), 3.0 * np.sin(0.2), 3.0 * np.cos(0.3) * np.cos(0.2)])
    strands += [
        [[0.1, 0.2, 0.0], eye * 1.5],  # through the eye plane
        [eye * 1.2, eye * 1.4 + 0.1],  # wholly behind the eye
        [eye * 0.99, [0.0, 0.0, 0.0]],  # from just in front of the eye
        [[0.2, 0.1, 0.3], [0.2, 0.1, 0.3], [0.5, -0.2, 0.1]],  # zero length, then a segment
        [[40.0, 0.0, 0.0], [45.0, 3.0, 0.0]],  # far off the image
        [[-3.0, 0.1, 0.0], [3.0, -0.2, 0.5]],  # across the image, both ends outside
        [[0.0, -0.5, 0.0], [0.0, 0.5, 0.0]],  # vertical in the orthographic view
        [[-0.5, 0.25, 0.0], [0.5, 0.25, 0.0]],  # horizontal there
        [[0.0, 0.0, -50.0], [0.1, 0.0, 50.0]],  # through the near and far planes
    ]
    g = Groom.from_strands([np.asarray(s, dtype=np.float64) for s in strands])
    colors = rng.random((g.vertex_count, 3)).astype(np.float32)
    colors[:3] = [[-0.5, 2.0, 0.5]]  # out of [0, 1]: clamped
    return g.points, g.topology.segment_end - 1, colors


@pytest.fixture
def threads():
    """``threads(n)`` sets numba's thread count for the test; the old count comes back after."""
    before = numba.get_num_threads()
    yield lambda n: numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    numba.set_num_threads(before)


@pytest.mark.parametrize("width", [1.0, 0.5, 2.0, 3.5, 8.0])
@pytest.mark.parametrize("view", ["perspective", "ortho"])
@pytest.mark.parametrize("n_threads", [1, 2])
def test_kernels_give_the_bytes_of_the_numpy_definition(width, view, n_threads, threads):
    threads(n_threads)
    mvp = _perspective() if view == "perspective" else _ortho()
    for seed in range(3):
        points, starts, colors = _awkward_segments(seed)
        rgba, depth = rasterize(points, starts, colors, mvp, SIZE, width)
        ref_rgba, ref_depth = rasterize_reference(points, starts, colors, mvp, SIZE, width)
        np.testing.assert_array_equal(rgba, ref_rgba)
        np.testing.assert_array_equal(depth, ref_depth)
        drawn = rgba[..., 3] == 255
        assert drawn.mean() > 0.05 and not drawn.all()  # a picture, not an empty or a full one
        assert np.all(depth[~drawn] == 1.0) and np.all(rgba[~drawn] == 0)
        assert np.all((depth[drawn] >= 0.0) & (depth[drawn] <= 1.0))


def test_thread_counts_give_the_same_bytes_on_a_dense_groom(threads):
    from hairtool import samples

    g = samples.scalp(strands=600, vertices=12, seed=4)
    cam = Camera.for_groom(g, aspect=200 / 150)
    mvp = cam.view_matrix() @ cam.projection_matrix(200 / 150)
    colors = np.random.default_rng(0).random((g.vertex_count, 3)).astype(np.float32)
    for width in (1.0, 2.0):
        images = []
        for n in (1, 2):
            threads(n)
            rgba, depth = rasterize(g.points, g.topology.segment_end - 1, colors, mvp, (200, 150), width)
            images.append((rgba.copy(), depth.copy()))
        np.testing.assert_array_equal(images[0][0], images[1][0])
        np.testing.assert_array_equal(images[0][1], images[1][1])
        ref = rasterize_reference(g.points, g.topology.segment_end - 1, colors, mvp, (200, 150), width)
        np.testing.assert_array_equal(images[0][0], ref[0])


def _setup_kernel(points, starts, colors, mvp, w, h, scale, *tables):
    """The set-up kernel on read-only, C-ordered inputs, as the renderer calls it: the kernel
    then loads the studio warm-up's compilation instead of compiling a variant of its own for
    the test's writable arrays (seconds each, on every fresh clone)."""
    inputs = (readonly(a) for a in (points, starts, colors, mvp))
    soft_raster._setup_kernel(*inputs, w, h, readonly(scale), *tables)


def _tables(e: int):
    """Empty set-up outputs for e segments: the segment table (width scale 1), boxes, nearest depths."""
    return np.ones((e, soft_raster._SEG)), np.zeros((4, e), np.int32), np.zeros(e, np.float32)


@pytest.mark.parametrize("width", [1.0, 2.5])
def test_any_split_into_bands_gives_the_same_bytes(width):
    points, starts, colors = _awkward_segments(3)
    mvp = np.ascontiguousarray(_perspective(), np.float64)
    ref_rgba, ref_depth = rasterize_reference(points, starts, colors, mvp, SIZE, width)
    e, h = len(starts), SIZE[1]
    seg, box, nearest = _tables(e)
    _setup_kernel(
        points, starts, colors, mvp, SIZE[0], h, np.zeros(0), seg, box, nearest,
        np.zeros(0, bool), width, np.zeros(0)
    )
    splits = [soft_raster.band_bounds(box[0], box[1], h, n) for n in (1, 4, 13)]
    splits += [np.arange(h + 1), np.array([0, 1, 2, 30, h])]  # one row each; uneven
    for bounds in splits:
        rgba, depth = np.zeros(SIZE[::-1], np.uint32), np.ones(SIZE[::-1], np.float32)
        half = 0.0 if width <= 1.0 else width / 2
        soft_raster.draw_bands(seg, box, nearest, bounds, half, True, np.uint32(0), rgba, depth, 2)
        np.testing.assert_array_equal(rgba.view(np.uint8).reshape(ref_rgba.shape), ref_rgba)
        np.testing.assert_array_equal(depth, ref_depth)


def _dense_thrice(size, width, colour_seed):
    """A dense scalp drawn three times over in random colours (every copy ties with the first in
    depth): its one-copy segment starts, the reference images, and the set-up tables."""
    from hairtool import samples

    g = samples.scalp(strands=400, vertices=12, seed=5)
    cam = Camera.for_groom(g, aspect=size[0] / size[1])
    mvp = np.ascontiguousarray(cam.view_matrix() @ cam.projection_matrix(size[0] / size[1]), np.float64)
    points = np.concatenate([g.points] * 3).astype(np.float32)
    colors = np.random.default_rng(colour_seed).random((len(points), 3)).astype(np.float32)
    one = g.topology.segment_end - 1
    starts = np.concatenate([one + c * g.vertex_count for c in range(3)]).astype(np.int64)
    seg, box, nearest = _tables(len(starts))
    _setup_kernel(
        points, starts, colors, mvp, size[0], size[1], np.zeros(0), seg, box, nearest,
        np.zeros(0, bool), width, np.zeros(0)
    )  # fmt: skip
    return one, rasterize_reference(points, starts, colors, mvp, size, width), (seg, box, nearest)


@pytest.mark.parametrize("width", [1.0, 2.5, 9.0])
def test_hidden_segments_are_skipped_without_changing_a_byte(width):
    # A dense groom drawn twice over in other colours (every copy ties with the first, and the
    # depth test keeps the first), its cells' farthest depths brought up to date after every
    # drawn segment, every 50 and never: the skipped segments change nothing. (Wide quads'
    # boxes span more than 3 × 3 cells, the others' fewer: both ways of reading them.)
    size = (80, 60)
    one, (ref_rgba, ref_depth), (seg, box, nearest) = _dense_thrice(size, width, colour_seed=1)
    (w, h), half = size, (0.0 if width <= 1.0 else width / 2)
    hidden = {}
    for refresh in (1, 50, 10**9):
        for bounds in (np.array([0, h]), soft_raster.band_bounds(box[0], box[1], h, 3)):
            rgba, depth = np.zeros((h, w), np.uint32), np.ones((h, w), np.float32)
            hidden[refresh] = soft_raster.draw_bands(
                seg, box, nearest, bounds, half, True, np.uint32(0), rgba, depth, refresh
            )
            np.testing.assert_array_equal(rgba.view(np.uint8).reshape(ref_rgba.shape), ref_rgba)
            np.testing.assert_array_equal(depth, ref_depth)
    assert hidden[10**9] == 0  # never brought up to date: the cleared depth hides nothing
    assert hidden[1] >= hidden[50] > 0
    if width > 1.0:  # quads cover the scalp: most copies are skipped (1-px lines leave gaps)
        assert hidden[1] > len(one) // 2


@pytest.mark.parametrize("width", [1.0, 9.0])
def test_hidden_segments_are_skipped_in_redrawn_tiles_without_changing_a_byte(width):
    # The same dense groom drawn thrice over, every tile of the image redrawn (tiles of 16 px,
    # the edge ones cut short): each tile keeps its cells' farthest depths as a band does, and
    # the segments it skips as hidden change nothing, whether its depths are brought up to date
    # after every drawn segment, every 7 or never.
    size = (90, 70)
    _, (ref_rgba, ref_depth), (seg, box, nearest) = _dense_thrice(size, width, colour_seed=3)
    e, (w, h), half = len(nearest), size, (0.0 if width <= 1.0 else width / 2)
    dirty = np.ones(((h + 15) // 16, (w + 15) // 16), bool)
    counts, near = np.zeros(dirty.size + 1, np.int64), np.zeros(e, np.int64)
    total = soft_raster._bin_segments(box, dirty, 4, counts, np.zeros(0, np.int64), near)
    entries = np.zeros(total, np.int64)
    soft_raster._bin_segments(box, dirty, 4, counts, entries, near)
    hidden = {}
    for refresh in (1, 7, 10**9):
        for jobs in (1, 3):
            tiles, job_start = soft_raster._balanced_jobs(np.diff(counts) + 1, jobs)
            rgba, depth = np.full((h, w), 5, np.uint32), np.zeros((h, w), np.float32)  # all overwritten
            hidden[refresh] = soft_raster._draw_tiles(
                seg, tiles, job_start, counts, entries, 4, half, np.uint32(0), rgba, depth,
                box, nearest, refresh,
            )  # fmt: skip
            np.testing.assert_array_equal(rgba.view(np.uint8).reshape(ref_rgba.shape), ref_rgba)
            np.testing.assert_array_equal(depth, ref_depth)
    assert hidden[10**9] == 0  # never brought up to date: the cleared depth hides nothing
    assert hidden[1] >= hidden[7] > 0
    if width > 1.0:  # quads cover the scalp: most copies are skipped
        assert hidden[1] > counts[-1] // 3


@pytest.mark.parametrize("width", [2.5, 8.0])
def test_tapered_quads_split_into_bands_give_the_bytes_of_the_numpy_definition(width):
    # Each box is widened by its own quad's reach: narrow tips get narrow boxes, which must
    # still hold every pixel the quad covers, whichever band or cell a pixel falls in.
    points, starts, colors = _awkward_segments(4)
    scale = np.random.default_rng(4).random(len(starts))
    scale[::5] = 0.0  # tips tapered away entirely
    mvp = np.ascontiguousarray(_perspective(), np.float64)
    ref_rgba, ref_depth = rasterize_reference(points, starts, colors, mvp, SIZE, width, scale=scale)
    e, h = len(starts), SIZE[1]
    seg, box, nearest = _tables(e)
    _setup_kernel(
        points, starts, colors, mvp, SIZE[0], h, scale, seg, box, nearest,
        np.zeros(0, bool), width, np.zeros(0)
    )
    for bounds in (np.array([0, h]), np.arange(h + 1), np.array([0, 1, 2, 30, h])):
        rgba, depth = np.zeros(SIZE[::-1], np.uint32), np.ones(SIZE[::-1], np.float32)
        soft_raster.draw_bands(seg, box, nearest, bounds, width / 2, True, np.uint32(0), rgba, depth, 1)
        np.testing.assert_array_equal(rgba.view(np.uint8).reshape(ref_rgba.shape), ref_rgba)
        np.testing.assert_array_equal(depth, ref_depth)


@pytest.mark.parametrize("transpose", [False, True])
def test_a_hidden_test_reads_the_third_row_and_column_of_cells(transpose):
    # A wall of near quads covers the cells of rows 0-27; a far segment behind it reaches down
    # into the open cells of rows 28-31, the third cell row (or, transposed, column) its box
    # touches: its pixels there show, so it must not be skipped on the first two.
    size = (40, 40)
    wall = [((-1.0, r + 0.5, 0.2), (41.0, r + 0.5, 0.2)) for r in range(28)]
    ends = np.array([*wall, ((20.5, 21.7, 0.5), (20.5, 29.5, 0.5))])  # window x, y, depth
    if transpose:
        ends = ends[:, :, [1, 0, 2]]
    ndc = 2.0 * ends / np.array([*size, 1.0]) - 1.0
    points = ndc.reshape(-1, 3).astype(np.float32)
    starts = np.arange(0, len(points), 2, dtype=np.int64)
    colors = np.repeat(np.random.default_rng(2).random((len(starts), 3)), 2, axis=0).astype(np.float32)
    ref_rgba, ref_depth = rasterize_reference(points, starts, colors, np.eye(4), size, 2.0)
    back = np.isclose(ref_depth, 0.5).T if transpose else np.isclose(ref_depth, 0.5)
    assert back[28:].any() and not back[:28].any()
    seg, box, nearest = _tables(len(starts))
    _setup_kernel(
        points, starts, colors, np.eye(4), *size, np.zeros(0), seg, box, nearest,
        np.zeros(0, bool), 2.0, np.zeros(0)
    )
    rgba, depth = np.zeros(size[::-1], np.uint32), np.ones(size[::-1], np.float32)
    soft_raster.draw_bands(seg, box, nearest, np.array([0, size[1]]), 1.0, True, np.uint32(0), rgba, depth, 1)
    np.testing.assert_array_equal(rgba.view(np.uint8).reshape(ref_rgba.shape), ref_rgba)
    np.testing.assert_array_equal(depth, ref_depth)


def test_a_box_holds_the_pixel_at_its_quads_farthest_corner():
    # A 45° quad's corners stick out h√2 from its ends: here the lowest corner lies just below a
    # pixel centre, so that pixel, alone in its one-row band, is drawn only if the box reaches
    # within half a pixel of the corner (h√2 − ½ from the end: the least any box may reach).
    size, h = (40, 30), 2.0
    ax, ay = 12.5, 10.5 + h * np.sqrt(2.0) - 0.01
    ndc = 2.0 * np.array([[ax, ay], [ax + 6.0, ay + 6.0]]) / np.array(size) - 1.0
    points = np.column_stack([ndc, np.zeros(2)]).astype(np.float32)
    colors = np.ones((2, 3), np.float32)
    mvp, starts = np.eye(4), np.array([0], np.int64)
    ref_rgba, _ = rasterize_reference(points, starts, colors, mvp, size, 2.0 * h)
    assert ref_rgba[10, 12, 3] == 255 and not ref_rgba[:10, :, 3].any()  # the corner's pixel, lowest
    seg, box, nearest = _tables(1)
    _setup_kernel(
        points, starts, colors, mvp, *size, np.zeros(0), seg, box, nearest,
        np.zeros(0, bool), 2 * h, np.zeros(0)
    )
    rgba, depth = np.zeros(size[::-1], np.uint32), np.ones(size[::-1], np.float32)
    soft_raster.draw_bands(seg, box, nearest, np.arange(size[1] + 1), h, True, np.uint32(0), rgba, depth, 1)
    np.testing.assert_array_equal(rgba.view(np.uint8).reshape(ref_rgba.shape), ref_rgba)


def test_kernel_bodies_as_plain_python_match_the_compiled_ones():
    # What NUMBA_DISABLE_JIT=1 runs: the kernels' Python bodies (helpers still compiled).
    points, starts, colors = _awkward_segments(7)
    mvp = np.ascontiguousarray(_perspective(), np.float64)
    e, (w, h) = len(starts), SIZE
    out = []
    for python in (False, True):
        setup, bands, tiles, cover = (
            k.py_func if python else k
            for k in (
                soft_raster._setup_kernel,
                soft_raster.draw_bands,
                soft_raster._draw_tiles,
                soft_raster._cover_steps,
            )
        )
        seg, box, nearest = _tables(e)
        weight = np.zeros(e)
        inputs = (readonly(a) for a in (points, starts, colors, mvp))  # read-only, as the renderer's
        setup(*inputs, w, h, readonly(np.zeros(0)), seg, box, nearest, np.zeros(0, bool), 3.0, weight)
        np.testing.assert_array_equal(weight, 1.0 + 3.0 * seg[:, 12])
        bounds = soft_raster.band_bounds(box[0], box[1], h, 3, weight)
        images = [np.zeros((h, w), np.uint32), np.ones((h, w), np.float32)] * 3
        images = [a.copy() for a in images]
        bands(seg, box, nearest, bounds, 0.0, True, np.uint32(7), *images[:2], 3)
        bands(seg, box, nearest, bounds, 1.5, True, np.uint32(7), *images[2:4], 3)
        dirty = np.ones(((h + 15) // 16, (w + 15) // 16), bool)
        counts = np.zeros(dirty.size + 1, np.int64)
        near = np.zeros(e, np.int64)
        total = soft_raster._bin_segments(box, dirty, 4, counts, np.zeros(0, np.int64), near)
        entries = np.zeros(total, np.int64)
        soft_raster._bin_segments(box, dirty, 4, counts, entries, near)
        jobs, job_start = soft_raster._balanced_jobs(np.diff(counts) + 1, 3)
        tiles(seg, jobs, job_start, counts, entries, 4, 1.5, np.uint32(7), *images[4:], box, nearest, 2)
        out.append((seg, box, cover(box[0], box[1], h, np.linspace(1.0, 3.0, e)), *images))
    for compiled, python in zip(*out, strict=True):
        np.testing.assert_array_equal(compiled, python)
    np.testing.assert_array_equal(out[0][-2], out[0][-4])  # the tiles drew what the bands drew
    np.testing.assert_array_equal(out[0][-1], out[0][-3])


def test_band_bounds_split_the_work_evenly():
    lo = np.array([0, 10, 10, 10, 0, 5], np.int32)
    hi = np.array([99, 19, 19, 19, -1, 4], np.int32)  # segments 4 and 5 touch no row
    bounds = soft_raster.band_bounds(lo, hi, 100, 4)
    assert bounds[0] == 0 and bounds[-1] == 100 and np.all(np.diff(bounds) >= 0)
    work = np.ones(100) + ((np.arange(100) >= 10) & (np.arange(100) < 20)) * 3 + 1
    per_band = [work[a:b].sum() for a, b in itertools.pairwise(bounds)]
    assert max(per_band) - min(per_band) <= work.max()
    assert soft_raster.band_bounds(lo, hi, 100, 1).tolist() == [0, 100]
    # weighted: segment 0 (all rows) counts 5 per row, the three on rows 10-19 count 2 each
    weight = np.array([5.0, 2.0, 2.0, 2.0, 7.0, 7.0])
    bounds = soft_raster.band_bounds(lo, hi, 100, 4, weight)
    work = np.ones(100) + 5.0 + ((np.arange(100) >= 10) & (np.arange(100) < 20)) * 6.0
    per_band = [work[a:b].sum() for a, b in itertools.pairwise(bounds)]
    assert max(per_band) - min(per_band) <= work.max()


def test_clear_none_draws_over_the_images_and_a_clear_colour_fills_them():
    points, starts, colors = _awkward_segments(1)
    mvp = _ortho()
    raster = StrandRaster()
    rgba, depth = raster.images(SIZE)
    rgba[:] = (10, 20, 30, 40)
    depth[:] = 0.5  # e.g. a mesh's depth read back: only strands in front of it are drawn
    raster.draw(points, starts, colors, mvp, SIZE, 2.0, clear=None)
    ref_rgba, ref_depth = rasterize_reference(points, starts, colors, mvp, SIZE, 2.0)
    front = ref_depth < 0.5
    assert front.any() and (~front & (ref_depth < 1.0)).any()
    np.testing.assert_array_equal(rgba[front], ref_rgba[front])
    assert np.all(rgba[~front] == (10, 20, 30, 40)) and np.all(depth[~front] == 0.5)
    again, _ = raster.draw(points, starts, colors, mvp, SIZE, 2.0, clear=(1, 2, 3, 4))
    assert again is rgba  # the images are kept between draws
    assert np.all(rgba[ref_rgba[..., 3] == 0] == (1, 2, 3, 4))
    bigger, _ = raster.draw(points, starts, colors, mvp, (80, 50), 2.0)
    assert bigger.shape == (50, 80, 4)


def test_one_pixel_lines_step_the_major_axis_and_quads_have_the_width():
    # 61 px show 2.5·61/47 units across; a horizontal line through row 23's centre, a vertical one.
    mvp = _ortho()
    y = (23.5 / SIZE[1] * 2.0 - 1.0) * 1.25
    g = Groom.from_strands([[[-0.8, y, 0.0], [0.8, y, 0.0]], [[0.1, -0.9, 0.0], [0.1, 0.9, 0.0]]])
    colors = np.ones((g.vertex_count, 3), np.float32)
    starts = g.topology.segment_end - 1
    thin, _ = rasterize(g.points, starts, colors, mvp, SIZE, 1.0)
    lit = thin[..., 3] > 0
    assert lit[23].sum() > 30 and lit[22].sum() <= 1 and lit[24].sum() <= 1  # one row
    column = np.flatnonzero(lit[10])
    assert len(column) == 1  # the vertical line: one pixel per row
    assert lit[:, column[0]].sum() > 30
    for width in (2.0, 4.0):
        wide, _ = rasterize(g.points, starts, colors, mvp, SIZE, width)
        assert (wide[10, :, 3] > 0).sum() == width  # across the vertical line
        assert (wide[:, 20, 3] > 0).sum() == width  # across the horizontal one


def test_colour_and_depth_run_along_the_segment():
    mvp = _ortho()
    g = Groom.from_strands([[[-1.0, 0.0, 0.5], [1.0, 0.0, -0.5]]])
    colors = np.float32([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    for width in (1.0, 3.0):
        rgba, depth = rasterize(g.points, [0], colors, mvp, SIZE, width)
        row = np.flatnonzero(rgba[:, SIZE[0] // 2, 3])[0]
        red, blue = rgba[row, :, 0].astype(int), rgba[row, :, 2].astype(int)
        lit = rgba[row, :, 3] > 0
        assert np.all(np.diff(red[lit]) <= 0) and np.all(np.diff(blue[lit]) >= 0)
        assert red[lit][0] > 200 and blue[lit][-1] > 200
        assert np.all(np.diff(depth[row, lit]) > 0)  # z = 0.5 is nearer the eye than z = −0.5


def test_first_drawn_wins_a_tie_and_nearer_wins_otherwise():
    mvp = _ortho()
    strands = [[[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0]]] * 2 + [[[-0.5, 0.0, 0.2], [0.5, 0.0, 0.2]]]
    g = Groom.from_strands(strands)
    colors = np.float32([[1, 0, 0]] * 2 + [[0, 1, 0]] * 2 + [[0, 0, 1]] * 2)
    rgba, _ = rasterize(g.points, [0, 2], colors, mvp, SIZE, 2.0)
    assert set(map(tuple, rgba[rgba[..., 3] > 0][:, :3])) == {(255, 0, 0)}
    rgba, _ = rasterize(g.points, [0, 2, 4], colors, mvp, SIZE, 2.0)
    assert set(map(tuple, rgba[rgba[..., 3] > 0][:, :3])) == {(0, 0, 255)}


def test_bad_inputs_are_refused():
    p, c = np.zeros((4, 3)), np.zeros((4, 3))
    for args, name in (
        ((np.zeros((4, 2)), [0], c, np.eye(4), SIZE, 1.0), "points"),
        ((p, [0], c[:3], np.eye(4), SIZE, 1.0), "colors"),
        ((p, [0], c, np.eye(3), SIZE, 1.0), "mvp"),
        ((p, [3], c, np.eye(4), SIZE, 1.0), "starts"),
        ((p, [0], c, np.eye(4), (0, 5), 1.0), "size"),
        ((p, [0], c, np.eye(4), SIZE, 0.0), "width"),
    ):
        with pytest.raises(ParameterError, match=name):
            rasterize(*args)


def test_ramp_sampling_is_gl_linear_filtering_with_clamped_edges():
    texels = ramp_texture("heat", 256)
    centres = (np.arange(256) + 0.5) / 256
    np.testing.assert_allclose(sample_linear(texels, centres), texels, atol=1e-6)
    np.testing.assert_allclose(sample_linear(texels, [-1.0, 0.0, 1.0, 2.0]), texels[[0, 0, -1, -1]])
    halfway = sample_linear(texels, [(10 + 1.0) / 256])  # between texels 10 and 11
    np.testing.assert_allclose(halfway[0], (texels[10] + texels[11]) / 2, atol=1e-6)


def _scalp_scene(size=(160, 120)):
    from hairtool import samples

    g = samples.scalp(strands=300, vertices=10, seed=2)
    cam = Camera.for_groom(g, aspect=size[0] / size[1])
    mvp = cam.view_matrix() @ cam.projection_matrix(size[0] / size[1])
    colors = np.random.default_rng(1).random((g.vertex_count, 3)).astype(np.float32)
    return g, g.topology.segment_end - 1, colors, mvp


@pytest.mark.parametrize("width", [1.0, 2.5])
@pytest.mark.parametrize("n_threads", [1, 2])
def test_redrawing_the_changed_tiles_gives_the_bytes_of_a_full_draw(width, n_threads, threads):
    threads(n_threads)
    size = (320, 240)
    g, starts, colors, mvp = _scalp_scene(size)
    rng = np.random.default_rng(5)
    raster = StrandRaster()
    points = g.points.copy()
    before = raster.draw(points, starts, colors, mvp, size, width, clear=(9, 8, 7, 255))[0].copy()
    partial = 0
    for step in range(12):
        if step == 5:  # a change of colour only
            colors = colors.copy()
            colors[g.offsets[3] : g.offsets[4]] = (1.0, 0.0, 0.0)
        else:  # the tips of a few strands move; now and then far, off the image or behind the eye
            for s in rng.choice(g.strand_count, size=int(rng.integers(1, 4)), replace=False):
                tip = g.offsets[s + 1]
                scale = 0.01 if step % 4 else 3.0
                points[tip - 3 : tip] += rng.normal(scale=scale, size=(3, 3)).astype(np.float32)
        rgba, depth = raster.draw(points, starts, colors, mvp, size, width, clear=(9, 8, 7, 255))
        ref_rgba, ref_depth = StrandRaster().draw(
            points, starts, colors, mvp, size, width, clear=(9, 8, 7, 255)
        )
        np.testing.assert_array_equal(rgba, ref_rgba)
        np.testing.assert_array_equal(depth, ref_depth)
        if raster.tiles_redrawn > 0:
            partial += 1
            r0, r1, c0, c1 = raster.changed
            outside = np.ones(depth.shape, bool)
            outside[r0:r1, c0:c1] = False
            np.testing.assert_array_equal(rgba[outside], before[outside])  # the rest did not change
            assert (r1 - r0) * (c1 - c0) < depth.size
        before = rgba.copy()
    assert partial >= 6  # most of these frames were redrawn in part


def test_frames_that_change_nearly_all_then_little_give_the_bytes_of_a_full_draw():
    # Render hair following a brush: most strands move for a few frames (drawn in full, the
    # next ones without looking for changes, and without keeping what they drew), then few, some
    # of them back where they were two frames before: each frame as a fresh draw gives it.
    size = (160, 120)
    g, starts, colors, mvp = _scalp_scene(size)
    rng = np.random.default_rng(8)
    raster = StrandRaster()
    rest = g.points.copy()
    shifts = [rng.normal(scale=0.02, size=rest.shape).astype(np.float32) for _ in range(3)]
    kinds = []
    for step in range(16):
        points = rest + shifts[step % 3] if step < 9 else rest.copy()
        if step >= 9:  # a few tips move, and back
            tip = g.offsets[5 + step % 2]
            points[tip - 2 : tip] += np.float32(0.03 if step % 2 else -0.03)
        rgba, depth = raster.draw(points, starts, colors, mvp, size, 2.5)
        want = StrandRaster().draw(points, starts, colors, mvp, size, 2.5)
        np.testing.assert_array_equal(rgba, want[0])
        np.testing.assert_array_equal(depth, want[1])
        kinds.append(raster.tiles_redrawn)
    assert kinds[1:9].count(-1) == 8 and any(k > 0 for k in kinds[10:])  # in full, then in part


def test_frames_whose_changes_touch_every_tile_stop_searching_for_a_while(monkeypatch):
    # Render hair following a brush: a sixth of the strands move each frame, spread over the
    # whole image, so their tiles hold every segment and the frame is drawn in full; the next
    # 1, then 3 frames are drawn in full without searching. Bytes as fresh draws throughout.
    from app.render import soft_raster

    searches = []
    search = soft_raster._changed_vertices
    monkeypatch.setattr(soft_raster, "_changed_vertices", lambda *a: searches.append(1) or search(*a))
    size = (160, 120)
    g, starts, colors, mvp = _scalp_scene(size)
    rng = np.random.default_rng(3)
    raster = StrandRaster()
    points = g.points.copy()
    for _ in range(9):
        for s in rng.choice(g.strand_count, size=g.strand_count // 6, replace=False):
            points[g.offsets[s] + 1 : g.offsets[s + 1]] += np.float32(0.002)
        rgba, depth = raster.draw(points, starts, colors, mvp, size, 2.5)
        want = StrandRaster().draw(points, starts, colors, mvp, size, 2.5)
        np.testing.assert_array_equal(rgba, want[0])
        np.testing.assert_array_equal(depth, want[1])
        assert raster.tiles_redrawn == -1
    assert len(searches) == 3  # on frames 2, 4 and 8 (the first has nothing to compare with)


def test_what_makes_a_full_draw_and_what_draws_nothing():
    size = (160, 120)
    g, starts, colors, mvp = _scalp_scene(size)
    raster = StrandRaster()
    raster.draw(g.points, starts, colors, mvp, size, 2.0)
    assert raster.tiles_redrawn == -1 and raster.changed == (0, 120, 0, 160)
    raster.draw(g.points, starts, colors, mvp, size, 2.0)
    assert raster.tiles_redrawn == 0 and raster.changed is None  # the same numbers: nothing to do
    for args in (
        (g.points, starts, colors, mvp, size, 3.0),  # another width
        (g.points, starts, colors, mvp @ np.diag([1.0, 1.0, 1.0, 1.01]), size, 3.0),  # the camera moved
        (g.points, starts, colors, mvp, (150, 120), 3.0),  # another size
        (g.points, starts[:-1], colors, mvp, (150, 120), 3.0),  # other segments
    ):
        raster.draw(*args)
        assert raster.tiles_redrawn == -1
    raster.draw(g.points, starts[:-1], colors, mvp, (150, 120), 3.0, clear=(1, 1, 1, 1))
    assert raster.tiles_redrawn == -1  # another clear colour
    rgba, _ = raster.images((150, 120))  # handed out to be drawn into: no longer the last frame
    rgba[:] = 0
    raster.draw(g.points, starts[:-1], colors, mvp, (150, 120), 3.0, clear=(1, 1, 1, 1))
    assert raster.tiles_redrawn == -1
    moved = g.points.copy()
    moved[g.offsets[1] - 2 : g.offsets[1]] += 0.01
    # All segments, then fewer (one buffer holds just those, the other more), redrawn in part:
    fresh = StrandRaster()
    fresh.draw(g.points, starts, colors, mvp, (150, 120), 3.0)
    fresh.draw(g.points, starts[:-1], colors, mvp, (150, 120), 3.0)
    rgba, depth = fresh.draw(moved, starts[:-1], colors, mvp, (150, 120), 3.0)
    assert fresh.tiles_redrawn > 0
    want = StrandRaster().draw(moved, starts[:-1], colors, mvp, (150, 120), 3.0)
    np.testing.assert_array_equal(rgba, want[0])
    np.testing.assert_array_equal(depth, want[1])
    raster.incremental = False
    moved[g.offsets[1] - 2 : g.offsets[1]] += 0.01
    raster.draw(moved, starts[:-1], colors, mvp, (150, 120), 3.0, clear=(1, 1, 1, 1))
    assert raster.tiles_redrawn == -1


def test_balanced_jobs_split_the_tiles_by_work():
    work = np.array([0, 5, 1, 1, 0, 9, 1, 1, 1, 0], np.int64)
    tiles, start = soft_raster._balanced_jobs(work, 2)
    jobs = [tiles[a:b] for a, b in itertools.pairwise(start)]
    assert sorted(np.concatenate(jobs).tolist()) == [1, 2, 3, 5, 6, 7, 8]
    assert all(np.all(np.diff(j) > 0) for j in jobs)
    loads = [work[j].sum() + 8 * len(j) for j in jobs]
    assert max(loads) - min(loads) <= 9 + 8
