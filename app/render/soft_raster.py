"""Strands rasterized on the CPU, for software OpenGL ("compute raster", as hair renderers do for
thin strands): an RGBA8 colour image and a float32 depth image, row 0 at the bottom as in GL.

Mesa's llvmpipe pays a fixed setup and binning cost for every line or triangle whatever its size,
so a groom of short segments is bound by its primitive count; here a segment costs little more
than its pixels. :mod:`app.render.raster_layer` puts the images into the GL frame.

The definition, shared by the kernels and :func:`rasterize_reference` (float64 throughout):

- clip = [x, y, z, 1] @ mvp (pyrr's row-major matrix, as the shaders' ``u_mvp * vec4(p, 1)``); a
  segment is cut at w = :data:`W_MIN` before the divide, as ``shaders/strands.glsl`` does; window
  x = (x·(1/w) + 1)·W/2, y likewise with H, depth = (z·(1/w) + 1)/2.
- width ≤ 1: one pixel per pixel centre of the major axis whose t = (centre − a)·(1/(b − a)) lies
  in [0, 1): the pixel holding the line's point at t.
- wider: the geometry shader's quad, ``width`` across and half a width past each end; each row
  gets the pixel centres between the quad's sides there (:func:`_slab`), bottom and left sides
  in, top and right out; t runs from 0 to 1 over the quad's length (clamped), as the shader's
  corner colours do.
- colour and depth linear in t; fragments with depth outside [0, 1] dropped; depth test LESS in
  float32, segments in index order (ties keep the first drawn); colour rounded, alpha 255.

Threads own bands of whole rows (no pixel has two writers) and every fragment is computed from
its own segment alone, so the bytes are the same whatever the thread count or the bands.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError

W_MIN = 1e-5  # as the geometry shader: an end nearer the eye plane than this is cut there
DIR_EPS = 1e-6  # as the geometry shader: shorter segments are drawn in direction (1, 0)
AXIS_EPS = 1e-12  # a quad side this close to horizontal bounds rows, not columns
OPAQUE = 0xFF000000
_SEG = 12  # per segment: window x, y, depth of both ends, then both ends' RGB × 255


@njit(cache=True, nogil=True, inline="always")
def _project(points, v, m):
    x, y, z = np.float64(points[v, 0]), np.float64(points[v, 1]), np.float64(points[v, 2])
    return (
        x * m[0, 0] + y * m[1, 0] + z * m[2, 0] + m[3, 0],
        x * m[0, 1] + y * m[1, 1] + z * m[2, 1] + m[3, 1],
        x * m[0, 2] + y * m[1, 2] + z * m[2, 2] + m[3, 2],
        x * m[0, 3] + y * m[1, 3] + z * m[2, 3] + m[3, 3],
    )


@njit(cache=True, nogil=True, inline="always")
def _unit(c):
    """A colour channel as float64 (numba's float() keeps float32), clamped to [0, 1]."""
    return min(max(np.float64(c), 0.0), 1.0)


@njit(cache=True, nogil=True, parallel=True)
def _setup_kernel(points, starts, colors, m, w, h, margin, seg, lo, hi):
    """Window coordinates and colours of every segment's ends, and the rows ``lo … hi`` it may
    touch (``lo > hi``: none, e.g. wholly behind the eye or off the image)."""
    for i in prange(starts.size):
        lo[i], hi[i] = 0, -1
        a = starts[i]
        ax, ay, az, aw = _project(points, a, m)
        bx, by, bz, bw = _project(points, a + 1, m)
        if aw < W_MIN and bw < W_MIN:
            continue
        cr, cg, cb = _unit(colors[a, 0]), _unit(colors[a, 1]), _unit(colors[a, 2])
        dr, dg, db = _unit(colors[a + 1, 0]), _unit(colors[a + 1, 1]), _unit(colors[a + 1, 2])
        if aw < W_MIN:  # cut the end behind the eye (at most one end is)
            s = (W_MIN - aw) / (bw - aw)
            ax, ay, az, aw = ax + s * (bx - ax), ay + s * (by - ay), az + s * (bz - az), aw + s * (bw - aw)
            cr, cg, cb = cr + s * (dr - cr), cg + s * (dg - cg), cb + s * (db - cb)
        elif bw < W_MIN:
            s = (W_MIN - bw) / (aw - bw)
            bx, by, bz, bw = bx + s * (ax - bx), by + s * (ay - by), bz + s * (az - bz), bw + s * (aw - bw)
            dr, dg, db = dr + s * (cr - dr), dg + s * (cg - dg), db + s * (cb - db)
        ia, ib = 1.0 / aw, 1.0 / bw
        xa, ya = (ax * ia + 1.0) * 0.5 * w, (ay * ia + 1.0) * 0.5 * h
        xb, yb = (bx * ib + 1.0) * 0.5 * w, (by * ib + 1.0) * 0.5 * h
        seg[i, 0], seg[i, 1], seg[i, 2] = xa, ya, (az * ia + 1.0) * 0.5
        seg[i, 3], seg[i, 4], seg[i, 5] = xb, yb, (bz * ib + 1.0) * 0.5
        seg[i, 6], seg[i, 7], seg[i, 8] = 255.0 * cr, 255.0 * cg, 255.0 * cb
        seg[i, 9], seg[i, 10], seg[i, 11] = 255.0 * dr, 255.0 * dg, 255.0 * db
        x0, x1 = min(xa, xb) - margin, max(xa, xb) + margin
        y0, y1 = min(ya, yb) - margin, max(ya, yb) + margin
        if x1 >= 0.0 and x0 <= w and y1 >= 0.0 and y0 <= h:
            lo[i], hi[i] = int(max(y0, 0.0)), int(min(y1, h - 1.0))


@njit(cache=True, nogil=True)
def _cover_steps(lo, hi, h):
    """+1 where each segment's rows ``lo … hi`` start, −1 after they end (0 … −1: none, cancels)."""
    steps = np.zeros(h + 1, np.int64)
    for i in range(lo.size):
        steps[lo[i]] += 1
        steps[hi[i] + 1] -= 1
    return steps


def band_bounds(lo: NDArray[np.int32], hi: NDArray[np.int32], h: int, n: int) -> NDArray[np.int64]:
    """``n + 1`` row boundaries: n bands of about equal work, counted as one per row plus one per
    (segment, row) pair, from each segment's rows ``lo … hi``."""
    work = np.cumsum(np.cumsum(_cover_steps(lo, hi, h))[:h] + 1)
    bounds = np.searchsorted(work * n, work[-1] * np.arange(1, n), side="left") + 1
    return np.concatenate([[0], np.minimum(bounds, h), [h]]).astype(np.int64)


@njit(cache=True, nogil=True, inline="always")
def _plot(t, r, c, z0, dz, c0, c1, c2, d0, d1, d2, rgba, depth):
    z = z0 + t * dz
    if 0.0 <= z <= 1.0:
        z32 = np.float32(z)
        if z32 < depth[r, c]:
            depth[r, c] = z32
            red, green, blue = int(c0 + t * d0 + 0.5), int(c1 + t * d1 + 0.5), int(c2 + t * d2 + 0.5)
            rgba[r, c] = red | (green << 8) | (blue << 16) | OPAQUE


@njit(cache=True, nogil=True, inline="always")
def _index(v, lo, hi):
    """``v`` (a float, maybe huge) as an int clamped to [lo, hi]."""
    return int(min(max(v, float(lo)), float(hi)))


@njit(cache=True, nogil=True, inline="always")
def _slab(u, v, a0, a1):
    """The x with a0 ≤ x·u + q·v ≤ a1 as ``lo + q·k ≤ x ≤ hi + q·k``; no bound for u ≈ 0 (the
    quad's rows bound it)."""
    if abs(u) <= AXIS_EPS:
        return -np.inf, np.inf, 0.0
    iu = 1.0 / u
    return (a0 * iu, a1 * iu, -v * iu) if u > 0.0 else (a1 * iu, a0 * iu, -v * iu)


@njit(cache=True, nogil=True, inline="always")
def _line(seg, i, r0, r1, rgba, depth):
    """Segment i's 1-px line, in rows [r0, r1)."""
    xa, ya, z0, xb, yb, z1 = seg[i, 0], seg[i, 1], seg[i, 2], seg[i, 3], seg[i, 4], seg[i, 5]
    c0, c1, c2 = seg[i, 6], seg[i, 7], seg[i, 8]
    d0, d1, d2 = seg[i, 9] - c0, seg[i, 10] - c1, seg[i, 11] - c2
    dx, dy = xb - xa, yb - ya
    w = rgba.shape[1]
    if abs(dx) >= abs(dy):
        if dx == 0.0:
            return
        inv = 1.0 / dx
        x0, x1 = min(xa, xb), max(xa, xb)
        if dy != 0.0:  # only the columns whose rows may fall in [r0, r1), 2 px to spare
            xs, xe = xa + (r0 - ya) / dy * dx, xa + (r1 - ya) / dy * dx
            x0, x1 = max(x0, min(xs, xe) - 2.0), min(x1, max(xs, xe) + 2.0)
        for c in range(_index(np.floor(x0 - 0.5), 0, w), _index(np.floor(x1 - 0.5) + 1.0, 0, w)):
            t = (c + 0.5 - xa) * inv
            if 0.0 <= t < 1.0:
                y = ya + t * dy
                if r0 <= y < r1:
                    _plot(t, int(y), c, z0, z1 - z0, c0, c1, c2, d0, d1, d2, rgba, depth)
    else:
        inv = 1.0 / dy
        first = _index(np.floor(min(ya, yb) - 0.5), r0, r1)
        for r in range(first, _index(np.floor(max(ya, yb) - 0.5) + 1.0, r0, r1)):
            t = (r + 0.5 - ya) * inv
            if 0.0 <= t < 1.0:
                x = xa + t * dx
                if 0.0 <= x < w:
                    _plot(t, r, int(x), z0, z1 - z0, c0, c1, c2, d0, d1, d2, rgba, depth)


@njit(cache=True, nogil=True, inline="always")
def _direction(dx, dy):
    """``(ux, uy, length)``: as the geometry shader, (1, 0) for segments shorter than DIR_EPS."""
    length = math.sqrt(dx * dx + dy * dy)
    if length > DIR_EPS:
        il = 1.0 / length
        return dx * il, dy * il, length
    return 1.0, 0.0, length


@njit(cache=True, nogil=True, inline="always")
def _corner_rows(ya, yb, ux, uy, half):
    """The lowest and highest y of the quad's corners (a − h·u ± h·n, b + h·u ± h·n)."""
    across = abs(ux) * half
    return min(ya - uy * half, yb + uy * half) - across, max(ya - uy * half, yb + uy * half) + across


@njit(cache=True, nogil=True, inline="always")
def _quad(seg, i, half, r0, r1, rgba, depth):
    """Segment i's quad (the geometry shader's), in rows [r0, r1)."""
    xa, ya, z0, xb, yb, z1 = seg[i, 0], seg[i, 1], seg[i, 2], seg[i, 3], seg[i, 4], seg[i, 5]
    c0, c1, c2 = seg[i, 6], seg[i, 7], seg[i, 8]
    d0, d1, d2 = seg[i, 9] - c0, seg[i, 10] - c1, seg[i, 11] - c2
    ux, uy, length = _direction(xb - xa, yb - ya)
    # along the segment −h ≤ (p − a)·u ≤ length + h, across it |(p − a)·n| ≤ h, n = (−uy, ux)
    l1, h1, k1 = _slab(ux, uy, -half, length + half)
    l2, h2, k2 = _slab(-uy, ux, -half, half)
    # In row r the centres x − 0.5 from max(a1 + r·k1, a2 + r·k2) to min(b1 + r·k1, b2 + r·k2).
    q0, x0 = 0.5 - ya, xa - 0.5
    a1, a2, b1, b2 = x0 + l1 + q0 * k1, x0 + l2 + q0 * k2, x0 + h1 + q0 * k1, x0 + h2 + q0 * k2
    inv = 1.0 / (length + 2.0 * half)
    tr, tc = uy * inv, ux * inv
    t0 = ((0.5 - xa) * ux + half) * inv + q0 * tr  # t = t0 + r·tr + c·tc
    y0, y1 = _corner_rows(ya, yb, ux, uy, half)
    w = rgba.shape[1]
    for r in range(_index(np.ceil(y0 - 0.5), r0, r1), _index(np.ceil(y1 - 0.5), r0, r1)):
        left, right = max(a1 + r * k1, a2 + r * k2), min(b1 + r * k1, b2 + r * k2)
        tt = t0 + r * tr
        for c in range(_index(np.ceil(left), 0, w), _index(np.ceil(right), 0, w)):
            t = min(max(tt + c * tc, 0.0), 1.0)
            _plot(t, r, c, z0, z1 - z0, c0, c1, c2, d0, d1, d2, rgba, depth)


@njit(cache=True, nogil=True, parallel=True)
def _draw_lines(seg, lo, hi, bounds, clear, background, rgba, depth):
    """Each band of rows: cleared (when ``clear``), then its segments' 1-px lines in index order."""
    for k in prange(bounds.size - 1):
        r0, r1 = bounds[k], bounds[k + 1]
        if clear:
            rgba[r0:r1] = background
            depth[r0:r1] = 1.0
        for i in range(lo.size):
            if lo[i] < r1 and hi[i] >= r0:
                _line(seg, i, r0, r1, rgba, depth)


@njit(cache=True, nogil=True, parallel=True)
def _draw_quads(seg, lo, hi, bounds, half, clear, background, rgba, depth):
    """As :func:`_draw_lines`, the segments' quads of half-width ``half`` (two kernels: each
    compiles in seconds, the first draw only needs one)."""
    for k in prange(bounds.size - 1):
        r0, r1 = bounds[k], bounds[k + 1]
        if clear:
            rgba[r0:r1] = background
            depth[r0:r1] = 1.0
        for i in range(lo.size):
            if lo[i] < r1 and hi[i] >= r0:
                _quad(seg, i, half, r0, r1, rgba, depth)


def draw_bands(seg, lo, hi, bounds, half, clear, background, rgba, depth) -> None:
    """The segments (after :func:`_setup_kernel`) into the images, one thread per band."""
    if half > 0.0:
        _draw_quads(seg, lo, hi, bounds, half, clear, background, rgba, depth)
    else:
        _draw_lines(seg, lo, hi, bounds, clear, background, rgba, depth)


def _check(points, starts, colors, mvp, size, width):
    p = np.asarray(points)
    if p.dtype != np.float32:
        p = p.astype(np.float32)
    s = np.ascontiguousarray(starts, np.int64)
    c = np.asarray(colors, np.float32)
    m = np.ascontiguousarray(mvp, np.float64)
    w, h = (int(v) for v in size)
    if p.ndim != 2 or p.shape[1] != 3 or c.shape != p.shape:
        raise ParameterError("points, colors", f"{p.shape}, {c.shape}", "(V, 3) and (V, 3)")
    if m.shape != (4, 4):
        raise ParameterError("mvp", m.shape, "a (4, 4) matrix")
    if s.size and (s.min() < 0 or s.max() + 1 >= len(p)):
        raise ParameterError("starts", f"[{s.min()}, {s.max()}]", f"segment starts in [0, {len(p) - 1})")
    if w < 1 or h < 1:
        raise ParameterError("size", size, "(W, H) of at least one pixel")
    if not width > 0:
        raise ParameterError("width", width, "a positive width in pixels")
    return p, s, c, m, w, h, float(width)


class StrandRaster:
    """:meth:`draw` into images kept between calls (made again only when the size changes)."""

    def __init__(self) -> None:
        self._rgba32 = np.zeros((0, 0), np.uint32)  # the kernels write whole pixels
        self.rgba = self._rgba32.view(np.uint8).reshape(0, 0, 4)
        self.depth = np.zeros((0, 0), np.float32)
        self._seg = np.zeros((0, _SEG))
        self._rows = np.zeros((2, 0), np.int32)

    def images(self, size: tuple[int, int]) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
        """The ``(H, W, 4)`` colour and ``(H, W)`` depth images, resized to ``size = (W, H)``."""
        w, h = (int(v) for v in size)
        if self.depth.shape != (h, w):
            self._rgba32 = np.zeros((h, w), np.uint32)
            self.rgba = self._rgba32.view(np.uint8).reshape(h, w, 4)
            self.depth = np.ones((h, w), np.float32)
        return self.rgba, self.depth

    def draw(
        self,
        points: ArrayLike,
        starts: ArrayLike,
        colors: ArrayLike,
        mvp: ArrayLike,
        size: tuple[int, int],
        width: float,
        clear: tuple[int, int, int, int] | None = (0, 0, 0, 0),
    ) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
        """Segments ``starts[i] → starts[i] + 1`` of ``points`` ``(V, 3)``, coloured by per-vertex
        RGB ``colors`` in [0, 1], seen through ``mvp``, into ``size = (W, H)`` images; ``width``
        in pixels (≤ 1: 1-px lines). The images are first cleared to the RGBA bytes ``clear`` and
        depth 1.0, or with ``clear=None`` drawn over as they are (see :meth:`images`).
        Returns :meth:`images`; the next draw overwrites them."""
        p, s, c, m, w, h, width = _check(points, starts, colors, mvp, size, width)
        rgba, depth = self.images((w, h))
        if self._seg.shape[0] < s.size:
            self._seg = np.empty((s.size, _SEG))
            self._rows = np.empty((2, s.size), np.int32)
        seg, lo, hi = self._seg[: s.size], self._rows[0, : s.size], self._rows[1, : s.size]
        half = 0.0 if width <= 1.0 else 0.5 * width
        _setup_kernel(p, s, c, m, w, h, 1.5 * half + 1.0, seg, lo, hi)
        # One band per thread: more, smaller bands cut more segments in two, which cost more
        # than the better balance gained.
        bounds = band_bounds(lo, hi, h, numba.get_num_threads())
        fill = np.array(clear if clear is not None else (0, 0, 0, 0), np.uint8).view(np.uint32)[0]
        draw_bands(seg, lo, hi, bounds, half, clear is not None, fill, self._rgba32, depth)
        return rgba, depth


def rasterize(
    points: ArrayLike,
    starts: ArrayLike,
    colors: ArrayLike,
    mvp: ArrayLike,
    size: tuple[int, int],
    width: float,
) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
    """:meth:`StrandRaster.draw` into fresh images."""
    return StrandRaster().draw(points, starts, colors, mvp, size, width)


def rasterize_reference(
    points: ArrayLike,
    starts: ArrayLike,
    colors: ArrayLike,
    mvp: ArrayLike,
    size: tuple[int, int],
    width: float,
) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
    """The definition in the module doc in numpy, one segment at a time over the whole image
    (small inputs): the oracle the kernels are tested against."""
    p, s, c, m, w, h, width = _check(points, starts, colors, mvp, size, width)
    half = 0.0 if width <= 1.0 else 0.5 * width
    p = p.astype(np.float64)
    clip = p[:, :1] * m[0] + p[:, 1:2] * m[1] + p[:, 2:3] * m[2] + m[3]
    rgb = np.clip(c.astype(np.float64), 0.0, 1.0)
    rgba = np.zeros((h, w, 4), np.uint8)
    depth = np.ones((h, w), np.float32)
    scale = np.array([0.5 * w, 0.5 * h, 0.5])
    for a in s:
        ea, eb, ca, cb = clip[a], clip[a + 1], rgb[a], rgb[a + 1]
        if ea[3] < W_MIN and eb[3] < W_MIN:
            continue
        if ea[3] < W_MIN:
            f = (W_MIN - ea[3]) / (eb[3] - ea[3])
            ea, ca = ea + f * (eb - ea), ca + f * (cb - ca)
        elif eb[3] < W_MIN:
            f = (W_MIN - eb[3]) / (ea[3] - eb[3])
            eb, cb = eb + f * (ea - eb), cb + f * (ca - cb)
        pa = (ea[:3] * (1.0 / ea[3]) + 1.0) * scale
        pb = (eb[:3] * (1.0 / eb[3]) + 1.0) * scale
        rows, cols, t = _quad_fragments(pa, pb, half, w, h) if half else _line_fragments(pa, pb, w, h)
        z = pa[2] + t * (pb[2] - pa[2])
        keep = (z >= 0.0) & (z <= 1.0)
        rows, cols, t, z32 = rows[keep], cols[keep], t[keep], z[keep].astype(np.float32)
        wins = z32 < depth[rows, cols]  # a segment covers a pixel at most once
        rows, cols, t = rows[wins], cols[wins], t[wins]
        depth[rows, cols] = z32[wins]
        c0, c1 = 255.0 * ca, 255.0 * cb
        rgba[rows, cols, :3] = np.floor(c0 + t[:, None] * (c1 - c0) + 0.5).astype(np.uint8)
        rgba[rows, cols, 3] = 255
    return rgba, depth


def _line_fragments(pa, pb, w, h):
    d = pb - pa
    major = 0 if abs(d[0]) >= abs(d[1]) else 1
    if d[major] == 0.0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    i = np.arange((w, h)[major])
    t = (i + 0.5 - pa[major]) * (1.0 / d[major])
    other = pa[1 - major] + t * d[1 - major]
    ok = (t >= 0.0) & (t < 1.0) & (other >= 0.0) & (other < (h, w)[major])
    i, other, t = i[ok], np.floor(other[ok]).astype(np.int64), t[ok]
    return (other, i, t) if major == 0 else (i, other, t)


def _quad_fragments(pa, pb, half, w, h):
    d = pb[:2] - pa[:2]
    length = np.sqrt(d[0] * d[0] + d[1] * d[1])
    ux, uy = (d[0] * (1.0 / length), d[1] * (1.0 / length)) if length > DIR_EPS else (1.0, 0.0)
    ends = (pa[1] - uy * half, pb[1] + uy * half)
    y0, y1 = min(ends) - abs(ux) * half, max(ends) + abs(ux) * half  # the corners' rows
    rows = np.arange(h)
    rows = rows[(rows + 0.5 >= y0) & (rows + 0.5 < y1)]
    q0, x0 = 0.5 - pa[1], pa[0] - 0.5
    left, right = np.full(rows.size, -np.inf), np.full(rows.size, np.inf)
    # Each pair of opposite sides: a0 ≤ x·u + q·v ≤ a1 for x = column centre − xa, q = row centre − ya.
    for u, v, a0, a1 in ((ux, uy, -half, length + half), (-uy, ux, -half, half)):
        if abs(u) > AXIS_EPS:
            iu = 1.0 / u
            e0, e1, k = (a0 * iu, a1 * iu, -v * iu) if u > 0 else (a1 * iu, a0 * iu, -v * iu)
            left = np.maximum(left, x0 + e0 + q0 * k + rows * k)
            right = np.minimum(right, x0 + e1 + q0 * k + rows * k)
    c0 = np.clip(np.ceil(left), 0.0, w).astype(np.int64)
    c1 = np.clip(np.ceil(right), 0.0, w).astype(np.int64)
    n = np.maximum(c1 - c0, 0)
    r = np.repeat(rows, n)
    c = np.repeat(c0, n) + np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
    inv = 1.0 / (length + 2.0 * half)
    t = ((0.5 - pa[0]) * ux + half) * inv + q0 * (uy * inv) + r * (uy * inv) + c * (ux * inv)
    return r, c, np.clip(t, 0.0, 1.0)
