"""FreezeDeform (Kim 2026, eqs. 2–7): stiffness-limited random stretch and bend of every segment.

Frozen hair barely stretches or bends; the method perturbs each rest segment by a small random
length change (alpha_s = 1/k_s) and a small random rotation (alpha_b·theta_max = theta_max/k_b),
rebuilding the strand from the root. The noise is a hash of (seed, strand, vertex), never a
running generator, so a strand's look does not depend on the thread count, on other strands, or
on how often the groom was updated. :func:`freeze` is the numba kernel, :func:`freeze_reference`
its plain numpy twin.
"""

from __future__ import annotations

import numpy as np
from numba import prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.frozen.noise import (
    CH_BEND,
    CH_STRAND,
    CH_STRETCH,
    EPS,
    check_seed,
    hash_head_nb,
    hash_tail_u01_nb,
    hash_u01,
    seed_u64,
)
from hairtool.groom import Groom
from hairtool.kernel_arrays import readonly
from hairtool.rotation import any_perpendicular, normalize, perpendicular_axis, rotate
from hairtool.serial_twins import twin_njit

AXIS_EPS = 1e-6  # |t̂[i−1] × t̂[i]| below this: the tangents are parallel, the cross gives no axis
MAX_STIFFNESS = 1e9
MAX_VARIATION = 4.0


def strand_multipliers(strand_count: int, variation: float | ArrayLike, seed: int = 0) -> NDArray[np.float64]:
    """``(S,)`` per-strand stiffness multipliers (the paper's strand-wise intensity variation).

    A number is a spread: multiplier = 2**(spread·U(−1,1)), seeded per strand (spread 1 gives
    ×0.5 … ×2). An array gives the multipliers directly (positive, one per strand).

    Parameters
    ----------
    strand_count : int
        S.
    variation : float or array_like
        A spread ≥ 0, or ``(S,)`` positive multipliers.
    seed : int, default 0
        The seed of the spread's draws.

    Returns
    -------
    ndarray
        ``(S,)`` float64 multipliers.
    """
    if np.ndim(variation) == 0:
        spread = float(variation)  # type: ignore[arg-type]
        if not np.isfinite(spread) or not 0.0 <= spread <= MAX_VARIATION:
            raise ParameterError("strand_variation", variation, f"a number in [0, {MAX_VARIATION:g}]")
        if spread == 0.0:
            return np.ones(strand_count)
        u = hash_u01(seed, np.arange(strand_count), 0, CH_STRAND)
        return np.exp2(spread * (2.0 * u - 1.0))
    m = np.asarray(variation, dtype=np.float64)
    if m.shape != (strand_count,):
        raise ParameterError("strand_variation", f"array of shape {m.shape}", f"shape ({strand_count},)")
    if not np.all(np.isfinite(m)) or np.any(m <= 0):
        raise ParameterError("strand_variation", "array", "positive finite multipliers")
    return m.copy()


def check_freeze_params(stretch_stiffness: float, bend_stiffness: float, max_bend_angle: float) -> None:
    """A ParameterError naming the first of FreezeDeform's parameters out of its range.

    Parameters
    ----------
    stretch_stiffness : float
        k_s of eq. 3, in [1, MAX_STIFFNESS].
    bend_stiffness : float
        k_b of eq. 4, in (0, MAX_STIFFNESS].
    max_bend_angle : float
        The largest turn in radians, in [0, π].
    """
    ks, kb, th = float(stretch_stiffness), float(bend_stiffness), float(max_bend_angle)
    if not np.isfinite(ks) or not 1.0 <= ks <= MAX_STIFFNESS:
        # Below 1 a target length l0·(1 + eta/k_s) could turn negative.
        raise ParameterError("stretch_stiffness", stretch_stiffness, f"a number in [1, {MAX_STIFFNESS:g}]")
    if not np.isfinite(kb) or not 0.0 < kb <= MAX_STIFFNESS:
        raise ParameterError("bend_stiffness", bend_stiffness, f"a number in (0, {MAX_STIFFNESS:g}]")
    if not np.isfinite(th) or not 0.0 <= th <= np.pi:
        raise ParameterError("max_bend_angle", max_bend_angle, "an angle in [0, pi] radians")


def _effective(groom, stretch_stiffness, bend_stiffness, max_bend_angle, seed, strand_variation):
    check_freeze_params(stretch_stiffness, bend_stiffness, max_bend_angle)
    seed = check_seed(seed)
    m = strand_multipliers(groom.strand_count, strand_variation, seed)
    # k_s·m is kept ≥ 1 so that 1 + alpha_s·eta never goes below 0.
    return np.maximum(float(stretch_stiffness) * m, 1.0), float(bend_stiffness) * m, seed


@twin_njit(nogil=True, parallel=True)
def _freeze_kernel(rest, offsets, ks, kb, theta_max, seed, planar, out):
    s_count = offsets.size - 1
    for s in prange(s_count):
        o = offsets[s]
        n = offsets[s + 1] - o
        alpha_s = 1.0 / (ks[s] + EPS)  # (3)
        alpha_b = 1.0 / (kb[s] + EPS)  # (4)
        head_s = hash_head_nb(seed, s, CH_STRETCH)  # per strand; one mix per vertex below
        head_b = hash_head_nb(seed, s, CH_BEND)
        px = np.float64(rest[o, 0])
        py = np.float64(rest[o, 1])
        pz = np.float64(rest[o, 2])
        out[o, 0], out[o, 1], out[o, 2] = rest[o, 0], rest[o, 1], rest[o, 2]
        qx = qy = qz = 0.0  # t̂[i−1]
        for i in range(1, n):
            dx = np.float64(rest[o + i, 0]) - np.float64(rest[o + i - 1, 0])  # (2)
            dy = np.float64(rest[o + i, 1]) - np.float64(rest[o + i - 1, 1])
            dz = np.float64(rest[o + i, 2]) - np.float64(rest[o + i - 1, 2])
            l0 = np.sqrt(dx * dx + dy * dy + dz * dz)
            tx, ty, tz = dx / (l0 + EPS), dy / (l0 + EPS), dz / (l0 + EPS)
            eta = 2.0 * hash_tail_u01_nb(head_s, i) - 1.0
            xi = 2.0 * hash_tail_u01_nb(head_b, i) - 1.0
            lstar = l0 * (1.0 + alpha_s * eta)  # (3)
            theta = theta_max * alpha_b * xi  # (4)
            # axis â = t̂[i−1] × t̂[i] / |…| (4), or a fallback where the tangents are parallel
            ax = qy * tz - qz * ty
            ay = qz * tx - qx * tz
            az = qx * ty - qy * tx
            an = np.sqrt(ax * ax + ay * ay + az * az)
            if i > 1 and an > AXIS_EPS:
                ax, ay, az = ax / an, ay / an, az / an
            elif planar:
                ax, ay, az = 0.0, 0.0, 1.0
            else:  # t̂ × e_k with k the axis least aligned with t̂ (as rotation.any_perpendicular)
                ax, ay, az = perpendicular_axis(tx, ty, tz)
            # Rodrigues (5)–(6): d̃ = d cosθ + (â × d) sinθ + â (â·d)(1 − cosθ)
            c = np.cos(theta)
            sn = np.sin(theta)
            ad = ax * dx + ay * dy + az * dz
            rx = dx * c + (ay * dz - az * dy) * sn + ax * ad * (1.0 - c)
            ry = dy * c + (az * dx - ax * dz) * sn + ay * ad * (1.0 - c)
            rz = dz * c + (ax * dy - ay * dx) * sn + az * ad * (1.0 - c)
            rn = np.sqrt(rx * rx + ry * ry + rz * rz)
            scale = lstar / (rn + EPS)  # (7)
            px += scale * rx
            py += scale * ry
            pz += scale * rz
            out[o + i, 0] = px
            out[o + i, 1] = py
            out[o + i, 2] = pz
            qx, qy, qz = tx, ty, tz


def freeze(
    groom: Groom,
    stretch_stiffness: float = 7.0,
    bend_stiffness: float = 7.0,
    max_bend_angle: float = np.radians(30.0),
    seed: int = 0,
    strand_variation: float | ArrayLike = 0.0,
) -> Groom:
    """FreezeDeform: the groom with every segment randomly stretched by at most 1/k_s of its rest
    length and turned by at most max_bend_angle/k_b (radians), rebuilt from the fixed roots.

    ``strand_variation`` scales both stiffnesses per strand (see :func:`strand_multipliers`).
    The result depends only on the inputs: same seed, same bytes.

    Parameters
    ----------
    groom
        The rest groom; FreezeDeform always starts from it, never from its own output.
    stretch_stiffness
        k_s of eq. 3, > 0: a segment's length changes by at most 1/k_s (7: about ±14 %).
    bend_stiffness
        k_b of eq. 4, > 0: a segment turns by at most ``max_bend_angle``/k_b.
    max_bend_angle
        θ_max in radians.
    seed
        The noise's seed: η and ξ are a function of (seed, strand, vertex).
    strand_variation
        A spread of per-strand stiffness (0: none), or ``(S,)`` multipliers.

    Returns
    -------
    Groom
        A new groom of the same topology and attributes; roots unchanged.

    Raises
    ------
    ParameterError
        A parameter is out of range; the message names it and its range.
    """
    ks, kb, seed = _effective(
        groom, stretch_stiffness, bend_stiffness, max_bend_angle, seed, strand_variation
    )
    points, back = _in_reference_axes(groom)
    out = np.empty_like(points)
    rest, offsets = readonly(points), readonly(groom.offsets)  # one signature: Y-up or Z-up
    _freeze_kernel(rest, offsets, ks, kb, float(max_bend_angle), seed_u64(seed), groom.is_planar, out)
    return groom.with_points(back(out))


def _in_reference_axes(groom: Groom):
    """The points in hairtool's reference axes (y up) and the map back: the fallback bend axis
    is picked among the coordinate axes, so a Z-up groom is frozen as its Y-up twin is. The
    axes differ by a signed permutation, so both maps are exact."""
    frame = groom.metadata.frame
    if groom.metadata.up_axis == "Y":
        return groom.points, lambda p: p
    ref = np.ascontiguousarray((groom.points.astype(np.float64) @ frame).astype(np.float32))
    return ref, lambda p: (np.asarray(p, np.float64) @ frame.T).astype(np.float32)


def freeze_reference(
    groom: Groom,
    stretch_stiffness: float = 7.0,
    bend_stiffness: float = 7.0,
    max_bend_angle: float = np.radians(30.0),
    seed: int = 0,
    strand_variation: float | ArrayLike = 0.0,
) -> Groom:
    """Plain numpy twin of :func:`freeze` (same noise, same fallbacks), for tests and benchmarks.

    Parameters
    ----------
    groom : Groom
        The groom at rest.
    stretch_stiffness, bend_stiffness, max_bend_angle, seed, strand_variation
        As :func:`freeze` takes them.

    Returns
    -------
    Groom
        What :func:`freeze` gives, to the last bit.
    """
    ks, kb, seed = _effective(
        groom, stretch_stiffness, bend_stiffness, max_bend_angle, seed, strand_variation
    )
    top = groom.topology
    points, back = _in_reference_axes(groom)
    p = points.astype(np.float64)
    end = top.segment_end
    s, i = top.strand_index[end], top.index_in_strand[end]
    d = p[end] - p[end - 1]  # (2)
    l0 = np.linalg.norm(d, axis=1)
    t = d / (l0[:, None] + EPS)
    eta = 2.0 * hash_u01(seed, s, i, CH_STRETCH) - 1.0
    xi = 2.0 * hash_u01(seed, s, i, CH_BEND) - 1.0
    lstar = l0 * (1.0 + eta / (ks[s] + EPS))  # (3)
    theta = float(max_bend_angle) * xi / (kb[s] + EPS)  # (4)
    t_prev = np.roll(t, 1, axis=0)  # segment k−1 is the previous one of the same strand when i > 1
    cross = np.cross(t_prev, t)
    cn = np.linalg.norm(cross, axis=1)
    has_axis = (i > 1) & (cn > AXIS_EPS)
    if groom.is_planar:
        fallback = np.tile([0.0, 0.0, 1.0], (len(t), 1))
    else:
        fallback = any_perpendicular(t)
        fallback[np.linalg.norm(fallback, axis=1) == 0] = [0.0, 0.0, 1.0]
    axis = np.where(has_axis[:, None], normalize(cross), fallback)
    dt = rotate(d, axis, theta)  # (5)–(6)
    step = lstar[:, None] * dt / (np.linalg.norm(dt, axis=1)[:, None] + EPS)  # (7)
    out = p.copy()
    for k in range(1, int(top.counts.max())):  # root outwards, all strands at once
        sel = i == k
        out[end[sel]] = out[end[sel] - 1] + step[sel]
    return groom.with_points(back(out))
