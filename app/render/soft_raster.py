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
- wider: the geometry shader's quad, ``width`` across and half a width past each end, walked
  along its minor axis: a quad nearer horizontal gives each row the pixel centres between its
  sides there (:func:`_slab`), left sides in and right sides out; a steeper one (|uy| > |ux|)
  gives each column the centres between its sides, bottom in and top out (the same
  computation on the transposed image). t runs from 0 to 1 over the quad's length (clamped),
  as the shader's corner colours do.
- a width that tapers: each segment's quad ``width`` × its own scale (the caller's per-segment
  ``scale``, e.g. 1 − taper·(t_a + t_b)/2 as the shaders compute it from the vertex parameter);
- colour and depth linear in t; fragments with depth outside [0, 1] dropped; depth test LESS in
  float32, segments in index order (ties keep the first drawn); colour rounded, alpha 255.

Threads own bands of whole rows, or whole tiles (no pixel has two writers), and every fragment
is computed from its own segment alone, so the bytes are the same whatever the thread count,
the bands or the tiles. A segment that cannot pass the depth test anywhere (hair behind hair:
on a head, half of it and more) is skipped whole, which changes no byte either
(:func:`draw_bands`). That is also what lets :class:`StrandRaster` redraw only the tiles
that changed: while a brush drags, most segments project to the very same numbers as in the
last frame, and a tile none of the changed ones touch (before or after) keeps its pixels.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.kernel_arrays import readonly

W_MIN = 1e-5  # as the geometry shader: an end nearer the eye plane than this is cut there
DIR_EPS = 1e-6  # as the geometry shader: shorter segments are drawn in direction (1, 0)
AXIS_EPS = 1e-12  # a quad side this close to horizontal bounds rows, not columns
OPAQUE = 0xFF000000
SQRT2 = math.sqrt(2.0)
_NO_SCALE = np.zeros(0)  # the setup's scale when there is none (widths × 1)
_SEG = 13  # per segment: window x, y, depth of both ends, both ends' RGB × 255, its width scale
TILE_SHIFT = 5  # tiles of 2**5 = 32 pixels a side are redrawn when a frame differs little from the last
TILE = 1 << TILE_SHIFT
REDRAW_ALL = 1.0  # a full draw when the changed tiles list more (segment, tile) pairs than this × segments
MOSTLY_CHANGED = 0.25  # … or at once when more than this share of the segments changed; then the
# next 1, then 3 (MAX_UNSEARCHED) frames are drawn in full without looking for changes (render
# hair following a brush: nearly every child moves, and the search cost a third of the full
# draw); kept short, since a frame that changed nothing (the brush circle moving after a
# stroke) is then drawn in full too
MAX_UNSEARCHED = 3
HIDDEN_SHIFT = 2  # a band's farthest depth is kept per cell of 2**2 = 4 pixels a side (8: 3-9 % slower)
REFRESH_EVERY = 4096  # drawn segments between updates of the cells' farthest depths (1,024: slower)
TILE_REFRESH_EVERY = 64  # the same in a redrawn tile (replayed bear comb frames: 16-128 alike, 4 slower)


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


@njit(cache=True, nogil=True, inline="always")
def _setup_one(i, points, starts, colors, m, w, h, scale, seg, box, nearest, width, weight):
    """Segment i's row of :func:`_setup_kernel`."""
    box[0, i], box[1, i], box[2, i], box[3, i] = 0, -1, 0, -1
    seg[i, 12] = scale[i] if scale.size else 1.0
    if weight.size:
        weight[i] = 1.0 + width * seg[i, 12]
    a = np.uint64(starts[i])  # unsigned: no wrap-around test at every access (10 % of the set-up)
    b = a + np.uint64(1)
    ax, ay, az, aw = _project(points, a, m)
    bx, by, bz, bw = _project(points, b, m)
    if aw < W_MIN and bw < W_MIN:
        return
    cr, cg, cb = _unit(colors[a, 0]), _unit(colors[a, 1]), _unit(colors[a, 2])
    dr, dg, db = _unit(colors[b, 0]), _unit(colors[b, 1]), _unit(colors[b, 2])
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
    # Every fragment's z lies between the ends' (to within rounding: hence the margin).
    nearest[i] = np.float32(min(seg[i, 2], seg[i, 5]) - 1e-9)
    seg[i, 6], seg[i, 7], seg[i, 8] = 255.0 * cr, 255.0 * cg, 255.0 * cb
    seg[i, 9], seg[i, 10], seg[i, 11] = 255.0 * dr, 255.0 * dg, 255.0 * db
    reach = SQRT2 * 0.5 * width * seg[i, 12] + 0.25 if width > 0.0 else 1.0
    x0, x1 = min(xa, xb) - reach, max(xa, xb) + reach
    y0, y1 = min(ya, yb) - reach, max(ya, yb) + reach
    if x1 >= 0.0 and x0 <= w and y1 >= 0.0 and y0 <= h:
        box[0, i], box[1, i] = int(max(y0, 0.0)), int(min(y1, h - 1.0))
        box[2, i], box[3, i] = int(max(x0, 0.0)), int(min(x1, w - 1.0))


@njit(cache=True, nogil=True, parallel=True)
def _setup_kernel(points, starts, colors, m, w, h, scale, seg, box, nearest, which, width, weight):
    """Window coordinates and colours of every segment's ends and its width ``scale`` (none
    given: 1) (or of those flagged in ``which``, when it is not empty), the depth of its nearer
    end less a margin for rounding in ``nearest`` (float32: what :func:`draw_bands` compares
    with the cells' farthest depths, in an array of its own so that a segment it skips costs
    4 bytes of memory traffic, not a row of ``seg``), and the rows
    ``box[0, i] … box[1, i]`` and columns ``box[2, i] … box[3, i]`` it may touch: its ends' box
    widened by its quad's reach, h√2 for half-width h = ``width``/2 × scale, plus a quarter
    pixel for rounding (a pixel's centre lies within the quad, so the pixel within h√2 − ½;
    1-px lines, ``width`` 0: one pixel) (rows ``0 … −1``: none, e.g. wholly behind the eye or
    off the image); with a ``weight`` array, the segment's work per row for :func:`band_bounds`,
    1 + its quad's ``width`` × scale (as a numpy pass over the table's strided column it had
    cost 10 ms a full-density frame)."""
    for i in prange(starts.size):
        if which.size and not which[i]:
            continue
        _setup_one(i, points, starts, colors, m, w, h, scale, seg, box, nearest, width, weight)


@njit(cache=True, nogil=True)
def _setup_listed(points, starts, colors, m, w, h, scale, seg, box, nearest, ids, width):
    """:func:`_setup_kernel` for the segments ``ids`` alone, on the calling thread: a brush
    move's few thousand cost less than waking the thread pool (on a loaded host the parallel
    set-up, looking at every segment's flag, took 7 ms a bear comb move)."""
    none = np.zeros(0)
    for n in range(ids.size):
        _setup_one(ids[n], points, starts, colors, m, w, h, scale, seg, box, nearest, width, none)


@njit(cache=True, nogil=True)
def _cover_steps(lo, hi, h, weight):
    """+w where each segment's rows ``lo … hi`` start, −w after they end (0 … −1: none, cancels);
    w its ``weight`` (none given: 1)."""
    steps = np.zeros(h + 1)
    for i in range(lo.size):
        wi = weight[i] if weight.size else 1.0
        steps[lo[i]] += wi
        steps[hi[i] + 1] -= wi
    return steps


def band_bounds(
    lo: NDArray[np.int32], hi: NDArray[np.int32], h: int, n: int, weight: NDArray[np.float64] | None = None
) -> NDArray[np.int64]:
    """``n + 1`` row boundaries: n bands of about equal work, counted as one per row plus, per
    (segment, row) pair, the segment's ``weight`` (default 1), from each segment's rows
    ``lo … hi``."""
    w = np.zeros(0) if weight is None else np.ascontiguousarray(weight, np.float64)
    work = np.cumsum(np.cumsum(_cover_steps(lo, hi, h, w))[:h] + 1.0)
    bounds = np.searchsorted(work * n, work[-1] * np.arange(1, n), side="left") + 1
    return np.concatenate([[0], np.minimum(bounds, h), [h]]).astype(np.int64)


@njit(cache=True, nogil=True, inline="always")
def _packed(t, e0, e1, e2, d0, d1, d2):
    """The RGBA8 pixel (as a little-endian uint32) of colour e + t·d, rounded, opaque."""
    red, green, blue = int(e0 + t * d0 + 0.5), int(e1 + t * d1 + 0.5), int(e2 + t * d2 + 0.5)
    return red | (green << 8) | (blue << 16) | OPAQUE


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


# The fragment loops below write the depth test out in full: passed to an inlined helper, the
# images are reference-counted at every fragment (1.4x slower). ``rgba`` and ``depth`` are the
# images flattened (row r, column c at r·w + c); pixel indices are unsigned, so numba adds no
# wrap-around for negative ones. When both ends' depths lie in [0, 1], so does every z0 + t·dz
# with t in [0, 1] (rounding is monotone, and z0 + (1 − z0) rounds to at most 1), and the
# range test is skipped.


@njit(cache=True, nogil=True)
def _line(seg, i, r0, r1, c0, c1, rgba, depth, w):
    """Segment i's 1-px line, in rows [r0, r1) and columns [c0, c1)."""
    xa, ya, z0, xb, yb, z1 = seg[i, 0], seg[i, 1], seg[i, 2], seg[i, 3], seg[i, 4], seg[i, 5]
    e0, e1, e2 = seg[i, 6], seg[i, 7], seg[i, 8]
    d0, d1, d2 = seg[i, 9] - e0, seg[i, 10] - e1, seg[i, 11] - e2
    dx, dy, dz = xb - xa, yb - ya, z1 - z0
    inside = 0.0 <= z0 <= 1.0 and 0.0 <= z1 <= 1.0
    if abs(dx) >= abs(dy):
        if dx == 0.0:
            return
        inv = 1.0 / dx
        x0, x1 = min(xa, xb), max(xa, xb)
        if dy != 0.0:  # only the columns whose rows may fall in [r0, r1), 2 px to spare
            xs, xe = xa + (r0 - ya) / dy * dx, xa + (r1 - ya) / dy * dx
            x0, x1 = max(x0, min(xs, xe) - 2.0), min(x1, max(xs, xe) + 2.0)
        for c in range(_index(np.floor(x0 - 0.5), c0, c1), _index(np.floor(x1 - 0.5) + 1.0, c0, c1)):
            t = (c + 0.5 - xa) * inv
            if 0.0 <= t < 1.0:
                y = ya + t * dy
                z = z0 + t * dz
                if r0 <= y < r1 and (inside or 0.0 <= z <= 1.0):
                    k, z32 = np.uint64(int(y) * w + c), np.float32(z)
                    if z32 < depth[k]:
                        depth[k] = z32
                        rgba[k] = _packed(t, e0, e1, e2, d0, d1, d2)
    else:
        inv = 1.0 / dy
        for r in range(
            _index(np.floor(min(ya, yb) - 0.5), r0, r1), _index(np.floor(max(ya, yb) - 0.5) + 1.0, r0, r1)
        ):
            t = (r + 0.5 - ya) * inv
            if 0.0 <= t < 1.0:
                x = xa + t * dx
                z = z0 + t * dz
                if c0 <= x < c1 and (inside or 0.0 <= z <= 1.0):
                    k, z32 = np.uint64(r * w + int(x)), np.float32(z)
                    if z32 < depth[k]:
                        depth[k] = z32
                        rgba[k] = _packed(t, e0, e1, e2, d0, d1, d2)


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


@njit(cache=True, nogil=True)
def _quad(seg, i, half, r0, r1, c0, c1, rgba, depth, w):
    """Segment i's quad (the geometry shader's), in rows [r0, r1) and columns [c0, c1): by rows
    of pixels, or for a steep quad by columns (x and y swapped, the same arithmetic)."""
    xa, ya, z0, xb, yb, z1 = seg[i, 0], seg[i, 1], seg[i, 2], seg[i, 3], seg[i, 4], seg[i, 5]
    e0, e1, e2 = seg[i, 6], seg[i, 7], seg[i, 8]
    d0, d1, d2 = seg[i, 9] - e0, seg[i, 10] - e1, seg[i, 11] - e2
    dz = z1 - z0
    ux, uy, length = _direction(xb - xa, yb - ya)
    # "lines" o of pixels across the minor axis, pixels n along them; pixel index o·so + n·sn
    o0, o1, n0, n1, so, sn = r0, r1, c0, c1, w, 1
    if abs(uy) > abs(ux):
        xa, ya, xb, yb, ux, uy = ya, xa, yb, xb, uy, ux
        o0, o1, n0, n1, so, sn = c0, c1, r0, r1, 1, w
    # along the segment −h ≤ (p − a)·u ≤ length + h, across it |(p − a)·n| ≤ h, n = (−uy, ux)
    l1, h1, k1 = _slab(ux, uy, -half, length + half)
    l2, h2, k2 = _slab(-uy, ux, -half, half)
    # On line o the centres n + 0.5 from max(a1 + o·k1, a2 + o·k2) to min(b1 + o·k1, b2 + o·k2).
    q0, x0 = 0.5 - ya, xa - 0.5
    a1, a2, b1, b2 = x0 + l1 + q0 * k1, x0 + l2 + q0 * k2, x0 + h1 + q0 * k1, x0 + h2 + q0 * k2
    inv = 1.0 / (length + 2.0 * half)
    tr, tc = uy * inv, ux * inv
    t0 = ((0.5 - xa) * ux + half) * inv + q0 * tr  # t = t0 + o·tr + n·tc
    y0, y1 = _corner_rows(ya, yb, ux, uy, half)
    inside = 0.0 <= z0 <= 1.0 and 0.0 <= z1 <= 1.0
    for o in range(_index(np.ceil(y0 - 0.5), o0, o1), _index(np.ceil(y1 - 0.5), o0, o1)):
        left, right = max(a1 + o * k1, a2 + o * k2), min(b1 + o * k1, b2 + o * k2)
        tt = t0 + o * tr
        base = o * so
        for n in range(_index(np.ceil(left), n0, n1), _index(np.ceil(right), n0, n1)):
            t = min(max(tt + n * tc, 0.0), 1.0)
            z = z0 + t * dz
            if inside or 0.0 <= z <= 1.0:
                k, z32 = np.uint64(base + n * sn), np.float32(z)
                if z32 < depth[k]:
                    depth[k] = z32
                    rgba[k] = _packed(t, e0, e1, e2, d0, d1, d2)


@njit(cache=True, nogil=True)
def _segment(seg, i, half, r0, r1, c0, c1, rgba, depth, w):
    if half > 0.0:
        _quad(seg, i, half * seg[i, 12], r0, r1, c0, c1, rgba, depth, w)
    else:
        _line(seg, i, r0, r1, c0, c1, rgba, depth, w)


@njit(cache=True, nogil=True)
def _refresh_farthest(bits, r0, r1, farthest, stale):
    """``farthest[ty, tx]``: the largest depth in each ``stale`` cell of the band of rows from
    ``r0``, not past ``r1``, of the depth image's int32 view ``bits`` (:func:`_refresh_tile` over
    the whole width)."""
    _refresh_tile(bits, r0, r1, 0, bits.shape[1], farthest, stale)


@njit(cache=True, nogil=True, parallel=True)
def draw_bands(seg, box, nearest, bounds, half, clear, background, rgba, depth, refresh_every):
    """The segments (after :func:`_setup_kernel`) into the images, one task per band of rows:
    cleared (when ``clear``), then its segments in index order; ``half`` the quads' half-width
    (0: 1-px lines). Returns how many (segment, band) pairs were skipped as hidden.

    Hidden segments are skipped whole: each band keeps, per cell of 2**HIDDEN_SHIFT pixels, the
    farthest depth in it (brought up to date every ``refresh_every`` drawn segments, for the
    cells they touched); a segment whose nearer end (``nearest``) lies beyond the farthest depth
    of every cell its box touches would fail the depth test at each of its pixels, since depths
    only decrease as a draw goes on. Skipping it leaves the bytes as they were (the reference
    draws it and changes nothing); on the studio's render hair it skips 55 % of a drag frame's
    segments, 77 % of a full-density one's (hair on the far side of the head, behind the hair in
    front). A box of at most 3 × 3 cells, most of them, is read as nine cells without a loop
    (repeating a row or column where it has fewer), where nested loops' exits mispredicted on
    every segment; that and ``nearest`` in an array of its own made the bands 12-16 % faster."""
    w = depth.shape[1]
    flat_rgba, flat_depth = rgba.reshape(-1), depth.reshape(-1)
    bits = depth.view(np.int32)
    shift = HIDDEN_SHIFT
    hidden = np.zeros(max(bounds.size - 1, 0), np.int64)
    for k in prange(bounds.size - 1):
        r0, r1 = bounds[k], bounds[k + 1]
        if clear:
            rgba[r0:r1] = background
            depth[r0:r1] = 1.0
        if r1 <= r0:
            continue
        farthest = np.empty((((r1 - r0 - 1) >> shift) + 1, ((w - 1) >> shift) + 1), np.int32)
        nx = farthest.shape[1]
        far_of = farthest.view(np.float32).reshape(-1)  # cell ty·nx + tx, unsigned: no wrap-around tests
        stale = np.ones(farthest.shape, np.bool_)
        to_refresh = stale.reshape(-1)
        _refresh_farthest(bits, r0, r1, farthest, stale)
        drawn = 0
        skipped = 0
        for i in range(box.shape[1]):
            if box[0, i] >= r1 or box[1, i] < r0:
                continue
            ty0, ty1 = (max(box[0, i], r0) - r0) >> shift, (min(box[1, i], r1 - 1) - r0) >> shift
            tx0, tx1 = box[2, i] >> shift, box[3, i] >> shift
            if ty1 - ty0 <= 2 and tx1 - tx0 <= 2:
                ya, yb, yc = np.uint64(ty0 * nx), np.uint64(min(ty0 + 1, ty1) * nx), np.uint64(ty1 * nx)
                xa, xb, xc = np.uint64(tx0), np.uint64(min(tx0 + 1, tx1)), np.uint64(tx1)
                far = max(
                    max(max(far_of[ya + xa], far_of[ya + xb]), far_of[ya + xc]),
                    max(max(far_of[yb + xa], far_of[yb + xb]), far_of[yb + xc]),
                )
                far = max(far, max(max(far_of[yc + xa], far_of[yc + xb]), far_of[yc + xc]))
            else:
                far = np.float32(0.0)
                for ty in range(ty0, ty1 + 1):
                    for tx in range(tx0, tx1 + 1):
                        far = max(far, far_of[np.uint64(ty * nx + tx)])
            if nearest[i] >= far:
                skipped += 1
                continue
            _segment(seg, i, half, r0, r1, 0, w, flat_rgba, flat_depth, w)
            for ty in range(ty0, ty1 + 1):
                for tx in range(tx0, tx1 + 1):
                    to_refresh[np.uint64(ty * nx + tx)] = True
            drawn += 1
            if drawn == refresh_every:
                _refresh_farthest(bits, r0, r1, farthest, stale)
                drawn = 0
        hidden[k] = skipped
    return hidden.sum()


@njit(cache=True, nogil=True, inline="always")
def _sync_vertex(a, b, c, d, i):
    """Whether vertex ``i``'s position ``a`` or colour ``c`` differs from the last (``b``, ``d``;
    all viewed as uint32: bit for bit), the last brought up to date where it does."""
    differ = False
    for k in range(3):
        differ |= (a[i, k] != b[i, k]) | (c[i, k] != d[i, k])
    if differ:
        for k in range(3):
            b[i, k], d[i, k] = a[i, k], c[i, k]
    return differ


@njit(cache=True, nogil=True, parallel=True)
def _changed_vertices(points, colors, last_points, last_colors, flags):
    """Flag the vertices whose position or colour differs from the last, bit for bit, and
    bring the last ones up to date."""
    a, b = points.view(np.uint32), last_points.view(np.uint32)
    c, d = colors.view(np.uint32), last_colors.view(np.uint32)
    for i in prange(points.shape[0]):
        flags[i] = _sync_vertex(a, b, c, d, i)


@njit(cache=True, nogil=True)
def _changed_in_runs(points, colors, last_points, last_colors, starts, runs, seg_runs, flags, which):
    """:func:`_changed_vertices` and :func:`_changed_ends` for the vertices of ``runs`` alone
    (``(R, 2)`` sorted disjoint ranges [a, b) outside which nothing changed), each run's segments
    ``seg_runs[r, 0] … seg_runs[r, 1] − 1`` (those with an end in it; ``starts`` increasing):
    ``which`` (all False before) flags the changed ones; returns how many. Serial: a brush's
    region is a few thousand vertices, fewer than a thread start is worth."""
    a32, b32 = points.view(np.uint32), last_points.view(np.uint32)
    c32, d32 = colors.view(np.uint32), last_colors.view(np.uint32)
    n = 0
    for r in range(runs.shape[0]):
        a, b = runs[r, 0], runs[r, 1]
        for v in range(a, b):
            flags[v] = _sync_vertex(a32, b32, c32, d32, v)
        for i in range(seg_runs[r, 0], seg_runs[r, 1]):
            s = starts[i]
            changed = (s >= a and flags[s]) or (s + 1 < b and flags[s + 1])
            if changed and not which[i]:
                which[i] = True
                n += 1
    return n


def changed_in_runs_reference(points, colors, last_points, last_colors, starts, runs):
    """:func:`_changed_in_runs` in numpy over the whole groom: the segments with an end inside
    ``runs`` whose position or colour differs bit for bit; the last arrays brought up to date
    there. Returns the flags (the oracle of the tests)."""
    inside = np.zeros(len(points) + 1, np.int64)
    for a, b in runs:
        inside[a] += 1
        inside[b] -= 1
    inside = np.cumsum(inside)[:-1] > 0
    bits = [np.ascontiguousarray(x).view(np.uint32) for x in (points, last_points, colors, last_colors)]
    differ = inside & ((bits[0] != bits[1]).any(axis=1) | (bits[2] != bits[3]).any(axis=1))
    last_points[differ], last_colors[differ] = points[differ], colors[differ]
    return differ[starts] | differ[starts + 1]


def merged_runs(runs: ArrayLike, v: int) -> NDArray[np.int64]:
    """``(R, 2)`` vertex ranges [a, b) of ``v`` vertices, sorted and those that overlap or touch
    merged; a range outside [0, v] or reversed is refused, naming ``changed``."""
    r = np.asarray(runs, np.int64).reshape(-1, 2) if np.size(runs) else np.zeros((0, 2), np.int64)
    if r.size and (r.min() < 0 or r[:, 1].max() > v or np.any(r[:, 1] < r[:, 0])):
        raise ParameterError("changed", "a vertex range out of order or out of range", f"[a, b) in [0, {v}]")
    r = r[np.argsort(r[:, 0], kind="stable")]
    if len(r) < 2:
        return r
    reach = np.maximum.accumulate(r[:, 1])
    first = np.concatenate([[True], r[1:, 0] > reach[:-1]])
    starts_at = np.flatnonzero(first)
    ends = reach[np.concatenate([starts_at[1:] - 1, [len(r) - 1]])]
    return np.stack([r[starts_at, 0], ends], axis=1)


@njit(cache=True, nogil=True, parallel=True)
def _changed_ends(starts, flags, which):
    """Flag the segments with an end among the flagged vertices; returns how many."""
    n = 0
    for i in prange(starts.size):
        changed = flags[starts[i]] | flags[starts[i] + 1]
        which[i] = changed
        n += changed
    return n


@njit(cache=True, nogil=True)
def _mark_tiles(bx, which, dirty, shift):
    """Mark the tiles of ``dirty`` (rows × columns of tiles 2**shift pixels wide) under the boxes
    ``bx`` of the segments ``which``. Returns how many segments were marked."""
    marked = 0
    for i in range(which.size):
        if not which[i]:
            continue
        marked += 1
        if bx[0, i] <= bx[1, i]:
            for ty in range(bx[0, i] >> shift, (bx[1, i] >> shift) + 1):
                for tx in range(bx[2, i] >> shift, (bx[3, i] >> shift) + 1):
                    dirty[ty, tx] = True
    return marked


@njit(cache=True, nogil=True, inline="always")
def _tile_span(box, i, shift, span):
    """The tiles (rows ty0 … ty1, columns tx0 … tx1) segment i's box touches, cut to ``span``
    (the same four for the tiles that matter); ty0 > ty1 when it touches none of them. Shifts,
    not divisions: two per coordinate cost 4 ms over 100,000 segments."""
    if box[0, i] > box[1, i]:
        return 1, 0, 0, -1
    ty0, ty1 = max(box[0, i] >> shift, span[0]), min(box[1, i] >> shift, span[1])
    tx0, tx1 = max(box[2, i] >> shift, span[2]), min(box[3, i] >> shift, span[3])
    if tx0 > tx1:
        return 1, 0, 0, -1
    return ty0, ty1, tx0, tx1


@njit(cache=True, nogil=True)
def _bin_segments(box, dirty, shift, counts, entries, near):
    """Per dirty tile (row-major index), the segments whose box touches it, in index order (CSR:
    ``counts`` (tiles + 1,) filled here; ``entries`` filled when large enough; ``near`` (E,)
    scratch). Returns the number of entries."""
    tiles_x = dirty.shape[1]
    rows, cols = np.flatnonzero(dirty.sum(axis=1)), np.flatnonzero(dirty.sum(axis=0))
    counts[:] = 0
    if rows.size == 0:
        return 0
    span = (rows[0], rows[-1], cols[0], cols[-1])  # the dirty tiles' bounding rectangle
    m = 0
    for i in range(box.shape[1]):
        ty0, ty1, tx0, tx1 = _tile_span(box, i, shift, span)
        if ty0 <= ty1:
            near[m] = i
            m += 1
            for ty in range(ty0, ty1 + 1):
                for tx in range(tx0, tx1 + 1):
                    counts[ty * tiles_x + tx + 1] += dirty[ty, tx]
    for k in range(counts.size - 1):
        counts[k + 1] += counts[k]
    total = counts[-1]
    if entries.size >= total:
        fill = counts[:-1].copy()
        for n in range(m):
            i = near[n]
            ty0, ty1, tx0, tx1 = _tile_span(box, i, shift, span)
            for ty in range(ty0, ty1 + 1):
                for tx in range(tx0, tx1 + 1):
                    if dirty[ty, tx]:
                        k = ty * tiles_x + tx
                        entries[fill[k]] = i
                        fill[k] += 1
    return total


@njit(cache=True, nogil=True)
def _refresh_tile(bits, r0, r1, c0, c1, farthest, stale):
    """``farthest``: the largest depth in each ``stale`` cell (2**HIDDEN_SHIFT pixels a side) of
    the tile at rows [r0, r1), columns [c0, c1) of the depth image's int32 view ``bits``, compared
    as integers: depths are ≥ 0 (or −0), whose bit patterns order as the floats, and an integer
    maximum vectorises where a float one (NaN-aware) does not. Whole cells are read with fixed
    loops and unsigned indices (no wrap-around tests), which the compiler unrolls."""
    w = bits.shape[1]
    cell = 1 << HIDDEN_SHIFT
    flat = bits.reshape(-1)
    for ty in range(farthest.shape[0]):
        ra, rb = r0 + (ty << HIDDEN_SHIFT), min(r0 + ((ty + 1) << HIDDEN_SHIFT), r1)
        for tx in range(farthest.shape[1]):
            if not stale[ty, tx]:
                continue
            stale[ty, tx] = False
            ca = c0 + (tx << HIDDEN_SHIFT)
            m = np.int32(0)
            if rb - ra == cell and ca + cell <= c1:
                base = np.uint64(ra * w + ca)
                for r in range(cell):
                    for c in range(cell):
                        m = max(m, flat[base + np.uint64(r * w + c)])
            else:
                for r in range(ra, rb):
                    for c in range(ca, min(ca + cell, c1)):
                        m = max(m, bits[r, c])
            farthest[ty, tx] = m


@njit(cache=True, nogil=True, parallel=True)
def _draw_tiles(
    seg, jobs, job_start, counts, entries, shift, half, background, rgba, depth, box, nearest, refresh_every
):
    """Each job's tiles (row-major tile indices ``jobs[job_start[j]:job_start[j + 1]]``):
    cleared, then their segments (``entries`` of the CSR ``counts``) in index order. Returns how
    many (segment, tile) entries were skipped as hidden.

    As :func:`draw_bands` does per band, a tile keeps the farthest depth of each of its cells
    (2**HIDDEN_SHIFT pixels a side; all 1.0 once cleared), brought up to date every
    ``refresh_every`` drawn segments for the cells they touched: a segment whose nearer end
    (``nearest``) lies beyond the farthest depth of every cell of the tile its box touches would
    fail the depth test at each of its pixels there, and is skipped (the bytes are the same)."""
    h, w = depth.shape
    tile = 1 << shift
    tiles_x = (w + tile - 1) >> shift
    cells = max(tile >> HIDDEN_SHIFT, 1)
    flat_rgba, flat_depth = rgba.reshape(-1), depth.reshape(-1)
    bits = depth.view(np.int32)
    hidden = np.zeros(max(job_start.size - 1, 0), np.int64)
    for j in prange(job_start.size - 1):
        farthest = np.empty((cells, cells), np.int32)
        far_of = farthest.view(np.float32)
        stale = np.zeros((cells, cells), np.bool_)
        skipped = 0
        for n in range(job_start[j], job_start[j + 1]):
            k = jobs[n]
            r0, c0 = (k // tiles_x) * tile, (k % tiles_x) * tile
            r1, c1 = min(r0 + tile, h), min(c0 + tile, w)
            rgba[r0:r1, c0:c1] = background
            depth[r0:r1, c0:c1] = 1.0
            far_of[:] = 1.0
            stale[:] = False
            drawn = 0
            for e in range(counts[k], counts[k + 1]):
                i = entries[e]
                ty0 = (max(box[0, i], r0) - r0) >> HIDDEN_SHIFT
                ty1 = (min(box[1, i], r1 - 1) - r0) >> HIDDEN_SHIFT
                tx0 = (max(box[2, i], c0) - c0) >> HIDDEN_SHIFT
                tx1 = (min(box[3, i], c1 - 1) - c0) >> HIDDEN_SHIFT
                far = np.float32(0.0)
                for ty in range(ty0, ty1 + 1):
                    for tx in range(tx0, tx1 + 1):
                        far = max(far, far_of[ty, tx])
                if nearest[i] >= far:
                    skipped += 1
                    continue
                _segment(seg, i, half, r0, r1, c0, c1, flat_rgba, flat_depth, w)
                for ty in range(ty0, ty1 + 1):
                    for tx in range(tx0, tx1 + 1):
                        stale[ty, tx] = True
                drawn += 1
                if drawn == refresh_every:
                    _refresh_tile(bits, r0, r1, c0, c1, farthest, stale)
                    drawn = 0
        hidden[j] = skipped
    return hidden.sum()


def _balanced_jobs(work: NDArray[np.int64], n: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The tiles ``work > 0`` in ``n`` jobs of about equal work (heaviest first, each to the
    lightest job so far): ``(tiles, job_start)``, a CSR of tile indices, increasing in each job."""
    tiles = np.flatnonzero(work)
    job = np.zeros(tiles.size, np.int64)
    load = np.zeros(n)
    for k in np.argsort(-work[tiles], kind="stable"):
        j = int(np.argmin(load))
        job[k] = j
        load[j] += work[tiles[k]] + 8.0  # clearing a tile costs about 8 entries' work
    order = np.lexsort((tiles, job))
    return tiles[order], np.searchsorted(job[order], np.arange(n + 1)).astype(np.int64)


def _check(points, starts, colors, mvp, size, width, check_starts=True):
    p = np.ascontiguousarray(points, np.float32)
    s = np.ascontiguousarray(starts, np.int64)
    c = np.ascontiguousarray(colors, np.float32)
    m = np.ascontiguousarray(mvp, np.float64)
    w, h = (int(v) for v in size)
    if p.ndim != 2 or p.shape[1] != 3 or c.shape != p.shape:
        raise ParameterError("points, colors", f"{p.shape}, {c.shape}", "(V, 3) and (V, 3)")
    if m.shape != (4, 4):
        raise ParameterError("mvp", m.shape, "a (4, 4) matrix")
    if check_starts and s.size and (s.min() < 0 or s.max() + 1 >= len(p)):
        raise ParameterError("starts", f"[{s.min()}, {s.max()}]", f"segment starts in [0, {len(p) - 1})")
    if w < 1 or h < 1:
        raise ParameterError("size", size, "(W, H) of at least one pixel")
    if not width > 0:
        raise ParameterError("width", width, "a positive width in pixels")
    return p, s, c, m, w, h, float(width)


class StrandRaster:
    """:meth:`draw` into images kept between calls (made again only when the size changes).

    A draw with a ``clear`` colour after one of the same segments, camera, size, width and
    colour redraws only the tiles under the segments with a vertex that moved or changed colour
    (where they were and where they are), when those are few: the bytes are those of a full
    draw (the tests hold it to that). :attr:`changed` says which rows and columns the last draw
    may have changed, for an upload of just those.

    The per-segment and per-vertex arrays are views into memory kept at the largest size drawn
    so far: the studio alternates between a share of its render hair (while dragging) and all of
    it (on release), and allocating 300 MB of segment table anew each time cost more than the
    kernels filling it (the pages are faulted in on first write).
    """

    def __init__(self) -> None:
        self._stores: dict[str, np.ndarray] = {}
        self._sources: dict[str, np.ndarray] = {}  # read-only arrays kept as they were given
        self._rgba32 = np.zeros((0, 0), np.uint32)  # the kernels write whole pixels
        self.rgba = self._rgba32.view(np.uint8).reshape(0, 0, 4)
        self.depth = np.zeros((0, 0), np.float32)
        self._seg = np.zeros((0, _SEG))
        self._box = np.zeros((4, 0), np.int32)
        self._nearest = np.zeros(0, np.float32)
        self._last: tuple | None = None  # (half, fill, size) of the images' last draw with a clear
        self._last_mvp = np.zeros((4, 4))
        self._last_starts = np.zeros(0, np.int64)
        self._last_points = np.zeros((0, 3), np.float32)
        self._last_colors = np.zeros((0, 3), np.float32)
        self._last_scale = np.float64(1.0)
        self._kept_current = False  # the last points and colours are those of the last draw
        self._increasing_starts: tuple[np.ndarray, bool] | None = None  # (kept starts, increasing)
        self._flags = np.zeros(0, np.bool_)
        self._which = np.zeros(0, np.bool_)
        self._all = np.zeros(0, np.bool_)  # an empty mask: every segment
        self._counts = np.zeros(1, np.int64)
        self._entries = np.zeros(0, np.int64)
        self._near = np.zeros(0, np.int64)
        self.incremental = True  # redraw only what changed when it can (False: always all)
        self._unsearched = 0  # frames to draw in full without looking for changes (see MOSTLY_CHANGED)
        self._next_unsearched = 0
        self.changed: tuple[int, int, int, int] | None = None  # (row0, row1, col0, col1) or None
        self.tiles_redrawn = 0  # in the last draw; −1: all of the image
        self.tiles_hidden = 0  # (segment, tile) entries of the last tile redraw skipped as hidden
        self.draws = 0  # calls of draw so far

    def _view(self, name: str, shape: tuple[int, ...], dtype: type) -> np.ndarray:
        """A C-contiguous ``shape`` array of ``dtype`` in the memory kept as ``name`` (grown when
        too small; its content is whatever was there)."""
        size = int(np.prod(shape))
        store = self._stores.get(name)
        if store is None or store.size < size or store.dtype != dtype:
            store = self._stores[name] = np.empty(size, dtype)
        return store[:size].reshape(shape)

    def images(self, size: tuple[int, int]) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
        """The ``(H, W, 4)`` colour and ``(H, W)`` depth images, resized to ``size = (W, H)``,
        to draw into (e.g. a read-back frame to draw strands over with ``clear=None``)."""
        self._last = None  # whatever the caller writes, the next draw starts afresh
        return self._images(size)

    def _images(self, size: tuple[int, int]) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
        w, h = (int(v) for v in size)
        if self.depth.shape != (h, w):
            self._rgba32 = np.zeros((h, w), np.uint32)
            self.rgba = self._rgba32.view(np.uint8).reshape(h, w, 4)
            self.depth = np.ones((h, w), np.float32)
            self._last = None
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
        scale: ArrayLike | None = None,
        changed: ArrayLike | None = None,
    ) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
        """Segments ``starts[i] → starts[i] + 1`` of ``points`` ``(V, 3)``, coloured by per-vertex
        RGB ``colors`` in [0, 1], seen through ``mvp``, into ``size = (W, H)`` images; ``width``
        in pixels (≤ 1: 1-px lines). The images are first cleared to the RGBA bytes ``clear`` and
        depth 1.0, or with ``clear=None`` drawn over as they are (see :meth:`images`).
        ``scale``: per segment, a factor in [0, 1] of its quad's width (None: 1, no taper).
        ``changed``: ``(R, 2)`` vertex ranges [a, b) outside which points and colours are those
        of the last draw, bit for bit (the caller knows what a brush move redid): a redraw of
        the changed tiles then compares only those vertices (None: any may differ; a draw that
        is not such a redraw ignores it). Returns :meth:`images`; the next draw overwrites them."""
        self.draws += 1
        fixed = self._same("starts", starts) and self._last_points.shape == np.shape(points)
        p, s, c, m, w, h, width = _check(points, starts, colors, mvp, size, width, check_starts=not fixed)
        sc = scale if self._same("scale", scale) else _check_scale(scale, s.size)
        rgba, depth = self._images((w, h))
        half = 0.0 if width <= 1.0 else 0.5 * width
        fill = np.array(clear if clear is not None else (0, 0, 0, 0), np.uint8).view(np.uint32)[0]
        key = (half, int(fill), (w, h))
        same = (
            clear is not None
            and self.incremental
            and self._last == key
            and self._last_points.shape == p.shape
            and np.array_equal(self._last_mvp, m)
            and (fixed or np.array_equal(self._last_starts, s))
            and (self._same("scale", sc) or np.array_equal(self._last_scale, sc))
        )
        self._last = None
        if not same:  # other strands, view or size: whatever changed before tells nothing now
            self._unsearched = self._next_unsearched = 0
        elif self._unsearched > 0:  # the last frames changed nearly all: so will this one
            same, self._unsearched = False, self._unsearched - 1
        runs = None if changed is None else merged_runs(changed, p.shape[0])
        if not (same and self._redraw_changed(p, s, c, m, half, fill, depth, runs)):
            self._draw_all(p, s, c, m, half, clear is not None, fill, depth, sc)
        if clear is not None:
            self._last = key
        return rgba, depth

    def _setup(self, p, s, c, m, half, which, weight=_NO_SCALE, ids=None) -> None:
        """The segments' window coordinates, colours and boxes (those flagged in ``which``, or all
        for an empty mask; or those listed in ``ids``, on this thread), the boxes widened for
        quads of half-width ``half``; into a non-empty ``weight``, each segment's work per row."""
        h, w = self.depth.shape
        sc = self._last_scale if self._last_scale.ndim else _NO_SCALE
        p, s, c, m, sc = (readonly(a) for a in (p, s, c, m, sc))
        if ids is not None:
            _setup_listed(p, s, c, m, w, h, sc, self._seg, self._box, self._nearest, ids, 2.0 * half)
            return
        _setup_kernel(p, s, c, m, w, h, sc, self._seg, self._box, self._nearest, which, 2.0 * half, weight)

    def _draw_all(self, p, s, c, m, half, clear, fill, depth, scale) -> None:
        h, w = depth.shape
        n = s.size
        self._seg, self._box = self._view("seg", (n, _SEG), np.float64), self._view("box", (4, n), np.int32)
        self._nearest = self._view("nearest", (n,), np.float32)
        self._last_scale = self._kept("scale", scale, fixed=True) if scale.ndim else scale
        # One band per thread: more, smaller bands cut more segments in two, which cost more
        # than the better balance gained. A quad's row costs about 1 + its width in pixels
        # (measured on the bench's tapered render hair: rows-only counts left one thread
        # a third more work than the other); the set-up writes that weight, into kept memory.
        weight = self._view("weight", (n,), np.float64) if half > 0.0 else None
        self._setup(p, s, c, m, half, self._all, _NO_SCALE if weight is None else weight)
        bounds = band_bounds(self._box[0], self._box[1], h, numba.get_num_threads(), weight)
        draw_bands(
            self._seg, self._box, self._nearest, bounds, half, clear, fill, self._rgba32, depth, REFRESH_EVERY
        )
        self.changed, self.tiles_redrawn = (0, h, 0, w), -1
        self._last_mvp, self._last_starts = m.copy(), self._kept("starts", s, fixed=True)
        self._kept_current = self._unsearched == 0
        if self._kept_current:  # the next draw may look for changes against what this one drew
            self._last_points, self._last_colors = self._kept("points", p), self._kept("colors", c)
        # (else it draws in full too, and so on up to one that keeps them: copying a drag frame's
        # 350,000 points and colours had cost 0.8 ms a frame)

    def _kept(self, name: str, a: np.ndarray, fixed: bool = False) -> np.ndarray:
        """``a`` as it is now: a copy in the memory kept as ``name``, or with ``fixed`` ``a``
        itself when it is a read-only array (not a view of changing data: the renderer's segment
        starts and widths, fixed per topology; comparing and copying those 3 million numbers
        each frame cost more than drawing a drag's changes)."""
        if fixed and not a.flags.writeable and a.base is None:
            self._sources[name] = a
            return a
        self._sources.pop(name, None)
        out = self._view(name, a.shape, a.dtype.type)
        out[...] = a
        return out

    def _same(self, name: str, a: object) -> bool:
        """Whether ``a`` is the read-only array last kept as ``name`` (so equal to it)."""
        return isinstance(a, np.ndarray) and not a.flags.writeable and self._sources.get(name) is a

    def _plan_searches(self, in_full: bool) -> None:
        """After a search for changes: a frame drawn in full (nearly every segment changed, or the
        changed ones touch tiles that hold nearly all the work) makes the next 1, then 3 frames
        draw in full without searching; a frame drawn in part (or not at all) resets that. Render
        hair following a brush moves a quarter of the segments, across nearly every tile: before
        the second case backed off too, 8 of the bench's 51 drag frames paid ~4 ms for a search
        that found a full draw."""
        self._next_unsearched = min(2 * self._next_unsearched + 1, MAX_UNSEARCHED) if in_full else 0
        self._unsearched = self._next_unsearched

    def _increasing(self, s: np.ndarray) -> bool:
        """Whether the segment starts increase (the renderer's do), remembered for kept ones."""
        if self._increasing_starts is not None and self._increasing_starts[0] is s:
            return self._increasing_starts[1]
        up = bool(np.all(s[1:] > s[:-1]))
        if self._same("starts", s):
            self._increasing_starts = (s, up)
        return up

    def _redraw_changed(self, p, s, c, m, half, fill, depth, runs=None) -> bool:
        """Redraw the tiles the changed segments touch; False when a full draw is cheaper.
        ``runs``: the only vertex ranges that may differ from the last draw (None: any)."""
        n, v = s.size, p.shape[0]
        self._flags, self._which = self._view("flags", (v,), np.bool_), self._view("which", (n,), np.bool_)
        if runs is not None and self._kept_current and self._increasing(s):
            # only the runs' vertices are compared, and their segments flagged
            seg_runs = np.stack([np.searchsorted(s, runs[:, 0] - 1), np.searchsorted(s, runs[:, 1])], axis=1)
            self._which[:] = False
            changed = _changed_in_runs(
                readonly(p), readonly(c), self._last_points, self._last_colors, readonly(s),
                runs, seg_runs, self._flags, self._which,
            )  # fmt: skip
        else:
            _changed_vertices(readonly(p), readonly(c), self._last_points, self._last_colors, self._flags)
            changed = _changed_ends(readonly(s), self._flags, self._which)
        self._kept_current = True
        ids = np.flatnonzero(self._which) if runs is not None else None
        if changed == 0:
            self._plan_searches(in_full=False)
            self.changed, self.tiles_redrawn = None, 0
            return True
        if changed > MOSTLY_CHANGED * n:
            self._plan_searches(in_full=True)
            return False
        h, w = depth.shape
        dirty = np.zeros(((h + TILE - 1) // TILE, (w + TILE - 1) // TILE), np.bool_)
        _mark_tiles(self._box, self._which, dirty, TILE_SHIFT)  # where they were,
        self._setup(p, s, c, m, half, self._which, ids=ids)
        _mark_tiles(self._box, self._which, dirty, TILE_SHIFT)  # and where they are
        if self._counts.size != dirty.size + 1:
            self._counts = np.zeros(dirty.size + 1, np.int64)
        if self._near.size < n:
            self._near = np.empty(n, np.int64)
        total = _bin_segments(self._box, dirty, TILE_SHIFT, self._counts, self._entries, self._near)
        if total > REDRAW_ALL * n:  # measured: then a full draw is as fast
            self._plan_searches(in_full=True)
            return False
        self._plan_searches(in_full=False)
        if self._entries.size < total:
            self._entries = np.empty(int(total * 1.5) + 64, np.int64)
            _bin_segments(self._box, dirty, TILE_SHIFT, self._counts, self._entries, self._near)
        work = np.diff(self._counts)
        work[dirty.reshape(-1)] += 1  # a dirty tile without segments is still cleared
        jobs, job_start = _balanced_jobs(work, numba.get_num_threads())
        self.tiles_hidden = _draw_tiles(
            self._seg,
            jobs,
            job_start,
            self._counts,
            self._entries,
            TILE_SHIFT,
            half,
            fill,
            self._rgba32,
            depth,
            self._box,
            self._nearest,
            TILE_REFRESH_EVERY,
        )
        rows, cols = np.flatnonzero(dirty.any(axis=1)), np.flatnonzero(dirty.any(axis=0))
        if rows.size == 0:  # the changed segments are off the image, before and after
            self.changed, self.tiles_redrawn = None, 0
            return True
        self.changed = (
            int(rows[0]) * TILE,
            min(int(rows[-1] + 1) * TILE, h),
            int(cols[0]) * TILE,
            min(int(cols[-1] + 1) * TILE, w),
        )
        self.tiles_redrawn = int(jobs.size)
        return True


def rasterize(
    points: ArrayLike,
    starts: ArrayLike,
    colors: ArrayLike,
    mvp: ArrayLike,
    size: tuple[int, int],
    width: float,
    scale: ArrayLike | None = None,
) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
    """:meth:`StrandRaster.draw` into fresh images."""
    return StrandRaster().draw(points, starts, colors, mvp, size, width, scale=scale)


def _check_scale(scale: ArrayLike | None, n: int) -> NDArray[np.float64]:
    """Per-segment width factors as float64 (a 0-d 1.0 for None)."""
    if scale is None:
        return np.float64(1.0)
    sc = np.asarray(scale, np.float64)
    if sc.shape != (n,) or not np.all((sc >= 0.0) & (sc <= 1.0)):
        raise ParameterError("scale", f"shape {sc.shape}", f"({n},) width factors in [0, 1], one per segment")
    return sc


def rasterize_reference(
    points: ArrayLike,
    starts: ArrayLike,
    colors: ArrayLike,
    mvp: ArrayLike,
    size: tuple[int, int],
    width: float,
    scale: ArrayLike | None = None,
) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
    """The definition in the module doc in numpy, one segment at a time over the whole image
    (small inputs): the oracle the kernels are tested against."""
    p, s, c, m, w, h, width = _check(points, starts, colors, mvp, size, width)
    sc = np.broadcast_to(_check_scale(scale, s.size), s.shape)
    half = 0.0 if width <= 1.0 else 0.5 * width
    p = p.astype(np.float64)
    clip = p[:, :1] * m[0] + p[:, 1:2] * m[1] + p[:, 2:3] * m[2] + m[3]
    rgb = np.clip(c.astype(np.float64), 0.0, 1.0)
    rgba = np.zeros((h, w, 4), np.uint8)
    depth = np.ones((h, w), np.float32)
    scale = np.array([0.5 * w, 0.5 * h, 0.5])
    for a, f_width in zip(s, sc, strict=True):
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
        rows, cols, t = (
            _quad_fragments(pa, pb, half * f_width, w, h) if half else _line_fragments(pa, pb, w, h)
        )
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
    if abs(uy) > abs(ux):  # steep: by columns, i.e. by rows of the transposed image
        cols, rows, t = _quad_fragments(pa[[1, 0, 2]], pb[[1, 0, 2]], half, h, w)
        return rows, cols, t
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
