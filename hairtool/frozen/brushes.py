"""Grooming brushes beside the paper's align: comb, smooth, length, puff, clump and mask.

Each brush sample acts on the vertices within its radius of the cursor, weighted by a falloff
curve of the distance (smooth, linear, constant, or the artist's own curve), times its strength.
Masked strands are locked for every brush. A sample may be mirrored across the plane x = m
(X symmetry): the mirrored cursor and direction act as a second sample of the same stroke.

- comb: the vertices move along the drag direction, more toward the tip (weight × arc-length
  fraction), then every segment gets its length back root to tip: tips follow the drag, lengths
  stay.
- smooth: each inner vertex moves half way (at full weight) toward the mean of its neighbours (a
  Laplacian step of 1/2, from the positions before the sample: larger steps flip zigzags instead
  of flattening them), lengths restored: curvature falls, roots stay.
- length: a strand's segments scale by 1 + strength·w, w the largest weight over its vertices:
  strength > 0 grows, < 0 shrinks (cuts), as a fraction of the length, directions kept.
- puff: a strand turns rigidly about its root so that its root direction moves toward the scalp
  normal (outward from the sphere fitted to the roots) by strength·w at the root: tips lift
  away from the scalp, lengths kept.
- mask: strength > 0 locks the strands a sample touches, < 0 frees them.
- select: strength > 0 selects the strands a sample touches, < 0 deselects them
  (:mod:`hairtool.frozen.selection`); a sample with ``only_selected`` leaves the unselected
  strands as if locked, and hidden strands are locked for every brush.
- clump: paints each strand's clump strength s in [0, 1], which ClumpWithGaps scales its
  adhesion step by: s moves toward 1 (strength > 0) or 0 (< 0) by |strength|·w, w the largest
  weight over the strand's vertices.

Front-facing only: a sample with a ``view`` (the camera's viewing direction, from the eye into
the scene) leaves the strands whose root normal n has n·view > 0 (facing away from the camera)
as if they were locked (:func:`root_normals`, :func:`facing_away`); the pipeline adds them to
the mask for that sample, for every brush and align.

Delete, pinch and snake hook live in :mod:`hairtool.frozen.sculpt`, slide in :mod:`hairtool.frozen.slide`.

Every kernel has a numpy twin (``*_reference``) computing the same definition.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.groom import Groom
from hairtool.serial_twins import twin_njit

F64 = NDArray[np.float64]

BRUSHES = (
    "align", "comb", "smooth", "length", "puff", "mask", "clump", "delete", "pinch", "snake_hook", "slide",
    "add", "density", "select",
)  # fmt: skip
#: The brushes of :mod:`hairtool.frozen.sculpt` and :mod:`hairtool.frozen.slide`, those that
#: add or remove strands, and those that need the head's surface.
SCULPT = ("delete", "pinch", "snake_hook", "slide", "add", "density")
CHANGE_STRANDS = ("delete", "add", "density")
MOVE_NONE = ("mask", "clump", "delete", "add", "density", "select")  # they move no vertex: nothing to collide
NEED_SURFACE = ("slide", "add", "density")
MAX_COUNT = 1000  # strands one add sample may plant
SIGNED = ("length", "mask", "clump", "pinch", "select")  # strength in [-1, 1]; the others in [0, 1]
FALLOFFS = ("smooth", "linear", "constant")
LUT_SIZE = 257  # samples of a falloff curve over [0, 1]: interpolated linearly between
MAX_FALLOFF_POINTS = 4 * LUT_SIZE  # a curve of more points than this says nothing more
EPS = 1e-12


def falloff_lut(falloff: str | Sequence[Sequence[float]]) -> F64:
    """``(LUT_SIZE,)`` weights over t = distance / radius in [0, 1]: a preset name, or curve
    points ``[[t, w], ...]`` (t increasing from 0 to 1, w in [0, 1]) joined by straight lines."""
    t = np.linspace(0.0, 1.0, LUT_SIZE)
    if isinstance(falloff, str):
        if falloff == "smooth":
            return 1.0 - t * t * (3.0 - 2.0 * t)  # smoothstep, 1 at the centre, 0 at the rim
        if falloff == "linear":
            return 1.0 - t
        if falloff == "constant":
            return np.ones_like(t)
        raise ParameterError("falloff", falloff, f"one of {', '.join(FALLOFFS)} or a list of [t, w] points")
    pts = _curve_points(falloff)
    if pts.shape[0] < 2:
        raise ParameterError("falloff", "curve", "at least two [t, w] points")
    if not np.all(np.isfinite(pts)) or np.any(np.diff(pts[:, 0]) <= 0):
        raise ParameterError("falloff", "curve", "finite points with t strictly increasing")
    if pts[0, 0] != 0.0 or pts[-1, 0] != 1.0 or np.any((pts[:, 1] < 0) | (pts[:, 1] > 1)):
        raise ParameterError("falloff", "curve", "t from 0 to 1 and weights in [0, 1]")
    return np.interp(t, pts[:, 0], pts[:, 1])


def _curve_points(falloff: object) -> F64:
    """``(n, 2)`` float64 curve points, the shape and every value checked before numpy sees
    them: a ragged curve, a huge one, a string or an integer beyond float64 is a ParameterError."""
    if isinstance(falloff, np.ndarray):
        if falloff.ndim != 2 or falloff.shape[1:] != (2,) or falloff.dtype.kind not in "fiu":
            raise ParameterError("falloff", "curve", "a list of [t, w] points")
        falloff = falloff.tolist()
    if not isinstance(falloff, Sequence) or isinstance(falloff, str | bytes):
        raise ParameterError("falloff", type(falloff).__name__, "a preset name or a list of [t, w] points")
    if len(falloff) > MAX_FALLOFF_POINTS:
        raise ParameterError("falloff", f"{len(falloff)} points", f"at most {MAX_FALLOFF_POINTS} points")
    for p in falloff:
        if isinstance(p, str | bytes) or not isinstance(p, Sequence | np.ndarray) or len(p) != 2:
            raise ParameterError("falloff", "curve", "[t, w] points of two numbers each")
        for v in p:
            if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating):
                raise ParameterError("falloff", "curve", "[t, w] points of two numbers each")
            if isinstance(v, int) and abs(v) > 1:  # t and w lie in [0, 1]: refused before float()
                raise ParameterError("falloff", "curve", "t from 0 to 1 and weights in [0, 1]")
    return np.array(falloff, dtype=np.float64).reshape(len(falloff), 2)


@dataclass(frozen=True)
class BrushSample:
    """One mouse move of one brush (groom units); ``lut`` from :func:`falloff_lut`; ``view`` the
    camera's viewing direction (from the eye into the scene): with it only the strands facing
    the camera are touched; None: every strand. ``start``: the first sample of a stroke (a
    snake hook hooks its strands there). ``collide``: with a head surface, no vertex the
    sample moves ends inside it (:mod:`hairtool.frozen.collide`). ``count`` and ``seed``: the
    strands an add sample plants, and the seed of where (density's too); ``spacing``: the
    distance a density sample leaves between roots. ``only_selected``: the strands not
    selected are left as if locked (:mod:`hairtool.frozen.selection`). ``pressure``: the pen's
    pressure in [0, 1] at this move (1 for a mouse), already applied to ``radius`` and
    ``strength`` where the brush's pressure toggles said so: kept so a stroke log records it."""

    brush: str
    cursor: tuple[float, float, float]
    direction: tuple[float, float, float]
    radius: float
    strength: float
    lut: tuple[float, ...]
    view: tuple[float, float, float] | None = None
    start: bool = False
    collide: bool = True
    count: int = 1
    seed: int = 0
    spacing: float = 0.0
    only_selected: bool = False
    pressure: float = 1.0

    def mirrored(self, plane_x: float) -> BrushSample:
        c, d = self.cursor, self.direction
        cursor, direction = (2.0 * plane_x - c[0], c[1], c[2]), (-d[0], d[1], d[2])
        return replace(self, cursor=cursor, direction=direction, view=mirrored_view(self.view))


def mirrored_view(view: tuple[float, float, float] | None) -> tuple[float, float, float] | None:
    """A viewing direction mirrored across a plane x = const (None stays None)."""
    return None if view is None else (-view[0], view[1], view[2])


def check_view(view: object) -> tuple[float, float, float] | None:
    """None, or three finite numbers not all zero (ParameterError naming ``view``)."""
    if view is None:
        return None
    try:
        v = np.asarray(view, dtype=np.float64) if not isinstance(view, str | bytes) else np.zeros(0)
    except (TypeError, ValueError):
        v = np.zeros(0)
    if v.shape != (3,) or not np.all(np.isfinite(v)) or not np.any(v != 0):
        raise ParameterError("view", view, "null or three finite numbers, not all zero")
    return (float(v[0]), float(v[1]), float(v[2]))


def check_sample(sample: BrushSample) -> BrushSample:
    if sample.brush not in BRUSHES or sample.brush == "align":
        raise ParameterError("brush", sample.brush, "one of " + ", ".join(BRUSHES[1:]))
    for name in ("cursor", "direction"):
        v = np.asarray(getattr(sample, name), dtype=np.float64)
        if v.shape != (3,) or not np.all(np.isfinite(v)):
            raise ParameterError(name, getattr(sample, name), "three finite numbers")
    if not np.isfinite(sample.radius) or sample.radius <= 0:
        raise ParameterError("radius", sample.radius, "a positive finite distance")
    check_view(sample.view)
    low = -1.0 if sample.brush in SIGNED else 0.0
    if not np.isfinite(sample.strength) or not low <= sample.strength <= 1.0:
        raise ParameterError("strength", sample.strength, f"a number in [{low:g}, 1]")
    c = sample.count
    if isinstance(c, bool) or not isinstance(c, int | np.integer) or not 1 <= c <= MAX_COUNT:
        raise ParameterError("count", c, f"a whole number of strands in [1, {MAX_COUNT}]")
    s = sample.seed
    if isinstance(s, bool) or not isinstance(s, int | np.integer) or not 0 <= s < 2**32:
        raise ParameterError("seed", s, "a whole number in [0, 2^32)")
    if sample.brush == "density" and not (np.isfinite(sample.spacing) and sample.spacing > 0):
        raise ParameterError("spacing", sample.spacing, "a positive distance between roots (groom units)")
    if len(sample.lut) != LUT_SIZE:
        raise ParameterError("falloff", f"{len(sample.lut)} samples", f"{LUT_SIZE}")
    check_pressure(sample.pressure)
    return sample


def check_pressure(pressure: object) -> float:
    """A pen's pressure: a number in [0, 1] (ParameterError naming ``pressure``)."""
    number = isinstance(pressure, int | float | np.integer | np.floating) and not isinstance(pressure, bool)
    if not number or not 0.0 <= float(pressure) <= 1.0:  # (NaN fails the comparison)
        raise ParameterError("pressure", pressure, "a number in [0, 1]")
    return float(pressure)


# -- shared pieces -----------------------------------------------------------------------------
@njit(cache=True, nogil=True, inline="always")
def _weight(px, py, pz, c, radius, lut):  # pragma: no cover - compiled
    dx, dy, dz = px - c[0], py - c[1], pz - c[2]
    t = np.sqrt(dx * dx + dy * dy + dz * dz) / radius
    if t >= 1.0:
        return 0.0
    f = t * (lut.size - 1)
    k = min(int(f), lut.size - 2)
    a = f - k
    return lut[k] * (1.0 - a) + lut[k + 1] * a


def _weights_reference(p: F64, c: F64, radius: float, lut: F64) -> F64:
    t = np.linalg.norm(p - c, axis=1) / radius
    f = np.clip(t, 0.0, 1.0) * (lut.size - 1)
    k = np.minimum(f.astype(np.int64), lut.size - 2)
    a = f - k
    return np.where(t < 1.0, lut[k] * (1.0 - a) + lut[k + 1] * a, 0.0)


@njit(cache=True, nogil=True)
def _restore_lengths(q, p, o, n):  # pragma: no cover - compiled
    """q[o+1 .. o+n−1] pulled back, root to tip, to the segment lengths of p: each vertex at its
    original distance from the (already restored) one before, in the direction toward where the
    brush put it (the original direction where q collapses onto it). Follow-the-leader, so the
    vertices past a moved one follow it: not :func:`hairtool.frozen.lengths.restore_lengths`,
    which keeps each clumped segment's own direction and would pull a combed tip back."""
    for i in range(o + 1, o + n):
        lx, ly, lz = p[i, 0] - p[i - 1, 0], p[i, 1] - p[i - 1, 1], p[i, 2] - p[i - 1, 2]
        length = np.sqrt(lx * lx + ly * ly + lz * lz)
        dx, dy, dz = q[i, 0] - q[i - 1, 0], q[i, 1] - q[i - 1, 1], q[i, 2] - q[i - 1, 2]
        d = np.sqrt(dx * dx + dy * dy + dz * dz)
        if d < EPS:
            dx, dy, dz, d = lx, ly, lz, length
        s = length / d if d >= EPS else 0.0
        q[i, 0] = q[i - 1, 0] + dx * s
        q[i, 1] = q[i - 1, 1] + dy * s
        q[i, 2] = q[i - 1, 2] + dz * s


def _restore_lengths_reference(q: F64, p: F64) -> F64:
    out = q.copy()
    for i in range(1, len(p)):
        seg = p[i] - p[i - 1]
        d = out[i] - out[i - 1]
        if np.linalg.norm(d) < EPS:
            d = seg
        norm = np.linalg.norm(d)
        out[i] = out[i - 1] + d * (np.linalg.norm(seg) / norm if norm >= EPS else 0.0)
    return out


# -- kernels -----------------------------------------------------------------------------------
@njit(cache=True, nogil=True, parallel=True)
def _brush_kernel(  # pragma: no cover - compiled
    p, offsets, locked, kind, c, direction, radius, strength, lut, centre, out
):
    """kind: 0 comb, 1 smooth, 2 length, 3 puff; ``p`` and ``out`` float64 (V, 3)."""
    for s in prange(offsets.size - 1):
        o, e = offsets[s], offsets[s + 1]
        n = e - o
        for i in range(o, e):
            out[i, 0], out[i, 1], out[i, 2] = p[i, 0], p[i, 1], p[i, 2]
        if locked[s] or n < 2:
            continue
        if kind == 0 or kind == 1:
            total = 0.0
            if kind == 0:  # only comb weighs by the arc-length fraction
                for i in range(o + 1, e):
                    total += _dist(p, i, i - 1)
            run = 0.0
            moved = False
            for i in range(o + 1, e):
                if kind == 0:
                    run += _dist(p, i, i - 1)
                w = _weight(p[i, 0], p[i, 1], p[i, 2], c, radius, lut) * strength
                if w == 0.0:
                    continue
                moved = True
                if kind == 0:
                    u = run / total if total > EPS else 0.0
                    for a in range(3):
                        out[i, a] = p[i, a] + w * u * direction[a]
                elif i < e - 1:
                    for a in range(3):
                        out[i, a] = p[i, a] + 0.5 * w * (0.5 * (p[i - 1, a] + p[i + 1, a]) - p[i, a])
            if moved:
                _restore_lengths(out, p, o, n)
        elif kind == 2:
            w = 0.0
            for i in range(o, e):
                w = max(w, _weight(p[i, 0], p[i, 1], p[i, 2], c, radius, lut))
            factor = max(1.0 + strength * w, 0.0)
            if w > 0.0:
                for i in range(o + 1, e):
                    for a in range(3):
                        out[i, a] = out[i - 1, a] + factor * (p[i, a] - p[i - 1, a])
        else:
            w = _weight(p[o, 0], p[o, 1], p[o, 2], c, radius, lut) * strength
            if w > 0.0:
                _puff_strand(p, o, e, w, centre, out)


@njit(cache=True, nogil=True, inline="always")
def _dist(p, i, j):  # pragma: no cover - compiled
    return np.sqrt((p[i, 0] - p[j, 0]) ** 2 + (p[i, 1] - p[j, 1]) ** 2 + (p[i, 2] - p[j, 2]) ** 2)


@njit(cache=True, nogil=True)
def _puff_strand(p, o, e, w, centre, out):  # pragma: no cover - compiled
    """Turn the strand rigidly about its root: its first segment toward the outward normal by
    the fraction w of the angle between them (Rodrigues' rotation)."""
    nx, ny, nz = p[o, 0] - centre[0], p[o, 1] - centre[1], p[o, 2] - centre[2]
    nn = np.sqrt(nx * nx + ny * ny + nz * nz)
    tx, ty, tz = p[o + 1, 0] - p[o, 0], p[o + 1, 1] - p[o, 1], p[o + 1, 2] - p[o, 2]
    tn = np.sqrt(tx * tx + ty * ty + tz * tz)
    if nn < EPS or tn < EPS:
        return
    nx, ny, nz, tx, ty, tz = nx / nn, ny / nn, nz / nn, tx / tn, ty / tn, tz / tn
    ax, ay, az = ty * nz - tz * ny, tz * nx - tx * nz, tx * ny - ty * nx
    sin_a = np.sqrt(ax * ax + ay * ay + az * az)
    cos_a = tx * nx + ty * ny + tz * nz
    if sin_a < 1e-9:
        return  # already along the normal (or exactly against it: no unique way to turn)
    ax, ay, az = ax / sin_a, ay / sin_a, az / sin_a
    angle = w * np.arctan2(sin_a, cos_a)
    cs, sn = np.cos(angle), np.sin(angle)
    for i in range(o + 1, e):
        vx, vy, vz = p[i, 0] - p[o, 0], p[i, 1] - p[o, 1], p[i, 2] - p[o, 2]
        dot = ax * vx + ay * vy + az * vz
        cx, cy, cz = ay * vz - az * vy, az * vx - ax * vz, ax * vy - ay * vx
        out[i, 0] = p[o, 0] + vx * cs + cx * sn + ax * dot * (1.0 - cs)
        out[i, 1] = p[o, 1] + vy * cs + cy * sn + ay * dot * (1.0 - cs)
        out[i, 2] = p[o, 2] + vz * cs + cz * sn + az * dot * (1.0 - cs)


KINDS = {"comb": 0, "smooth": 1, "length": 2, "puff": 3}


def _sphere_centre(groom: Groom) -> F64 | None:
    """Centre of the sphere fitted to the roots (least squares, |x|² = 2c·x + k), or None where
    the roots do not determine one (fewer than 4, coplanar, or a sphere far larger than them)."""
    r = groom.roots.astype(np.float64)
    if len(r) < 4:
        return None
    a = np.column_stack([2.0 * r, np.ones(len(r))])
    b = np.einsum("ij,ij->i", r, r)
    sol, *_ = np.linalg.lstsq(a, b, rcond=None)
    centre = sol[:3]
    if not np.all(np.isfinite(centre)) or np.linalg.matrix_rank(a) < 4:
        return None
    return centre


def scalp_centre(groom: Groom) -> F64:
    """Centre of the sphere fitted to the roots (least squares, |x|² = 2c·x + k): the scalp's
    outward normal at a root points away from it; where the roots are coplanar (or fewer than
    4), a point below their centroid, along the scene's −up (its up axis, +y or +z)."""
    centre = _sphere_centre(groom)
    if centre is None:
        r = groom.roots.astype(np.float64)
        up = groom.metadata.up
        centre = r.mean(axis=0) - up * float(np.ptp(r @ up) + 1.0)
    return centre


PLANAR_RATIO = 100.0  # a fitted sphere this many times wider than the roots' extent: a flat scalp


def root_normals(groom: Groom) -> F64:
    """``(S, 3)`` unit outward scalp normal at each root, for front-facing brushes.

    On a head (the roots fit a sphere, as puff uses): away from the sphere's centre. A headless
    groom whose roots lie in a plane (or on a sphere over PLANAR_RATIO times wider than they
    are: numerically a plane) has one normal, the plane's, on the side its strands grow to (the
    mean root-to-tip direction): seen from that side every strand faces the camera, from
    behind none does. Roots on a line or a point (no plane): zero normals, so no strand ever
    faces away and front-facing changes nothing."""
    r = groom.roots.astype(np.float64)
    s = len(r)
    centre = _sphere_centre(groom)
    extent = float(np.ptp(r, axis=0).max()) if s else 0.0
    if centre is not None and np.linalg.norm(r - centre, axis=1).max() <= PLANAR_RATIO * extent:
        n = r - centre
        norm = np.linalg.norm(n, axis=1, keepdims=True)
        return np.divide(n, norm, out=np.zeros_like(n), where=norm > EPS)
    out = np.zeros((s, 3))
    if s < 3:
        return out
    _, sv, vt = np.linalg.svd(r - r.mean(axis=0), full_matrices=False)
    if sv[1] <= 1e-9 * max(sv[0], EPS):
        return out  # the roots lie on a line: no plane
    normal = vt[2]
    tips = groom.points[groom.topology.tip_indices].astype(np.float64)
    if float(np.mean(tips - r, axis=0) @ normal) < 0:
        normal = -normal
    out[:] = normal
    return out


@twin_njit(nogil=True, parallel=True)
def _facing_away_kernel(normals, view, out):  # pragma: no cover - compiled
    for s in prange(normals.shape[0]):
        out[s] = normals[s, 0] * view[0] + normals[s, 1] * view[1] + normals[s, 2] * view[2] > 0.0


def facing_away(normals: ArrayLike, view: ArrayLike) -> np.ndarray:
    """``(S,)`` the strands whose root normal faces away from a camera looking along ``view``
    (n·view > 0): a front-facing brush leaves them as if locked."""
    n = np.ascontiguousarray(normals, dtype=np.float64)
    out = np.empty(len(n), dtype=np.bool_)
    _facing_away_kernel(n, np.asarray(view, np.float64), out)
    return out


def facing_away_reference(normals: ArrayLike, view: ArrayLike) -> np.ndarray:
    """Numpy twin of :func:`facing_away`."""
    n = np.asarray(normals, np.float64)
    v = np.asarray(view, np.float64)
    return n[:, 0] * v[0] + n[:, 1] * v[1] + n[:, 2] * v[2] > 0.0


@njit(cache=True, nogil=True)
def _any_within_kernel(points, cx, cy, cz, r2):
    for i in range(points.shape[0]):
        ex = np.float64(points[i, 0]) - cx
        ey = np.float64(points[i, 1]) - cy
        ez = np.float64(points[i, 2]) - cz
        if ex * ex + ey * ey + ez * ez <= r2:
            return True
    return False


def any_within(points: np.ndarray, centre: ArrayLike, radius: float) -> bool:
    """Whether a vertex of ``points`` ``(V, 3)`` lies within ``radius`` of ``centre`` (float64
    differences): the press asks it of the whole groom, so it stops at the first one found and
    makes no array the groom's size (the numpy twin made four: 5-7 ms on the bear)."""
    c = np.asarray(centre, np.float64)
    return bool(_any_within_kernel(points, float(c[0]), float(c[1]), float(c[2]), float(radius) ** 2))


def any_within_reference(points: np.ndarray, centre: ArrayLike, radius: float) -> bool:
    """Numpy twin of :func:`any_within`."""
    d = np.asarray(points, np.float64) - np.asarray(centre, np.float64)
    return bool(np.any(np.einsum("ij,ij->i", d, d) <= float(radius) ** 2))


def apply_brush(groom: Groom, sample: BrushSample, locked: ArrayLike, centre: ArrayLike) -> Groom:
    """One comb, smooth, length or puff sample (numba); ``locked``: ``(S,)`` masked strands."""
    check_sample(sample)
    if sample.brush not in KINDS:
        raise ParameterError("brush", sample.brush, "one of " + ", ".join(KINDS))
    out = np.empty((groom.vertex_count, 3))
    _brush_kernel(
        groom.points.astype(np.float64),
        groom.offsets,
        np.asarray(locked, dtype=np.bool_),
        KINDS[sample.brush],
        np.asarray(sample.cursor, np.float64),
        np.asarray(sample.direction, np.float64),
        float(sample.radius),
        float(sample.strength),
        np.asarray(sample.lut, np.float64),
        np.asarray(centre, np.float64),
        out,
    )
    return groom.with_points(out.astype(np.float32))


def apply_brush_reference(groom: Groom, sample: BrushSample, locked: ArrayLike, centre: ArrayLike) -> Groom:
    """Numpy twin of :func:`apply_brush`, strand by strand from the definitions above."""
    check_sample(sample)
    p_all = groom.points.astype(np.float64)
    out = p_all.copy()
    c, d = np.asarray(sample.cursor, np.float64), np.asarray(sample.direction, np.float64)
    lut = np.asarray(sample.lut, np.float64)
    locked = np.asarray(locked, dtype=bool)
    for s, (o, e) in enumerate(zip(groom.offsets[:-1], groom.offsets[1:], strict=True)):
        p = p_all[o:e]
        if locked[s] or len(p) < 2:
            continue
        w = _weights_reference(p, c, sample.radius, lut)
        if sample.brush in ("comb", "smooth"):
            q = p.copy()
            wm = w * sample.strength
            if not np.any(wm[1:] != 0):
                continue
            if sample.brush == "comb":
                seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
                u = np.concatenate([[0.0], np.cumsum(seg)]) / max(seg.sum(), EPS)
                u = np.where(seg.sum() > EPS, u, 0.0)
                q[1:] = p[1:] + (wm * u)[1:, None] * d
            else:
                q[1:-1] = p[1:-1] + 0.5 * wm[1:-1, None] * (0.5 * (p[:-2] + p[2:]) - p[1:-1])
            out[o:e] = _restore_lengths_reference(q, p)
        elif sample.brush == "length":
            if w.max() > 0:
                factor = max(1.0 + sample.strength * w.max(), 0.0)
                for i in range(1, len(p)):
                    out[o + i] = out[o + i - 1] + factor * (p[i] - p[i - 1])
        else:
            wr = w[0] * sample.strength
            if wr > 0:
                out[o:e] = _puff_reference(p, wr, np.asarray(centre, np.float64))
    return groom.with_points(out.astype(np.float32))


def _puff_reference(p: F64, w: float, centre: F64) -> F64:
    n, t = p[0] - centre, p[1] - p[0]
    if np.linalg.norm(n) < EPS or np.linalg.norm(t) < EPS:
        return p
    n, t = n / np.linalg.norm(n), t / np.linalg.norm(t)
    axis = np.cross(t, n)
    sin_a = np.linalg.norm(axis)
    if sin_a < 1e-9:
        return p
    axis /= sin_a
    angle = w * np.arctan2(sin_a, float(t @ n))
    v = p - p[0]
    rotated = (
        v * np.cos(angle)
        + np.cross(axis, v) * np.sin(angle)
        + axis * (v @ axis)[:, None] * (1.0 - np.cos(angle))
    )
    return p[0] + rotated


def paint_mask(
    groom: Groom, sample: BrushSample, locked: ArrayLike, skip: ArrayLike | None = None
) -> np.ndarray:
    """``(S,)`` the mask after one mask sample: strands with a vertex inside the brush are locked
    (strength > 0) or freed (strength < 0); the strands ``skip`` (facing away) are left as they are."""
    check_sample(sample)
    locked = np.array(locked, dtype=bool)
    c, lut = np.asarray(sample.cursor, np.float64), np.asarray(sample.lut, np.float64)
    w = _weights_reference(groom.points.astype(np.float64), c, sample.radius, lut)
    touched = np.maximum.reduceat(w, groom.offsets[:-1]) > 0
    if skip is not None:
        touched &= ~np.asarray(skip, dtype=bool)
    locked[touched] = sample.strength > 0
    return locked


@njit(cache=True, nogil=True, parallel=True)
def _paint_clump_kernel(p, offsets, locked, c, radius, strength, lut, s_in, s_out):  # pragma: no cover
    target = 1.0 if strength > 0.0 else 0.0
    amount = abs(strength)
    for s in prange(offsets.size - 1):
        s_out[s] = s_in[s]
        if locked[s]:
            continue
        w = 0.0
        for i in range(offsets[s], offsets[s + 1]):
            w = max(w, _weight(p[i, 0], p[i, 1], p[i, 2], c, radius, lut))
        if w > 0.0:
            s_out[s] = s_in[s] + amount * w * (target - s_in[s])


def paint_clump(groom: Groom, sample: BrushSample, strength: ArrayLike, locked: ArrayLike) -> np.ndarray:
    """``(S,)`` float64 clump strengths after one clump sample: each unlocked strand's s moves
    toward 1 (sample strength > 0) or 0 (< 0) by |strength|·w, w its largest vertex weight, so
    it stays in [0, 1] (numba)."""
    check_sample(sample)
    if sample.brush != "clump":
        raise ParameterError("brush", sample.brush, "clump")
    s_in = np.ascontiguousarray(strength, dtype=np.float64)
    out = np.empty_like(s_in)
    _paint_clump_kernel(
        groom.points.astype(np.float64), groom.offsets, np.asarray(locked, np.bool_),
        np.asarray(sample.cursor, np.float64), float(sample.radius), float(sample.strength),
        np.asarray(sample.lut, np.float64), s_in, out,
    )  # fmt: skip
    return out


def paint_clump_reference(
    groom: Groom, sample: BrushSample, strength: ArrayLike, locked: ArrayLike
) -> np.ndarray:
    """Numpy twin of :func:`paint_clump`."""
    check_sample(sample)
    s_in = np.asarray(strength, dtype=np.float64)
    c, lut = np.asarray(sample.cursor, np.float64), np.asarray(sample.lut, np.float64)
    w = np.maximum.reduceat(_weights_reference(groom.points.astype(np.float64), c, sample.radius, lut),
                            groom.offsets[:-1])
    w = np.where(np.asarray(locked, bool), 0.0, w)
    target = 1.0 if sample.strength > 0 else 0.0
    return np.where(w > 0, s_in + abs(sample.strength) * w * (target - s_in), s_in)
