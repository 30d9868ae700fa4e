"""A move that changed a few strands uploads only theirs: the GPU's bytes are those of a whole
upload, fewer bytes are written (counted at :func:`app.render.strand_gpu.write_buffer`), and the
shaded colours of the strands that did not move are not recomputed yet stay exact."""

from __future__ import annotations

import numpy as np
import pytest

from app.render import strand_gpu
from app.render.camera import Camera
from app.render.strand_gpu import changed_strands, joined, strand_rows, vertex_runs
from app.render.strands import StrandRenderer
from hairtool import samples
from hairtool.errors import ParameterError

SIZE = (96, 72)


@pytest.fixture
def written(monkeypatch):
    """Bytes and calls through write_buffer, per buffer (``log[id(buffer)]``)."""
    log: dict[int, list[int]] = {}
    real = strand_gpu.write_buffer

    def counting(buffer, data, offset=0):
        log.setdefault(id(buffer), []).append(int(np.asarray(data).nbytes))
        return real(buffer, data, offset)

    monkeypatch.setattr(strand_gpu, "write_buffer", counting)
    return log


def _frame(renderer, ctx, camera):
    fbo = ctx.framebuffer([ctx.renderbuffer(SIZE, 4)], ctx.depth_renderbuffer(SIZE))
    try:
        renderer.render(fbo, camera, SIZE)
        return np.frombuffer(fbo.read(components=4), np.uint8).reshape(SIZE[1], SIZE[0], 4)
    finally:
        fbo.release()


def _move_some(points, groom, strands, by=(0.02, -0.01, 0.015)):
    out = points.copy()
    for s in strands:
        a, b = groom.offsets[s], groom.offsets[s + 1]
        out[a + 1 : b] += np.float32(by) * groom.topology.vertex_param[a + 1 : b, None]
    return out


def test_changed_strands_and_runs_are_the_plain_definitions():
    g = samples.scalp(strands=40, vertices=6, seed=1)
    moved = _move_some(g.points, g, [3, 4, 17, 39])
    moved[g.offsets[25]] = -0.0 * moved[g.offsets[25]]  # a sign bit alone is a change of bytes
    want = [s for s in range(40) if moved[g.offsets[s] : g.offsets[s + 1]].tobytes()
            != g.points[g.offsets[s] : g.offsets[s + 1]].tobytes()]  # fmt: skip
    assert changed_strands(g.points, moved, g.topology).tolist() == want
    runs = vertex_runs(g.offsets, np.array([3, 4, 17, 39]), gap=1)
    assert runs.tolist() == [[18, 30], [102, 108], [234, 240]]
    assert vertex_runs(g.offsets, np.array([3, 4, 17, 39]), gap=100).tolist() == [[18, 108], [234, 240]]
    rows, sub = strand_rows(g.offsets, np.array([4, 17]))
    assert rows.tolist() == list(range(24, 30)) + list(range(102, 108)) and sub.tolist() == [0, 6, 12]
    assert joined(np.array([[5, 9], [0, 2], [2, 3], [8, 12]])).tolist() == [[0, 3], [5, 12]]


@pytest.mark.parametrize("shaded", [False, True])
def test_a_partial_update_leaves_the_buffers_as_a_whole_upload_would(gl_ctx, written, shaded):
    g = samples.scalp(strands=600, vertices=12, seed=3)
    cam = Camera.for_groom(g, aspect=SIZE[0] / SIZE[1])
    colours = np.random.default_rng(2).uniform(0.1, 0.9, (g.vertex_count, 3)).astype(np.float32)
    r = StrandRenderer(gl_ctx)
    try:
        r.strand_raster = "gl"
        r.set_hair_shading(shaded)
        r.set_strands(g.points, g.topology, colours)
        _frame(r, gl_ctx, cam)
        written.clear()
        points = g.points
        for step, few in enumerate(([5, 6, 7], [300], [0, 599], list(range(100, 160)))):
            points = _move_some(points, g, few, by=(0.01 * (step + 1), 0.0, -0.01))
            r.update_points(points)
            assert r.last_moved.tolist() == few
            got = _frame(r, gl_ctx, cam)
        pos = np.frombuffer(r.position_buffer.read(), np.float32).reshape(-1, 3)
        assert pos.tobytes() == np.ascontiguousarray(points, np.float32).tobytes()
        fresh = StrandRenderer(gl_ctx)
        try:
            fresh.strand_raster = "gl"
            fresh.set_hair_shading(shaded)
            fresh.set_strands(points, g.topology, colours)
            want = _frame(fresh, gl_ctx, cam)
            assert r.color_buffer.read() == fresh.color_buffer.read()  # the shade too, byte for byte
            np.testing.assert_array_equal(got, want)
        finally:
            fresh.release()
        sent = written[id(r.position_buffer)]
        moved_bytes = 12 * 12 * (3 + 1 + 2 + 60)
        assert sum(sent) < 0.15 * len(sent) * points.nbytes and sum(sent) >= moved_bytes
        if shaded:  # the colours of the moved strands alone went up again
            assert sum(written[id(r.color_buffer)]) < 0.15 * 4 * colours.nbytes
    finally:
        r.release()


def test_the_engine_s_list_of_changed_strands_is_taken_as_it_is(gl_ctx, written):
    g = samples.scalp(strands=300, vertices=8, seed=5)
    cam = Camera.for_groom(g, aspect=SIZE[0] / SIZE[1])
    r = StrandRenderer(gl_ctx)
    try:
        r.strand_raster = "gl"
        r.set_groom(g)
        _frame(r, gl_ctx, cam)
        written.clear()
        points = _move_some(g.points, g, [10, 11, 250])
        r.update_points(points, changed=[250, 10, 11, 12])  # a superset, in any order
        assert r.last_moved.tolist() == [10, 11, 12, 250]
        assert np.frombuffer(r.position_buffer.read(), np.float32).tobytes() == points.tobytes()
        assert sum(written[id(r.position_buffer)]) <= 12 * 8 * 4 + 12 * 8  # two runs, one of 4 strands
        with pytest.raises(ParameterError, match="changed"):
            r.update_points(points, changed=[300])
    finally:
        r.release()


def test_many_strands_moved_or_a_stale_buffer_write_all_of_it(gl_ctx, written):
    g = samples.scalp(strands=200, vertices=8, seed=6)
    cam = Camera.for_groom(g, aspect=SIZE[0] / SIZE[1])
    r = StrandRenderer(gl_ctx)
    try:
        r.strand_raster = "gl"
        r.set_groom(g)
        _frame(r, gl_ctx, cam)
        buffer = id(r._main.buffer)
        written.clear()
        points = _move_some(g.points, g, range(0, 200, 2))  # every other strand: 100 runs
        r.update_points(points)
        assert written[buffer] == [points.nbytes]
        r.strand_raster = "cpu"
        _frame(r, gl_ctx, cam)  # a CPU draw: later moves upload nothing at once …
        written.clear()
        points = _move_some(points, g, [3])
        r.update_points(points)
        assert buffer not in written
        r.strand_raster = "gl"
        _frame(r, gl_ctx, cam)  # … and the next GL draw uploads it whole
        assert written[buffer] == [points.nbytes]
        assert np.frombuffer(r.position_buffer.read(), np.float32).tobytes() == points.tobytes()
    finally:
        r.release()


def test_the_quads_texture_takes_the_moved_rows_only_and_matches_a_fresh_one(gl_ctx):
    g = samples.scalp(strands=1200, vertices=10, seed=7)  # 12,000 vertices: three texel rows
    cam = Camera.for_groom(g, aspect=SIZE[0] / SIZE[1])
    r = StrandRenderer(gl_ctx)
    try:
        r.strand_raster, r.wide_lines, r.line_width = "gl", "quads", 3.0
        r.set_hair_shading(True)
        r.set_groom(g)
        _frame(r, gl_ctx, cam)
        points = _move_some(g.points, g, [2, 1199])
        r.update_points(points)
        got = _frame(r, gl_ctx, cam)
        texels = np.frombuffer(r._main.texture().read(), np.float32).reshape(-1, 4)
        assert texels[: g.vertex_count, :3].tobytes() == points.tobytes()
        fresh = StrandRenderer(gl_ctx)
        try:
            fresh.strand_raster, fresh.wide_lines, fresh.line_width = "gl", "quads", 3.0
            fresh.set_hair_shading(True)
            fresh.set_groom(g.with_points(points))
            np.testing.assert_array_equal(got, _frame(fresh, gl_ctx, cam))
            assert r._gpu.color_texture().read() == fresh._gpu.color_texture().read()
        finally:
            fresh.release()
    finally:
        r.release()


@pytest.mark.parametrize("shaded", [False, True])
def test_new_vertex_colours_upload_and_shade_only_the_strands_they_change(gl_ctx, written, shaded):
    """A colour mode that follows the brush (displacement) sends every vertex's colour each move."""
    g = samples.scalp(strands=500, vertices=10, seed=8)
    cam = Camera.for_groom(g, aspect=SIZE[0] / SIZE[1])
    colours = np.random.default_rng(4).uniform(0.0, 1.0, (g.vertex_count, 3)).astype(np.float32)
    r = StrandRenderer(gl_ctx)
    try:
        r.strand_raster = "gl"
        r.set_hair_shading(shaded)
        r.set_strands(g.points, g.topology, colours)
        _frame(r, gl_ctx, cam)
        buffer = id(r._gpu.color_buffer)
        written.clear()
        for few in ([3, 4], [250], [499]):
            rows, _ = strand_rows(g.offsets, np.array(few))
            colours = colours.copy()
            colours[rows] = np.float32(1.3) - colours[rows]  # some go past 1: clipped as before
            r.set_vertex_colors(colours)
            got = _frame(r, gl_ctx, cam)
        assert sum(written[buffer]) <= 3 * 2 * 10 * 12  # the changed strands' rows alone
        fresh = StrandRenderer(gl_ctx)
        try:
            fresh.strand_raster = "gl"
            fresh.set_hair_shading(shaded)
            fresh.set_strands(g.points, g.topology, colours)
            np.testing.assert_array_equal(got, _frame(fresh, gl_ctx, cam))
            assert r.color_buffer.read() == fresh.color_buffer.read()
        finally:
            fresh.release()
    finally:
        r.release()
