"""Guide tables: each guide resampled to a child's vertex count, its segments, their lengths,
and a rotation-minimising frame at every vertex, so a guide that turns carries what hangs on
its frames with it.

Frames are rows (t, n, b). The root frame is the rest guide's root frame (t along the first
segment, n from the world axis least along t) turned by the smallest rotation taking the rest
root tangent to the current one; along the guide each frame is the previous one turned by the
smallest rotation from the previous segment's tangent to this one (parallel transport, the
rotation-minimising frame of Wang et al. 2008 for a polyline). A zero-length segment keeps the
previous frame. The numba kernel :func:`guide_tables` has the numpy twin :func:`guide_tables_reference`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from hairtool.groom import Groom
from hairtool.kernel_arrays import readonly
from hairtool.rotation import turn_between
from hairtool.serial_twins import twin_njit

TINY = 1e-30


@njit(cache=True, nogil=True, inline="always")
def _unit(x, y, z):
    d = np.sqrt(x * x + y * y + z * z)
    if d > TINY:
        return x / d, y / d, z / d, True
    return x, y, z, False


@njit(cache=True, nogil=True, inline="always")
def _root_normal(tx, ty, tz, axes):
    """n of a rest root frame: the scene axis (a column of ``axes``, the groom's frame) least
    along t, made perpendicular to t; so the same groom in Y-up or Z-up gets the same frames."""
    ax = abs(axes[0, 0] * tx + axes[1, 0] * ty + axes[2, 0] * tz)
    ay = abs(axes[0, 1] * tx + axes[1, 1] * ty + axes[2, 1] * tz)
    az = abs(axes[0, 2] * tx + axes[1, 2] * ty + axes[2, 2] * tz)
    k = 0 if ax <= ay and ax <= az else (1 if ay <= az else 2)
    ex, ey, ez = axes[0, k], axes[1, k], axes[2, k]
    d = ex * tx + ey * ty + ez * tz
    nx, ny, nz, _ = _unit(ex - d * tx, ey - d * ty, ez - d * tz)
    return nx, ny, nz


@njit(cache=True, nogil=True, inline="always")
def _guide_rows(points, offsets, counts, n, rest_tangent, axes, row0, seg, seglen, out, g):
    """Guide g's rows ``row0 + g·n …`` of the tables: its ``points`` (float32; strand ``offsets``
    and ``counts``) resampled to n vertices as :func:`resampled` does, each row's segment from
    the previous point (0 at the root) and its length, and the frames (t, n, b) of
    :func:`frames_reference`, whose tangents are these very differences."""
    a = row0 + g * n
    m, o = counts[g], offsets[g]
    ratio = (m - 1) / (n - 1)
    px, py, pz = 0.0, 0.0, 0.0
    for i in range(n):
        if m == n:
            qx, qy, qz = (
                np.float64(points[o + i, 0]),
                np.float64(points[o + i, 1]),
                np.float64(points[o + i, 2]),
            )
        else:
            u = i * ratio
            j = o + min(int(np.floor(u)), m - 2)
            f = u - (j - o)
            ax, ay, az = np.float64(points[j, 0]), np.float64(points[j, 1]), np.float64(points[j, 2])
            bx, by, bz = (
                np.float64(points[j + 1, 0]),
                np.float64(points[j + 1, 1]),
                np.float64(points[j + 1, 2]),
            )
            qx, qy, qz = ax + f * (bx - ax), ay + f * (by - ay), az + f * (bz - az)
        sx, sy, sz = qx - px, qy - py, qz - pz
        if i == 0:
            sx, sy, sz = 0.0, 0.0, 0.0
        seg[a + i, 0], seg[a + i, 1], seg[a + i, 2] = sx, sy, sz
        seglen[a + i] = np.sqrt(sx * sx + sy * sy + sz * sz)
        px, py, pz = qx, qy, qz
    rx, ry, rz = rest_tangent[g, 0], rest_tangent[g, 1], rest_tangent[g, 2]
    nx, ny, nz = _root_normal(rx, ry, rz, axes)
    tx, ty, tz, ok = _unit(seg[a + 1, 0], seg[a + 1, 1], seg[a + 1, 2])
    if not ok:
        tx, ty, tz = rx, ry, rz
    nx, ny, nz = turn_between(nx, ny, nz, rx, ry, rz, tx, ty, tz)  # rest root frame → current
    for i in range(n):
        if i >= 2:
            ux, uy, uz, ok = _unit(seg[a + i, 0], seg[a + i, 1], seg[a + i, 2])
            if ok:
                nx, ny, nz = turn_between(nx, ny, nz, tx, ty, tz, ux, uy, uz)
                tx, ty, tz = ux, uy, uz
        d = nx * tx + ny * ty + nz * tz  # keep n ⟂ t and unit against drift
        nx, ny, nz, _ = _unit(nx - d * tx, ny - d * ty, nz - d * tz)
        v = a + i  # (indexed in place: a row view per vertex costs two atomic counts)
        out[v, 0], out[v, 1], out[v, 2] = tx, ty, tz
        out[v, 3], out[v, 4], out[v, 5] = nx, ny, nz
        out[v, 6], out[v, 7], out[v, 8] = ty * nz - tz * ny, tz * nx - tx * nz, tx * ny - ty * nx


@twin_njit(nogil=True, parallel=True)
def _tables_kernel(points, offsets, counts, n, rest_tangent, axes, row0, seg, seglen, out):
    """:func:`_guide_rows` of every guide, a guide per thread (threads pay from 10 guides on)."""
    for g in prange(counts.size):
        _guide_rows(points, offsets, counts, n, rest_tangent, axes, row0, seg, seglen, out, g)


def guide_tables(
    guides: Groom,
    n: int,
    rest_tangent: np.ndarray,
    out: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    row0: int = 0,
    axes: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(seg (G·n, 3), seglen (G·n,), frames (G·n, 9))`` float64 of the guides at n ≥ 2
    vertices (``rest_tangent`` (G, 3): their rest root tangents), into rows ``row0 …`` of
    ``out`` when given; ``axes``: the scene's frame the root normals start from (default the
    guides' own, :attr:`hairtool.metadata.Metadata.frame`). The numpy twin is
    :func:`guide_tables_reference`.

    Parameters
    ----------
    guides : Groom
        The guides.
    n : int
        Vertices per guide, ≥ 2.
    rest_tangent : ndarray
        ``(G, 3)`` rest root tangents.
    out : tuple of ndarray, optional
        Tables to write into.
    row0 : int, default 0
        The first row written.
    axes : ndarray, optional
        The scene's frame (None: x, y, z).

    Returns
    -------
    tuple of (ndarray, ndarray, ndarray)
        ``seg``, ``seglen`` and ``frames``.
    """
    rows = guides.strand_count * n
    seg, seglen, frm = out if out is not None else (np.empty((rows, 3)), np.empty(rows), np.empty((rows, 9)))
    frame = guides.metadata.frame if axes is None else axes
    # read-only inputs: one compilation whatever the guides hold (a video's frames are copies)
    _tables_kernel(
        readonly(np.asarray(guides.points, np.float32)), guides.offsets[:-1].astype(np.int64),
        guides.counts.astype(np.int64), int(n), readonly(np.asarray(rest_tangent, np.float64)),
        readonly(np.asarray(frame, np.float64)), int(row0), seg, seglen, frm,
    )  # fmt: skip
    return seg, seglen, frm


def guide_tables_reference(
    guides: Groom, n: int, rest_tangent: np.ndarray, axes: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Numpy twin of :func:`guide_tables`: :func:`resampled`, whole-array differences and
    :func:`frames_reference`.

    Parameters
    ----------
    guides, n, rest_tangent, axes
        As :func:`guide_tables` takes them.

    Returns
    -------
    tuple of (ndarray, ndarray, ndarray)
        As :func:`guide_tables` gives them.
    """
    p = resampled(guides, n)
    s = np.zeros_like(p)
    s.reshape(-1, n, 3)[:, 1:] = np.diff(p.reshape(-1, n, 3), axis=1)
    return (
        s,
        np.sqrt(s[:, 0] * s[:, 0] + s[:, 1] * s[:, 1] + s[:, 2] * s[:, 2]),
        frames_reference(p, rest_tangent, n, guides.metadata.frame if axes is None else axes),
    )


def root_tangents(points: np.ndarray, n: int) -> np.ndarray:
    """``(G, 3)`` unit tangents of the first segments of guides of n vertices (x where a first
    segment has no length).

    Parameters
    ----------
    points : ndarray
        ``(G·n, 3)`` guides of n vertices each.
    n : int
        Vertices per guide.

    Returns
    -------
    ndarray
        ``(G, 3)`` float64.
    """
    p = points.reshape(-1, n, 3)
    t = p[:, 1] - p[:, 0]
    d = np.linalg.norm(t, axis=1)
    ok = d > TINY
    out = np.zeros_like(t)
    out[:, 0] = 1.0
    out[ok] = t[ok] / d[ok, None]
    return out


def _turn_ref(v: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    c = float(a @ b)
    if 1.0 + c < 1e-12:
        return v - 2.0 * float(v @ a) * a
    k = np.cross(a, b)
    return v * c + np.cross(k, v) + k * float(k @ v) / (1.0 + c)


def frames_reference(
    points: np.ndarray, rest_tangent: np.ndarray, n: int, axes: np.ndarray | None = None
) -> np.ndarray:
    """Numpy twin of :func:`frames`, one guide and one vertex at a time (``axes``: the scene's
    frame, default x, y, z).

    Parameters
    ----------
    points : ndarray
        ``(G·n, 3)`` guides of n vertices each.
    rest_tangent : ndarray
        ``(G, 3)`` rest root tangents.
    n : int
        Vertices per guide.
    axes : ndarray, optional
        The scene's frame.

    Returns
    -------
    ndarray
        ``(G·n, 9)`` float64 frames.
    """
    p = np.asarray(points, np.float64).reshape(-1, n, 3)
    out = np.empty((p.shape[0], n, 9))
    f = np.eye(3) if axes is None else np.asarray(axes, np.float64)
    for g in range(p.shape[0]):
        r = rest_tangent[g]
        e = f[:, int(np.argmin(np.abs(r @ f)))]
        nrm = e - float(e @ r) * r
        nrm = nrm / np.linalg.norm(nrm)
        first = p[g, 1] - p[g, 0]
        t = first / np.linalg.norm(first) if np.linalg.norm(first) > TINY else r
        nrm = _turn_ref(nrm, r, t)
        for i in range(n):
            if i >= 2:
                s = p[g, i] - p[g, i - 1]
                if np.linalg.norm(s) > TINY:
                    u = s / np.linalg.norm(s)
                    nrm = _turn_ref(nrm, t, u)
                    t = u
            nrm = nrm - float(nrm @ t) * t
            nrm = nrm / np.linalg.norm(nrm)
            out[g, i] = np.concatenate([t, nrm, np.cross(t, nrm)])
    return out.reshape(-1, 9)


def resampled(guides: Groom, n: int) -> np.ndarray:
    """``(G·n, 3)`` float64: every guide at n vertices, evenly in vertex parameter (i/(n−1) of
    its vertices, linearly between them); a guide of n vertices is taken as it is.

    Parameters
    ----------
    guides : Groom
        The guides.
    n : int
        Vertices per guide.

    Returns
    -------
    ndarray
        ``(G·n, 3)`` float64.
    """
    g = guides.strand_count
    out = np.empty((g, n, 3))
    pts = guides.points.astype(np.float64)
    for m in np.unique(guides.counts):
        ids = np.flatnonzero(guides.counts == m)
        starts = guides.offsets[ids]
        if m == n:
            out[ids] = pts[starts[:, None] + np.arange(n)]
            continue
        u = np.arange(n) * ((m - 1) / (n - 1))
        i0 = np.minimum(np.floor(u).astype(np.int64), m - 2)
        f = (u - i0)[None, :, None]
        a = pts[starts[:, None] + i0]
        b = pts[starts[:, None] + i0 + 1]
        out[ids] = a + f * (b - a)
    return out.reshape(-1, 3)
