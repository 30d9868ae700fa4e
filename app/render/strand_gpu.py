"""GPU copies of one groom's strands for the GL line methods of :mod:`app.render.strands`.

Positions live in two GPU forms: a vertex buffer (the ``"thin"`` and ``"geometry"`` draws read it
as an attribute) and an RGBA32F texture with t in alpha (the ``"quads"`` draw pulls both ends of a
segment from it), besides the float32 copy on the CPU that the ``"cpu"`` method rasterizes. While
a brush drags, :meth:`PointSet.write` uploads only the form the last draw used (none after a CPU
draw) and marks the others stale; a draw with another method refreshes its form first. Index
buffers are made once per topology, when a method first needs them.
"""

from __future__ import annotations

import moderngl
import numpy as np
from numpy.typing import NDArray

from hairtool.groom import Topology

RESTART_INDEX = 0xFFFFFFFF
TEXTURE_WIDTH = 4096  # texels per row of the point and colour textures (vertex v at v % W, v // W)
_QUAD_CORNERS = np.array([0, 1, 2, 2, 1, 3], dtype=np.uint32)


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
        self._index: dict[str, moderngl.Buffer] = {}

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

    def colors_written(self) -> None:
        """:attr:`colors` were written in place (e.g. shaded straight into them): upload them
        before the next GL draw that reads them."""
        self._color_buffer_stale = self._color_texture_stale = True

    def sync_color_buffer(self) -> None:
        """Bring the colour vertex buffer up to date before a draw that reads it."""
        buffer = self.color_buffer  # made, and marked stale, on first use
        if self._color_buffer_stale:
            buffer.write(self._colors)
            self._color_buffer_stale = False

    def color_texture(self) -> moderngl.Texture:
        if self._color_texture is None:
            self._color_texture = _texture(self.ctx, self.topology.vertex_count, 3)
            self._color_texture_stale = True
        if self._color_texture_stale:
            _write_texture(self._color_texture, self._colors)
            self._color_texture_stale = False
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
        self.last_used = "buffer"  # the form the last draw read ("buffer", "texture", "cpu")

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

    def write(self, points: NDArray[np.float32]) -> None:
        """New positions (same topology): upload the form in use now, the other when needed."""
        self._points[:] = points
        self._stale = {"buffer": True, "texture": True}
        if self.last_used == "buffer":
            self.vertex_buffer()
        elif self.last_used == "texture" and self._texture is not None:
            self.texture()

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
            buffer.write(self._points)
            self._stale["buffer"] = False
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
            self._stale["texture"] = False
        return self._texture

    def release(self) -> None:
        if self._buffer is not None:
            self._buffer.release()
            self._buffer = None
        if self._texture is not None:
            self._texture.release()
            self._texture = None
            self._texels = None


def _texture(ctx: moderngl.Context, v: int, components: int) -> moderngl.Texture:
    tex = ctx.texture((TEXTURE_WIDTH, _rows(v)), components, dtype="f4")
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    tex.repeat_x = tex.repeat_y = False
    return tex


def _write_texture(tex: moderngl.Texture, data: NDArray[np.float32]) -> None:
    """Rows of ``data`` (``(n, components)``) into the texture, vertex v at (v % W, v // W)."""
    rows = tex.height
    c = tex.components
    if len(data) == rows * TEXTURE_WIDTH:
        tex.write(np.ascontiguousarray(data))
        return
    full = len(data) // TEXTURE_WIDTH
    if full:
        tex.write(np.ascontiguousarray(data[: full * TEXTURE_WIDTH]), viewport=(0, 0, TEXTURE_WIDTH, full))
    rest = len(data) - full * TEXTURE_WIDTH
    if rest:
        tail = np.ascontiguousarray(data[full * TEXTURE_WIDTH :], np.float32).reshape(rest, c)
        tex.write(tail, viewport=(0, full, rest, 1))
