"""Posing bunch chains from per-segment bend angles (the geometry half of the anime cycle).

A bunch is one chain skeleton, root to tip. Every strand of a groom is a chain; with guides,
each strand joins the bunch of the guide whose root is nearest and takes that guide's bend
axis, amplitude scale and phase, so a bunch moves as one lock of hair.

Bending rotates each rest segment about its bunch's fixed bend axis by the sampled angle θ_j
(the sum of the relative node rotations from the root to that segment) and rebuilds the chain
from its root: rotations keep every segment length, and a 2-D groom bent about z stays planar.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.groom import Groom
from hairtool.kernel_arrays import readonly
from hairtool.rotation import any_perpendicular, normalize

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

UP = np.array([0.0, 1.0, 0.0])  # the reference frame's up (hairtool.samples); a scene's: its frame
VIEW_HORIZONTAL = np.array([1.0, 0.0, 0.0])  # lateral in Y-up and Z-up scenes alike
_DEGENERATE = 1e-6  # |sin| between a chord and the sway below which the sway gives no axis


def wave_x(groom: Groom) -> F64:
    """``(V,)`` the wave's x at every node: π × arc length from the root / chain length, in [0, π].

    Parameters
    ----------
    groom : Groom
        The chains at rest.

    Returns
    -------
    ndarray
        ``(V,)`` float64.
    """
    return np.pi * np.clip(groom.arc_param, 0.0, 1.0)


def check_guides(groom: Groom, guides: ArrayLike) -> I64:
    """Validated, distinct guide strand ids, in the given order.

    Parameters
    ----------
    groom : Groom
        The strands.
    guides : array_like
        Guide strand ids.

    Returns
    -------
    ndarray
        int64 ids (ParameterError naming a bad or repeated one).
    """
    g = np.asarray(guides)
    if g.ndim != 1 or g.size == 0 or not np.issubdtype(g.dtype, np.integer):
        raise ParameterError("guides", guides, "a non-empty list of strand ids")
    g = g.astype(np.int64)
    if g.min() < 0 or g.max() >= groom.strand_count:
        raise ParameterError("guides", guides, f"strand ids in [0, {groom.strand_count})")
    if np.unique(g).size != g.size:
        raise ParameterError("guides", guides, "distinct strand ids")
    return g


def nearest_guide(groom: Groom, guides: I64, chunk: int = 4096) -> I64:
    """``(S,)`` the bunch of every strand: the index into ``guides`` of the nearest guide root.

    Ties go to the guide listed first; a guide is always its own bunch.

    Parameters
    ----------
    groom : Groom
        The strands.
    guides : ndarray
        Checked guide ids (:func:`check_guides`).
    chunk : int, default 4096
        Strands measured at once (bounds the distance table's memory).

    Returns
    -------
    ndarray
        ``(S,)`` int64.
    """
    roots = groom.roots.astype(np.float64)
    g_roots = roots[guides]
    out = np.empty(groom.strand_count, dtype=np.int64)
    for lo in range(0, groom.strand_count, chunk):
        d = roots[lo : lo + chunk, None, :] - g_roots[None, :, :]
        out[lo : lo + chunk] = np.argmin(np.einsum("ijk,ijk->ij", d, d), axis=1)
    out[guides] = np.arange(guides.size)
    return out


def check_sway(sway: ArrayLike | None) -> F64 | None:
    """``sway`` as a float64 3-vector, or None; a ParameterError for a zero or non-finite one.

    Parameters
    ----------
    sway : array_like or None
        The direction the wave bends toward.

    Returns
    -------
    ndarray or None
        ``(3,)`` float64.
    """
    if sway is None:
        return None
    w = np.asarray(sway, dtype=np.float64)
    if w.shape != (3,) or not np.all(np.isfinite(w)) or np.linalg.norm(w) == 0:
        raise ParameterError("sway", sway, "a non-zero, finite 3-vector (x, y, z)")
    return w / np.linalg.norm(w)


def bend_axes(
    chains: Groom, sway: ArrayLike | None = None, planar: bool | None = None, up: ArrayLike | None = None
) -> F64:
    """``(S,)``×3 unit bend axes, one per chain, so that positive wave y bends toward ``sway``.

    The axis is chord × sway (chord = root → tip of the rest chain). ``sway`` defaults to up
    (−gravity: ``up``, default the chains' scene's up axis, +y or +z): the axis is then
    perpendicular to the strand and to gravity and the wave's gravity term pulls chains down.
    2-D grooms always bend about ±z and stay planar. Chords parallel to the sway fall back to
    the view's horizontal (+x) as the sway, then to any perpendicular. ``planar`` defaults to
    ``chains.is_planar``.

    Parameters
    ----------
    chains : Groom
        One chain per bunch, at rest.
    sway : array_like, optional
        The direction positive y bends toward (None: up).
    planar : bool, optional
        The chains lie in a plane (None: ask the groom).
    up : array_like, optional
        The scene's up (None: the chains' scene's).

    Returns
    -------
    ndarray
        ``(S, 3)`` float64 unit axes.
    """
    w = check_sway(sway)
    up_dir = chains.metadata.up if up is None else np.asarray(up, dtype=np.float64)
    w = up_dir if w is None else w
    chord = (chains.tips - chains.roots).astype(np.float64)
    length = np.linalg.norm(chord, axis=1)
    if chains.is_planar if planar is None else planar:
        w_xy = np.array([w[0], w[1], 0.0])
        if np.linalg.norm(w_xy) < _DEGENERATE:
            raise ParameterError("sway", sway, "a direction in the x-y plane for a 2-D groom")
        z = np.cross(chord, w_xy)[:, 2]
        sign = np.where(z < 0.0, -1.0, 1.0)
        return np.column_stack([np.zeros_like(sign), np.zeros_like(sign), sign])
    axes = np.cross(chord, w)
    ok = np.linalg.norm(axes, axis=1) > _DEGENERATE * np.maximum(length, 1e-30)
    if not np.all(ok):
        fallback = np.cross(chord[~ok], VIEW_HORIZONTAL if abs(w[0]) < 0.9 else up_dir)
        bad = np.linalg.norm(fallback, axis=1) <= _DEGENERATE * np.maximum(length[~ok], 1e-30)
        fallback[bad] = any_perpendicular(np.where(length[~ok][bad, None] > 0, chord[~ok][bad], up_dir))
        axes[~ok] = fallback
    return normalize(axes)


def bunch_variation(
    n_bunches: int,
    amplitude_spread: float = 0.0,
    phase_spread: float = 0.0,
    seed: int = 0,
) -> tuple[F64, F64]:
    """Per-bunch amplitude scale 1 ± ``amplitude_spread`` and phase offset in [0, ``phase_spread``) cycles.

    Bunch b's draws depend only on (seed, b), so adding bunches does not reshuffle the others.

    Parameters
    ----------
    n_bunches : int
        Bunches.
    amplitude_spread : float, default 0.0
        Each scale is 1 ± this.
    phase_spread : float, default 0.0
        Each phase is in [0, this) cycles.
    seed : int, default 0
        The draws' seed.

    Returns
    -------
    tuple of (ndarray, ndarray)
        ``(n_bunches,)`` scales and phases, float64.
    """
    for name, v in (("amplitude_spread", amplitude_spread), ("phase_spread", phase_spread)):
        if not np.isfinite(v) or not 0.0 <= v <= 1.0:
            raise ParameterError(name, v, "a number in [0, 1]")
    if int(seed) != seed or seed < 0:
        raise ParameterError("seed", seed, "a whole number ≥ 0")
    seed = int(seed)
    scale = 1.0 + amplitude_spread * np.random.default_rng([seed, 0]).uniform(-1.0, 1.0, n_bunches)
    phase = phase_spread * np.random.default_rng([seed, 1]).uniform(0.0, 1.0, n_bunches)
    return scale, phase


def check_per_bunch(name: str, values: ArrayLike, n_bunches: int) -> F64:
    """One value, or one per bunch, as ``(n_bunches,)`` finite float64; a ParameterError naming
    ``name`` otherwise.

    Parameters
    ----------
    name : str
        The parameter, named in a refusal.
    values : array_like
        A number or ``(n_bunches,)`` numbers.
    n_bunches : int
        Bunches.

    Returns
    -------
    ndarray
        ``(n_bunches,)`` float64.
    """
    v = np.asarray(values, dtype=np.float64)
    if v.ndim == 0:
        v = np.full(n_bunches, float(v))
    if v.shape != (n_bunches,) or not np.all(np.isfinite(v)):
        raise ParameterError(name, values, f"a finite number or {n_bunches} finite numbers (one per bunch)")
    return v


def bend_chains(groom: Groom, axes: ArrayLike, angles: ArrayLike) -> F64:
    """``(P, V, 3)`` float64 poses: rest segments rotated by ``angles`` about ``axes``, rebuilt from roots.

    ``axes``: ``(S, 3)`` unit axis per strand; ``angles``: ``(P, V−S)`` radians per segment and
    pose (θ_j, the absolute bend of segment j, i.e. the relative node rotations summed root to j).

    Parameters
    ----------
    groom : Groom
        The chains at rest.
    axes : array_like
        ``(S, 3)`` unit axes.
    angles : array_like
        ``(P, V−S)`` radians.

    Returns
    -------
    ndarray
        ``(P, V, 3)`` float64.
    """
    a = np.asarray(angles, dtype=np.float64)
    return bend_chains_cs(groom, axes, np.cos(a), np.sin(a))


def bend_chains_cs(groom: Groom, axes: ArrayLike, cos: F64, sin: F64) -> F64:
    """:func:`bend_chains` given cosθ and sinθ, ``(P, V−S)`` each (no trigonometry on the hot path).

    Parameters
    ----------
    groom : Groom
        The chains at rest.
    axes : array_like
        ``(S, 3)`` unit axes.
    cos, sin : ndarray
        ``(P, V−S)`` each.

    Returns
    -------
    ndarray
        ``(P, V, 3)`` float64.
    """
    top = groom.topology
    seg_end = top.segment_end
    if cos.ndim != 2 or cos.shape[1] != seg_end.size or sin.shape != cos.shape:
        raise ParameterError("angles", cos.shape, f"shape (P, {seg_end.size})")
    seg_axes = np.asarray(axes, dtype=np.float64)[top.strand_index[seg_end]]
    p64 = groom.points.astype(np.float64)
    rest = p64[seg_end] - p64[seg_end - 1]  # in float64, like the kernel
    # Rodrigues with the angle-free parts hoisted out of the pose loop:
    # R v = (v − w) cosθ + (â × v) sinθ + w, with w = â(â·v) the part along the axis.
    along = seg_axes * np.einsum("ij,ij->i", seg_axes, rest)[:, None]
    across = rest - along
    turn = np.cross(seg_axes, rest)
    pos = np.zeros((cos.shape[0], top.vertex_count, 3))
    pos[:, seg_end] = across * cos[..., None] + turn * sin[..., None] + along
    np.cumsum(pos, axis=1, out=pos)
    # Restart the running sum at each root: subtract the sum up to the root, add the root.
    base = p64[top.root_indices] - pos[:, top.root_indices]
    pos += base[:, top.strand_index]
    return pos


# -- the whole pose: eq. (1) sampled at the nodes, then the bend ------------------------------
# Both take per-strand arrays: ``axes`` (S, 3) unit bend axes, ``scale`` (S,) amplitude factors,
# ``shift`` (S,) time offsets in seconds (phase × T); ``wave`` = (a, k, s, p, T).


def wave_values(x: ArrayLike, t: ArrayLike, a: float, k: float, s: float, p: float, period: float) -> F64:
    """Eq. (1) without argument checks: −(a/s)(x/π)^p (cos(x/k − 2πt/T) + 1/s), broadcast.

    Parameters
    ----------
    x : array_like
        Positions along the chain, in [0, π].
    t : array_like
        Times in seconds.
    a, k, s, p, period : float
        Amplitude, wavelength, gravity, profile and period T of eq. (1).

    Returns
    -------
    ndarray
        f(x, t), float64.
    """
    x = np.asarray(x, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    return -(a / s) * (x / np.pi) ** p * (np.cos(x / k - 2.0 * np.pi * t / period) + 1.0 / s)


def pose_reference(
    groom: Groom, times: F64, axes: F64, scale: F64, shift: F64, wave: tuple[float, ...]
) -> F64:
    """``(P, V, 3)`` float64 poses, plain numpy: the reference for :func:`pose_numba`.

    Parameters
    ----------
    groom : Groom
        The chains at rest.
    times : ndarray
        ``(P,)`` seconds.
    axes : ndarray
        ``(S, 3)`` unit bend axes.
    scale, shift : ndarray
        ``(S,)`` each strand's amplitude scale and time shift (its bunch's).
    wave : tuple of float
        ``(a, k, s, p, period)``.

    Returns
    -------
    ndarray
        ``(P, V, 3)`` float64.
    """
    top = groom.topology
    x = wave_x(groom)
    t_v = times[:, None] + shift[top.strand_index][None, :]
    y = scale[top.strand_index][None, :] * wave_values(x[None, :], t_v, *wave)
    # cosθ_j, sinθ_j of the sampled segments from (Δx, Δy): the same as atan2, without trig.
    end = top.segment_end
    dx = np.broadcast_to(x[end] - x[end - 1], (times.size, end.size))
    dy = y[:, end] - y[:, end - 1]
    h = np.hypot(dx, dy)
    flat = h == 0.0  # zero-length rest segments: nothing to turn
    h[flat] = 1.0
    return bend_chains_cs(groom, axes, np.where(flat, 1.0, dx / h), dy / h)


@njit(cache=True, nogil=True, parallel=True)
def _pose_kernel(
    points, offsets, x, envelope, cos_x, sin_x, times, axes, scale, shift, a, s, period, out
):  # pragma: no cover
    """Eq. (1) with cos(x/k − ωt) = cos(x/k)cos(ωt) + sin(x/k)sin(ωt): no trig per node and pose."""
    omega = 2.0 * math.pi / period
    for si in prange(offsets.size - 1):
        lo, hi = offsets[si], offsets[si + 1]
        ax0, ax1, ax2 = axes[si, 0], axes[si, 1], axes[si, 2]
        amp = -scale[si] * a / s
        for pi in range(times.size):
            cw = math.cos(omega * (times[pi] + shift[si]))
            sw = math.sin(omega * (times[pi] + shift[si]))
            px, py, pz = points[lo, 0], points[lo, 1], points[lo, 2]
            out[pi, lo, 0], out[pi, lo, 1], out[pi, lo, 2] = px, py, pz
            y_prev = amp * envelope[lo] * (cos_x[lo] * cw + sin_x[lo] * sw + 1.0 / s)
            for v in range(lo + 1, hi):
                y = amp * envelope[v] * (cos_x[v] * cw + sin_x[v] * sw + 1.0 / s)
                dx = x[v] - x[v - 1]
                dy = y - y_prev
                y_prev = y
                h = math.sqrt(dx * dx + dy * dy)
                c, sn = (1.0, 0.0) if h == 0.0 else (dx / h, dy / h)
                r0 = points[v, 0] - points[v - 1, 0]
                r1 = points[v, 1] - points[v - 1, 1]
                r2 = points[v, 2] - points[v - 1, 2]
                # Rodrigues: (r − w) cosθ + (â × r) sinθ + w, with w = â(â·r)
                dot = ax0 * r0 + ax1 * r1 + ax2 * r2
                w0, w1, w2 = ax0 * dot, ax1 * dot, ax2 * dot
                px += (r0 - w0) * c + (ax1 * r2 - ax2 * r1) * sn + w0
                py += (r1 - w1) * c + (ax2 * r0 - ax0 * r2) * sn + w1
                pz += (r2 - w2) * c + (ax0 * r1 - ax1 * r0) * sn + w2
                out[pi, v, 0], out[pi, v, 1], out[pi, v, 2] = px, py, pz


def pose_numba(groom: Groom, times: F64, axes: F64, scale: F64, shift: F64, wave: tuple[float, ...]) -> F64:
    """:func:`pose_reference` in one pass per strand, parallel over strands (same bits, any thread count).

    Parameters
    ----------
    groom, times, axes, scale, shift, wave
        As :func:`pose_reference` takes them.

    Returns
    -------
    ndarray
        ``(P, V, 3)`` float64, the same bits.
    """
    a, k, s, p, period = (float(w) for w in wave)
    x = wave_x(groom)
    out = np.empty((times.size, groom.vertex_count, 3))
    _pose_kernel(
        groom.points.astype(np.float64),
        groom.offsets,
        x,
        (x / np.pi) ** p,  # the root-to-tip envelope (x/π)^p and cos, sin of x/k: the same every pose
        np.cos(x / k),
        np.sin(x / k),
        readonly(np.ascontiguousarray(times, dtype=np.float64)),
        np.ascontiguousarray(axes, dtype=np.float64),
        np.ascontiguousarray(scale, dtype=np.float64),
        np.ascontiguousarray(shift, dtype=np.float64),
        a,
        s,
        period,
        out,
    )
    return out
