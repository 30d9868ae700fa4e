"""GPU copies of one groom's strands for the GL line methods of :mod:`app.render.strands`.

Positions live in two GPU forms: a vertex buffer (the ``"thin"`` and ``"geometry"`` draws read it
as an attribute) and an RGBA32F texture with t in alpha (the ``"quads"`` draw pulls both ends of a
segment from it), besides the float32 copy on the CPU that the ``"cpu"`` method rasterizes. While
a brush drags, :meth:`PointSet.write` uploads only the form the last draw used (none after a CPU
draw) and marks the others stale; a draw with another method refreshes its form first. Index
buffers are made once per topology, when a method first needs them.

A move that changed a few strands writes only theirs: :meth:`PointSet.write` finds the strands
whose points differ bit for bit from the last (or takes the caller's list of them), and a form
that was up to date gets ``Buffer.write(..., offset=)`` for each run of those strands' vertices,
runs closer than :data:`COALESCE_VERTICES` merged into one write (each write is a driver call),
or one whole write when they cover most of the buffer (:func:`write_runs`). The colours work the
same way (:meth:`StrandGPU.colors_written` with the strands shaded again). Every byte goes
through :func:`write_buffer`, which the tests count.
"""

from __future__ import annotations

import moderngl
import numpy as np
from numpy.typing import NDArray

from hairtool.groom import Topology

RESTART_INDEX = 0xFFFFFFFF
TEXTURE_WIDTH = 4096  # texels per row of the point and colour textures (vertex v at v % W, v // W)
_QUAD_CORNERS = np.array([0, 1, 2, 2, 1, 3], dtype=np.uint32)
COALESCE_VERTICES = 1024  # changed runs of vertices closer than this are written as one (12 KiB of points)
WHOLE_SHARE = 0.5  # runs covering more than this share of a buffer: one write of all of it
MAX_WRITES = 64  # … or needing more writes than this


def write_buffer(buffer: moderngl.Buffer, data: NDArray, offset: int = 0) -> int:
    """``data`` into ``buffer`` at byte ``offset``; returns the bytes written (every upload of
    points and colours goes through here)."""
    buffer.write(data, offset=offset)
    return int(data.nbytes)


def changed_strands(old: NDArray, new: NDArray, topology: Topology) -> NDArray[np.int64]:
    """Sorted ids of the strands with a vertex whose ``(V, 3)`` row of ``new`` differs bit for
    bit from ``old``'s (a −0.0 for a 0.0 too: the bytes are what is uploaded). Flat compares and
    the changed vertices' strands, no per-row reduction (numpy's ``any(axis=1)`` over rows of
    three cost ten times the compare)."""
    a = np.ascontiguousarray(old).view(np.uint32).reshape(-1)
    b = np.ascontiguousarray(new).view(np.uint32).reshape(-1)
    differ = a != b
    vertices = np.flatnonzero(differ[0::3] | differ[1::3] | differ[2::3])
    strands = topology.strand_index[vertices]  # increasing with the vertex
    if strands.size < 2:
        return strands.astype(np.int64)
    first = np.concatenate([[True], strands[1:] != strands[:-1]])
    return strands[first].astype(np.int64)


def vertex_runs(offsets: NDArray, strands: NDArray, gap: int = COALESCE_VERTICES) -> NDArray[np.int64]:
    """``(R, 2)`` vertex ranges [a, b) covering the sorted ``strands``, neighbouring ranges
    less than ``gap`` vertices apart merged."""
    s = np.asarray(strands, np.int64)
    if s.size == 0:
        return np.zeros((0, 2), np.int64)
    a, b = offsets[s], offsets[s + 1]
    cut = np.flatnonzero(a[1:] - b[:-1] >= gap) + 1  # a new run where the gap is wide
    first = np.concatenate([[0], cut])
    last = np.concatenate([cut - 1, [s.size - 1]])
    return np.stack([a[first], b[last]], axis=1).astype(np.int64)


def strand_rows(offsets: NDArray, strands: NDArray) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The vertex ids of ``strands`` one strand after another, and their offsets (S' + 1) in
    that list: the strands as a groom of their own."""
    s = np.asarray(strands, np.int64)
    counts = offsets[s + 1] - offsets[s]
    sub = np.zeros(s.size + 1, np.int64)
    np.cumsum(counts, out=sub[1:])
    rows = np.arange(sub[-1], dtype=np.int64) + np.repeat(offsets[s] - sub[:-1], counts)
    return rows, sub


def write_runs(buffer: moderngl.Buffer, data: NDArray, runs: NDArray | None) -> int:
    """Rows ``runs`` (``(R, 2)`` [a, b), None: all) of ``data`` into ``buffer`` (row r at byte
    r · row size), all of it at once when the runs are many or cover most of it; the bytes."""
    row = data.nbytes // max(len(data), 1)
    if runs is None or len(runs) > MAX_WRITES or (runs[:, 1] - runs[:, 0]).sum() > WHOLE_SHARE * len(data):
        return write_buffer(buffer, data)
    return sum(write_buffer(buffer, data[a:b], int(a) * row) for a, b in runs if b > a)


def strip_indices(topology: Topology) -> NDArray[np.uint32]:
    """``(V + S,)`` u4: each strand's vertex indices followed by the restart index.

    Vertex i of strand s lands at position i + s, so the restarts fall at offsets[s+1] + s.
    """
    idx = np.full(topology.vertex_count + topology.strand_count, RESTART_INDEX, dtype=np.uint32)
    v = np.arange(topology.vertex_count, dtype=np.int64)
    idx[v + topology.strand_index] = v
    return idx


def line_indices(topology: Topology) -> NDArray[np.uint32]:
    """``(2·(V − S),)`` u4: the two ends of every segment, for one ``LINES`` draw (llvmpipe draws
    this about 1.5× faster than a ``LINE_STRIP`` broken by primitive restarts)."""
    end = topology.segment_end
    return np.stack([end - 1, end], axis=1).astype(np.uint32).ravel()


def quad_indices(topology: Topology) -> NDArray[np.uint32]:
    """``(6·(V − S),)`` u4: two triangles per segment i → i + 1 over the vertex ids 4i … 4i + 3."""
    first = (topology.segment_end - 1).astype(np.uint32)
    return (first[:, None] * 4 + _QUAD_CORNERS).ravel()


def segment_indices_reference(topology: Topology, method: str) -> NDArray[np.uint32]:
    """Loop over strands: the plain definition :func:`line_indices` and :func:`quad_indices` are
    tested against."""
    out: list[int] = []
    for s in range(topology.strand_count):
        for i in range(int(topology.offsets[s]), int(topology.offsets[s + 1]) - 1):
            if method == "lines":
                out += [i, i + 1]
            else:
                out += [4 * i + c for c in (0, 1, 2, 2, 1, 3)]
    return np.array(out, dtype=np.uint32)


def _rows(v: int) -> int:
    return max(1, -(-v // TEXTURE_WIDTH))


class StrandGPU:
    """What all point sets of one topology share: t, colours, index buffers."""

    def __init__(self, ctx: moderngl.Context, topology: Topology) -> None:
        self.ctx = ctx
        self.topology = topology
        v = topology.vertex_count
        self.param = np.ascontiguousarray(topology.vertex_param, np.float32)
        self._param_buffer: moderngl.Buffer | None = None
        self._color_buffer: moderngl.Buffer | None = None
        self._colors = np.zeros((v, 3), np.float32)
        self._color_texture: moderngl.Texture | None = None
        self._color_texture_stale = False
        self._color_buffer_stale = False
        self._color_runs: list[NDArray] = []  # rows written since the last upload, per GL form
        self._color_texture_runs: list[NDArray] = []
        self.cpu_color_runs: list[NDArray] | None = None  # rows written since the last CPU draw (None: any)
        self._index: dict[str, moderngl.Buffer] = {}
        self.uploaded_bytes = 0  # colours uploaded so far (all written through write_buffer)

    # GL buffers are made when a GL draw first reads them: a groom only rasterized on the CPU
    # (the studio on llvmpipe) uploads no t and reserves no colour buffer.
    @property
    def param_buffer(self) -> moderngl.Buffer:
        if self._param_buffer is None:
            self._param_buffer = self.ctx.buffer(self.param)
        return self._param_buffer

    @property
    def color_buffer(self) -> moderngl.Buffer:
        if self._color_buffer is None:
            self._color_buffer = self.ctx.buffer(reserve=self.topology.vertex_count * 12, dynamic=True)
            self._color_buffer_stale = True
        return self._color_buffer

    def index_buffer(self, kind: str) -> moderngl.Buffer:
        """``"strip"`` (LINE_STRIP with restarts), ``"lines"`` or ``"quads"``, made on first use."""
        buf = self._index.get(kind)
        if buf is None:
            make = {"strip": strip_indices, "lines": line_indices, "quads": quad_indices}[kind]
            buf = self._index[kind] = self.ctx.buffer(make(self.topology))
        return buf

    @property
    def colors(self) -> NDArray[np.float32]:
        """The ``(V, 3)`` vertex colours last written (the CPU's copy)."""
        return self._colors

    def write_colors(self, colors: NDArray[np.float32]) -> None:
        """New vertex colours, uploaded when a GL draw reads them (a CPU draw reads
        :attr:`colors`, so colour modes that change every frame upload nothing there)."""
        self._colors[:] = colors
        self.colors_written()

    def colors_written(self, runs: NDArray | None = None) -> None:
        """:attr:`colors` were written in place (e.g. shaded straight into them): upload them
        before the next GL draw that reads them; ``runs`` (``(R, 2)`` vertex ranges): only
        those rows changed (None: any)."""
        if runs is None:
            self._color_buffer_stale = self._color_texture_stale = True
            self._color_runs.clear()
            self._color_texture_runs.clear()
            self.cpu_color_runs = None
            return
        self.cpu_color_runs = kept_runs(self.cpu_color_runs, runs)
        if not self._color_buffer_stale:
            self._color_runs.append(runs)
        if not self._color_texture_stale:
            self._color_texture_runs.append(runs)

    def sync_color_buffer(self) -> None:
        """Bring the colour vertex buffer up to date before a draw that reads it."""
        buffer = self.color_buffer  # made, and marked stale, on first use
        if self._color_buffer_stale:
            self.uploaded_bytes += write_buffer(buffer, self._colors)
        elif self._color_runs:
            self.uploaded_bytes += write_runs(buffer, self._colors, merged_runs(self._color_runs))
        self._color_buffer_stale = False
        self._color_runs.clear()

    def color_texture(self) -> moderngl.Texture:
        if self._color_texture is None:
            self._color_texture = _texture(self.ctx, self.topology.vertex_count, 3)
            self._color_texture_stale = True
        if self._color_texture_stale:
            _write_texture(self._color_texture, self._colors)
        elif self._color_texture_runs:
            _write_texture_runs(self._color_texture, self._colors, merged_runs(self._color_texture_runs))
        self._color_texture_stale = False
        self._color_texture_runs.clear()
        return self._color_texture

    def release(self) -> None:
        for obj in (self._param_buffer, self._color_buffer, self._color_texture, *self._index.values()):
            if obj is not None:
                obj.release()
        self._index.clear()
        self._param_buffer = self._color_buffer = self._color_texture = None


class PointSet:
    """One set of positions (the groom, or the ghost) in the forms the draws read: a contiguous
    ``(V, 3)`` float32 copy on the CPU (what the CPU rasterizer reads without copying it again),
    and the vertex buffer and texture, each made and uploaded when a draw first reads it."""

    def __init__(self, gpu: StrandGPU, points: NDArray[np.float32]) -> None:
        self.gpu = gpu
        self._points = np.array(points, np.float32, order="C")
        self._buffer: moderngl.Buffer | None = None
        self._texels: NDArray[np.float32] | None = None  # the texture's RGBA: xyz and t
        self._texture: moderngl.Texture | None = None
        self._stale = {"buffer": True, "texture": True}
        self._runs: dict[str, list[NDArray]] = {"buffer": [], "texture": []}  # rows to upload
        self.cpu_runs: list[NDArray] | None = None  # rows written since the last CPU draw (None: any)
        self.last_used = "buffer"  # the form the last draw read ("buffer", "texture", "cpu")
        self.uploaded_bytes = 0  # points uploaded to the vertex buffer so far

    @property
    def buffer(self) -> moderngl.Buffer:
        """The vertex buffer object (made on first use; :meth:`vertex_buffer` brings it up to date)."""
        if self._buffer is None:
            self._buffer = self.gpu.ctx.buffer(reserve=max(self._points.nbytes, 4), dynamic=True)
            self._stale["buffer"] = True
        return self._buffer

    @property
    def points(self) -> NDArray[np.float32]:
        """The positions (a read-only view)."""
        view = self._points.view()
        view.flags.writeable = False
        return view

    def write(
        self, points: NDArray[np.float32], changed: NDArray | None = None, find: bool = False
    ) -> NDArray[np.int64] | None:
        """New positions (same topology): upload the form in use now, the other when needed.

        ``changed``: sorted ids of the only strands whose points may differ from the last
        (None: any). A form in use that was up to date then gets only those strands' vertices;
        without ``changed`` they are found by comparing (when a form will be written now, or
        with ``find``). Returns the changed strands where known, else None."""
        form = self.last_used
        partial = form in ("buffer", "texture") and not self._stale[form]
        partial = partial and (self._buffer if form == "buffer" else self._texture) is not None
        moved = None
        offsets = self.gpu.topology.offsets
        if changed is not None:
            moved = np.asarray(changed, np.int64)
        elif partial or find:
            moved = changed_strands(self._points, points, self.gpu.topology)
        self._points[:] = points
        runs = None if moved is None or not partial else vertex_runs(offsets, moved)  # for the form in use
        if moved is None:
            self.cpu_runs = None
        elif self.cpu_runs is not None:  # the CPU raster compares what it is told: no gaps filled
            self.cpu_runs = kept_runs(self.cpu_runs, vertex_runs(offsets, moved, gap=1))
        for name in self._stale:
            if runs is None or name != form or not partial:
                self._stale[name] = True
                self._runs[name].clear()
            else:
                self._runs[name].append(runs)
        if form == "buffer":
            self.vertex_buffer()
        elif form == "texture" and self._texture is not None:
            self.texture()
        return moved

    def cpu_points(self) -> NDArray[np.float32]:
        """The positions for a CPU draw (a view, current); later writes upload nothing at once."""
        self.last_used = "cpu"
        return self.points

    def vertex_buffer(self, draw: bool = True) -> moderngl.Buffer:
        """The vertex buffer, brought up to date (``draw``: a draw reads it, so later writes
        upload to it at once)."""
        if draw:
            self.last_used = "buffer"
        buffer = self.buffer
        if self._stale["buffer"]:
            self.uploaded_bytes += write_buffer(buffer, self._points)
        elif self._runs["buffer"]:
            self.uploaded_bytes += write_runs(buffer, self._points, merged_runs(self._runs["buffer"]))
        self._stale["buffer"] = False
        self._runs["buffer"].clear()
        return buffer

    def texture(self) -> moderngl.Texture:
        self.last_used = "texture"
        v = self.gpu.topology.vertex_count
        if self._texture is None:
            self._texture = _texture(self.gpu.ctx, v, 4)
            self._texels = np.zeros((_rows(v) * TEXTURE_WIDTH, 4), np.float32)
            self._texels[:v, 3] = self.gpu.param
            self._stale["texture"] = True
        if self._stale["texture"]:
            self._texels[:v, :3] = self._points
            _write_texture(self._texture, self._texels)
        elif self._runs["texture"]:
            runs = merged_runs(self._runs["texture"])
            for a, b in runs:
                self._texels[a:b, :3] = self._points[a:b]
            _write_texture_runs(self._texture, self._texels, runs)
        self._stale["texture"] = False
        self._runs["texture"].clear()
        return self._texture

    def release(self) -> None:
        if self._buffer is not None:
            self._buffer.release()
            self._buffer = None
        if self._texture is not None:
            self._texture.release()
            self._texture = None
            self._texels = None


def kept_runs(parts: list[NDArray] | None, runs: NDArray) -> list[NDArray] | None:
    """``parts`` (rows written since the last CPU draw) with ``runs`` too; None (any) stays
    None, and so does a list longer than :data:`MAX_WRITES` (no CPU draw is reading them: the
    GL methods draw)."""
    if parts is None or len(parts) >= MAX_WRITES:
        return None
    parts.append(runs)
    return parts


def merged_runs(parts: list[NDArray]) -> NDArray[np.int64]:
    """The union of several ``(R, 2)`` lists of ranges [a, b): sorted, overlapping or touching
    ranges joined."""
    if len(parts) == 1:
        return parts[0]  # one list from vertex_runs: sorted and disjoint already
    return joined(np.concatenate(parts))


def joined(runs: NDArray) -> NDArray[np.int64]:
    """``(R, 2)`` ranges [a, b) sorted, the overlapping or touching ones joined."""
    if len(runs) < 2:
        return runs
    runs = runs[np.argsort(runs[:, 0], kind="stable")]
    ends = np.maximum.accumulate(runs[:, 1])
    cut = np.flatnonzero(runs[1:, 0] > ends[:-1]) + 1
    first = np.concatenate([[0], cut])
    last = np.concatenate([cut - 1, [len(runs) - 1]])
    return np.stack([runs[first, 0], ends[last]], axis=1)


def _texture(ctx: moderngl.Context, v: int, components: int) -> moderngl.Texture:
    tex = ctx.texture((TEXTURE_WIDTH, _rows(v)), components, dtype="f4")
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    tex.repeat_x = tex.repeat_y = False
    return tex


def _write_texture(tex: moderngl.Texture, data: NDArray[np.float32], row0: int = 0) -> None:
    """Rows of ``data`` (``(n, components)``) into the texture from texel row ``row0`` on,
    vertex v at (v % W, row0 + v // W)."""
    c = tex.components
    if row0 == 0 and len(data) == tex.height * TEXTURE_WIDTH:
        tex.write(np.ascontiguousarray(data))
        return
    full = len(data) // TEXTURE_WIDTH
    if full:
        rows = np.ascontiguousarray(data[: full * TEXTURE_WIDTH])
        tex.write(rows, viewport=(0, row0, TEXTURE_WIDTH, full))
    rest = len(data) - full * TEXTURE_WIDTH
    if rest:
        tail = np.ascontiguousarray(data[full * TEXTURE_WIDTH :], np.float32).reshape(rest, c)
        tex.write(tail, viewport=(0, row0 + full, rest, 1))


def _write_texture_runs(tex: moderngl.Texture, data: NDArray[np.float32], runs: NDArray) -> None:
    """The texel rows holding the vertex ranges ``runs`` of ``data`` (whole rows, rows shared
    by neighbouring runs written once; all of it when they cover most of it)."""
    if (runs[:, 1] - runs[:, 0]).sum() > WHOLE_SHARE * len(data) or len(runs) > MAX_WRITES:
        _write_texture(tex, data)
        return
    w = TEXTURE_WIDTH
    rows = np.stack([runs[:, 0] // w, (runs[:, 1] + w - 1) // w], axis=1)
    for r0, r1 in joined(rows):
        if r1 > r0:
            _write_texture(tex, data[r0 * w : min(r1 * w, len(data))], int(r0))
