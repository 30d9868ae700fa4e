"""Motion capture for key-frame extraction (seed 003): features, the quaternion cost table, reconstruction.

Seed 003 measures poses by the quaternion distance Dist(q1, q2) = arccos(|w|), [w, x, y, z] =
q2 q1⁻¹ (half the rotation angle, radians), weighted per joint with the trunk heavier than the
limbs. The key-frame DP (hairtool.keys.dp) needs, for every candidate segment i < j, the
error of interpolating the frames between keys i and j: :func:`rotation_cost_table`.
"""

from __future__ import annotations

import os
from collections.abc import Callable

import numpy as np
from numba import get_num_threads, njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.kernel_arrays import aligned_rows, borrowed
from hairtool.keys.costs import check_frame_count
from hairtool.mocap import quaternion as quat
from hairtool.mocap.bvh import Motion, read_bvh

F64 = NDArray[np.float64]

KINDS = ("positions", "rotations")
INTERPS = ("linear", "hermite", "hermite-fit")


# ---------------------------------------------------------------------------------------
# Weights and features
# ---------------------------------------------------------------------------------------
def joint_weights(motion: Motion, falloff: float = 0.5) -> F64:
    """``(J,)`` ω_j = falloff^depth_j, normalised to sum 1.

    A parent's rotation moves all its children, so the trunk weighs most (seed 003, §3.2).

    Parameters
    ----------
    motion : Motion
        The capture.
    falloff : float, default 0.5
        The weight's factor per level of depth.

    Returns
    -------
    ndarray
        ``(J,)`` float64, summing to 1.
    """
    if not (np.isfinite(falloff) and 0.0 < falloff <= 1.0):
        raise ParameterError("falloff", falloff, "a number in (0, 1]")
    w = float(falloff) ** motion.depths().astype(np.float64)
    return w / w.sum()


def _check_weights(motion: Motion, weights: ArrayLike | None) -> F64:
    if weights is None:
        return joint_weights(motion)
    w = np.asarray(weights, dtype=np.float64)
    if w.shape != (motion.n_joints,):
        raise ParameterError("weights", w.shape, f"one weight per joint, shape ({motion.n_joints},)")
    if not np.all(np.isfinite(w)) or np.any(w < 0) or w.sum() <= 0:
        raise ParameterError("weights", "…", "finite, non-negative weights with a positive sum")
    return w


def skeleton_size(motion: Motion) -> float:
    """A length scale L for the root translation: the rest skeleton's bounding-box diagonal.

    Translation errors enter the rotation costs as (|Δp| / L)², so one skeleton size of drift
    weighs like one radian of joint rotation.

    Parameters
    ----------
    motion : Motion
        The capture.

    Returns
    -------
    float
        L, in the capture's units.
    """
    rest = motion.with_values(np.zeros((1, motion.n_channels)))
    p = rest.joint_positions(end_sites=True)[0]
    size = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))
    return size if size > 0 else 1.0


def motion_features(motion: Motion, kind: str = "positions", weights: ArrayLike | None = None) -> F64:
    """``(F, D)`` float64 per-frame features whose squared Euclidean distances carry the joint weights.

    - "positions": D = 3J. Joint positions relative to the root, each times sqrt(ω_j); the root's
      slot holds the root translation (times sqrt(ω_root)). Scene units.
    - "rotations": D = 4J + 3. Local quaternions hemisphere-aligned frame to frame, each times
      sqrt(ω_j), then the root translation / L times sqrt(ω_root) (L = :func:`skeleton_size`).
      |q_a − q_b|² ≈ Dist² for small angles; the exact seed metric is :func:`rotation_cost_table`.

    Parameters
    ----------
    motion : Motion
        The capture.
    kind : {"positions", "rotations"}, default "positions"
        Which features, as above.
    weights : array_like, optional
        ``(J,)`` joint weights ω (None: the defaults by joint name).

    Returns
    -------
    ndarray
        ``(F, D)`` float64 features.
    """
    if kind not in KINDS:
        raise ParameterError("kind", kind, f"one of {', '.join(KINDS)}")
    w = np.sqrt(_check_weights(motion, weights))
    if kind == "positions":
        p = motion.joint_positions()
        rel = p - p[:, :1]
        rel[:, 0] = p[:, 0]
        return (rel * w[None, :, None]).reshape(motion.n_frames, -1)
    q = quat.align_hemisphere(motion.local_rotations(), axis=0)
    root = motion.root_translation() / skeleton_size(motion)
    return np.concatenate([(q * w[None, :, None]).reshape(motion.n_frames, -1), root * w[0]], axis=1)


def bvh_features(
    path: str | os.PathLike[str], kind: str = "positions", weights: ArrayLike | None = None
) -> F64:
    """:func:`motion_features` of a BVH file.

    Parameters
    ----------
    path : str or os.PathLike
        A BVH file.
    kind : {"positions", "rotations"}, default "positions"
        Which features.
    weights : array_like, optional
        ``(J,)`` joint weights.

    Returns
    -------
    ndarray
        ``(F, D)`` float64.
    """
    return motion_features(read_bvh(path), kind, weights)


# ---------------------------------------------------------------------------------------
# The seed-003 segment cost table
# ---------------------------------------------------------------------------------------
def _cost_inputs(motion: Motion, weights, translation_weight):
    w = _check_weights(motion, weights)
    if translation_weight is None:
        translation_weight = float(w[0])
    if not (np.isfinite(translation_weight) and translation_weight >= 0):
        raise ParameterError("translation_weight", translation_weight, "a finite number ≥ 0")
    # (F, J, 4), aligned so that neighbouring frames share a hemisphere.
    q = np.ascontiguousarray(quat.align_hemisphere(motion.local_rotations(), axis=0))
    p = np.ascontiguousarray(motion.root_translation() / skeleton_size(motion))
    return q, p, w, float(translation_weight)


def rotation_cost_table(
    motion: Motion,
    weights: ArrayLike | None = None,
    interp: str = "slerp",
    translation_weight: float | None = None,
    max_span: int | None = None,
    progress: Callable[[float], None] | None = None,
) -> F64:
    """``(F, F)`` float64 cost of keying frames i and j and interpolating the frames between.

    cost[i, j] = Σ_{i<k<j} [ Σ_joints ω · Dist(q_k, slerp(q_i, q_j, (k−i)/(j−i)))²
                             + ω_T · |p_k − lerp(p_i, p_j, (k−i)/(j−i))|² / L² ]
    with Dist the seed's arccos(|w|) (radians, squared as in the seed's squared-distance fitting
    error), p the root translation, L = :func:`skeleton_size`, ω_T = ``translation_weight``
    (default ω_root). The table is symmetric (interpolation from j to i is the same curve);
    the diagonal and adjacent frames cost 0; pairs with |i − j| > ``max_span`` cost +inf (all
    pairs by default: O(F³·J) work, a DP over keys at most ``max_span`` apart needs O(F·span²·J)).
    Only "slerp" interpolation is offered. The kernel equals its numpy twin
    :func:`rotation_cost_table_reference` to float64 rounding: its arccos² is one of three
    polynomials exact to a few units in the last place (:func:`acos2_reference`). With
    ``progress``, the table is made in :data:`PROGRESS_STEPS` row ranges of equal work, saying
    after each what share is done (the same numbers).

    Parameters
    ----------
    motion : Motion
        The capture.
    weights : array_like, optional
        ``(J,)`` joint weights ω (None: the defaults by joint name).
    interp : {"slerp"}, default "slerp"
        The curve between keys.
    translation_weight : float, optional
        ω_T (None: ω_root).
    max_span : int, optional
        Pairs further apart cost +inf (None: every pair).
    progress : callable, optional
        ``progress(share)`` after each row range.

    Returns
    -------
    ndarray
        ``(F, F)`` float64 costs.
    """
    if interp != "slerp":
        raise ParameterError("interp", interp, "'slerp'")
    n = check_frame_count(motion.n_frames)
    if max_span is None:
        max_span = n
    if int(max_span) != max_span or max_span < 1:
        raise ParameterError("max_span", max_span, "a whole number of frames ≥ 1")
    q, p, w, wt = _cost_inputs(motion, weights, translation_weight)
    q = np.ascontiguousarray(q.transpose(1, 0, 2))
    span, hands = int(min(max_span, n)), max(1, min(n, get_num_threads()))
    cost = np.zeros((n, n))
    if progress is None:
        _cost_table_kernel(q, p, w, wt, span, hands, cost, 0, n)
    else:
        ranges = _row_ranges(n, span, PROGRESS_STEPS)
        for step, (lo, hi) in enumerate(ranges):
            _cost_table_kernel(q, p, w, wt, span, hands, cost, lo, hi)
            progress((step + 1) / len(ranges))
    return cost + cost.T


def rotation_cost_table_reference(
    motion: Motion,
    weights: ArrayLike | None = None,
    translation_weight: float | None = None,
    max_span: int | None = None,
) -> F64:
    """The numpy twin of :func:`rotation_cost_table` (slow: a Python loop over the pairs i < j).

    Parameters
    ----------
    motion : Motion
        The capture.
    weights : array_like, optional
        ``(J,)`` joint weights.
    translation_weight : float, optional
        ω_T (None: ω_root).
    max_span : int, optional
        Pairs further apart cost +inf.

    Returns
    -------
    ndarray
        ``(F, F)`` float64 costs, as :func:`rotation_cost_table` gives them.
    """
    q, p, w, wt = _cost_inputs(motion, weights, translation_weight)
    n = len(q)
    cost = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 2, n):
            cost[i, j] = _pair_cost_reference(q, p, w, wt, i, j)
    if max_span is not None:
        cost[np.triu(np.ones((n, n), dtype=bool), k=int(max_span) + 1)] = np.inf
    return cost + cost.T


def _pair_cost_reference(q: F64, p: F64, w: F64, wt: float, i: int, j: int) -> float:
    """cost[i, j] of :func:`rotation_cost_table_reference` from :func:`_cost_inputs`' arrays."""
    t = (np.arange(i + 1, j) - i) / (j - i)
    s = quat.slerp(q[i][None], q[j][None], t[:, None])  # (k, J, 4)
    d = quat.distance(q[i + 1 : j], s)
    lin = p[i] + t[:, None] * (p[j] - p[i])
    return float(np.sum(w[None, :] * d * d) + wt * np.sum((p[i + 1 : j] - lin) ** 2))


#: The kernel's only fast-math flag: "contract" fuses a multiply and an add into one FMA (one
#: rounding instead of two). Nothing approximates a function or a reciprocal, nothing reorders sums.
_EXACT = {"contract"}

#: Segment ends per sub-block: each takes the shortest arccos² polynomial its largest gap allows
#: (measured on a 1,300-frame walk: 64 and 512 ends were 3 % and 5 % slower than 256).
_SUB = 256

# arccos(1 − u)² = u·h(u), h a polynomial in u (Chebyshev interpolation of h in 80-bit floats,
# then monomial coefficients), on [0, 1/16] (θ ≤ 20.4°), [0, 1/4] (θ ≤ 41.4°) and [0, 1]
# (θ ≤ 90°). Largest relative error in float64, measured: 5.4e-16, 1.1e-15 and 2.0e-15.
_U1, _U2 = 1.0 / 16.0, 0.25
#: The same bounds as int64 bit patterns: for u ≥ 0 they order as the floats, and an integer
#: maximum vectorises without fast-math.
_U1_BITS, _U2_BITS = 4589168020290535424, 4598175219545276416


@njit(cache=True, nogil=True, fastmath=_EXACT, inline="always")
def _acos2_near(u):
    """arccos(1 − u)² for 0 ≤ u ≤ 1/16."""
    h = 0.0016587757106338228
    h = h * u + 0.003836902789771557
    h = h * u + 0.01015915616192485
    h = h * u + 0.028571420933181862
    h = h * u + 0.08888888893728109
    h = h * u + 0.3333333333334162
    h = h * u + 1.9999999999999993
    return u * h


@njit(cache=True, nogil=True, fastmath=_EXACT, inline="always")
def _acos2_mid(u):
    """arccos(1 − u)² for 0 ≤ u ≤ 1/4."""
    h = 0.00020308569073677064
    h = h * u + 0.00020115391816943884
    h = h * u + 0.00064151104161283
    h = h * u + 0.0015182428560365224
    h = h * u + 0.003848517351804048
    h = h * u + 0.010158689544002186
    h = h * u + 0.028571430492193305
    h = h * u + 0.0888888888393425
    h = h * u + 0.3333333333339091
    h = h * u + 1.9999999999999982
    return u * h


@njit(cache=True, nogil=True, fastmath=_EXACT, inline="always")
def _acos2_far(u):
    """arccos(1 − u)² for 0 ≤ u ≤ 1."""
    h = 3.4761421071986355e-05
    h = h * u - 0.00024251604271638725
    h = h * u + 0.0008069299340907795
    h = h * u - 0.0016465834701698946
    h = h * u + 0.002308452547721471
    h = h * u - 0.0023095900668168826
    h = h * u + 0.001748620558582085
    h = h * u - 0.0009182387609061809
    h = h * u + 0.0005183182390656861
    h = h * u + 0.0001309088526161912
    h = h * u + 0.0006519955169871485
    h = h * u + 0.0015170739473920644
    h = h * u + 0.0038486357622751597
    h = h * u + 0.010158678453392354
    h = h * u + 0.028571431233411215
    h = h * u + 0.08888888881200444
    h = h * u + 0.3333333333343413
    h = h * u + 1.9999999999999964
    return u * h


def acos2_reference(u: ArrayLike) -> F64:
    """arccos(1 − u)², the numpy twin of the kernel's three polynomials (:func:`_acos2_near`, …),
    written (2·arcsin √(u/2))² so that it keeps its digits for small u too.

    Parameters
    ----------
    u : array_like
        1 − cos, in [0, 1].

    Returns
    -------
    ndarray
        float64, radians squared.
    """
    return (2.0 * np.arcsin(np.sqrt(np.asarray(u, dtype=np.float64) / 2.0))) ** 2


@njit(cache=True, nogil=True, parallel=True)
def _cost_table_kernel(q, p, w, wt, max_span, n_hands, cost, row_lo, row_hi):
    """Rows ``row_lo … row_hi − 1`` of the upper triangle of the cost table (into ``cost``, zeros)
    from q ``(J, F, 4)``; pairs farther apart than ``max_span`` get +inf. Each row i is computed
    by one thread, so the result depends neither on the thread count nor on the row ranges."""
    n = q.shape[1]
    # Row i costs ~(n − i)²: deal rows like cards (i ≡ c mod n_hands), one hand per thread, so
    # every thread gets the same work to within one row.
    for c in prange(n_hands):
        for i in range(row_lo + c, row_hi, n_hands):
            j_end = min(n, i + max_span + 1)
            _cost_row(q, p, w, wt, i, j_end, cost[i])
            for j in range(j_end, n):
                cost[i, j] = np.inf


#: Row ranges of about equal work a table is made in when a progress bar follows it.
PROGRESS_STEPS = 20


def _row_ranges(n: int, span: int, steps: int) -> list[tuple[int, int]]:
    """``steps`` consecutive row ranges of about equal work (row i costs ~min(n − i, span)²)."""
    work = np.cumsum(np.minimum(n - np.arange(n), span).astype(np.float64) ** 2)
    cuts = np.searchsorted(work, work[-1] * np.arange(1, steps) / steps)
    edges = np.unique(np.concatenate([[0], cuts, [n]]))
    return list(zip(edges[:-1].tolist(), edges[1:].tolist(), strict=True))


#: Segment ends l = j − i handled together: the eleven arrays a block's passes touch (acc, ca, sa,
#: cd, sd, live, e0-e2, gap, gap2: 44 KB) stay in the 48 KB L1 cache.
_BLOCK = 512


@njit(cache=True, nogil=True, inline="always")
def _cos_sin_small(d):
    """cos d and sin d for 0 ≤ d ≤ π/4 by their Taylor series to d¹⁸ (terms below 2e-18): a
    polynomial, so the loop that uses it vectorises, and as exact as libm there."""
    d2 = d * d
    c = 1.0 / 6402373705728000.0  # 1/18!
    c = c * d2 - 1.0 / 20922789888000.0
    c = c * d2 + 1.0 / 87178291200.0
    c = c * d2 - 1.0 / 479001600.0
    c = c * d2 + 1.0 / 3628800.0
    c = c * d2 - 1.0 / 40320.0
    c = c * d2 + 1.0 / 720.0
    c = c * d2 - 1.0 / 24.0
    c = c * d2 + 0.5
    s = 1.0 / 355687428096000.0  # 1/17!
    s = s * d2 - 1.0 / 1307674368000.0
    s = s * d2 + 1.0 / 6227020800.0
    s = s * d2 - 1.0 / 39916800.0
    s = s * d2 + 1.0 / 362880.0
    s = s * d2 - 1.0 / 5040.0
    s = s * d2 + 1.0 / 120.0
    s = s * d2 - 1.0 / 6.0
    return 1.0 - c * d2, d + d * (s * d2)


@njit(cache=True, nogil=True, fastmath=_EXACT, inline="always")
def _across(q, b, k, qi0, qi1, qi2, qi3):
    """q[b, k] in the orthonormal basis (q_i, q_i·i, q_i·j, q_i·k) of quaternion space: its part
    along q_i and its three coordinates across it (multiplying by a unit quaternion on the left
    is a rotation of R⁴, so the four are orthonormal)."""
    a0, a1, a2, a3 = q[b, k, 0], q[b, k, 1], q[b, k, 2], q[b, k, 3]
    along = a0 * qi0 + a1 * qi1 + a2 * qi2 + a3 * qi3
    v0 = -a0 * qi1 + a1 * qi0 + a2 * qi3 - a3 * qi2
    v1 = -a0 * qi2 - a1 * qi3 + a2 * qi0 + a3 * qi1
    v2 = -a0 * qi3 + a1 * qi2 - a2 * qi1 + a3 * qi0
    return along, v0, v1, v2


@njit(cache=True, nogil=True, fastmath=_EXACT, inline="always")
def _skip_frame(ca, sa, cd, sd, e0, e1, e2, live, gap, dk, qk0, qk1, qk2, lo, hi):
    """Frame k's gap u = 1 − |q_k · slerp| = 1 − cos Dist in every segment end l in [lo, hi)
    (min(u, live): 0 where ``live`` is 0, u where it is 2), and each end's (cos, sin) one step on.
    The views start at 0 so the compiler sees plain non-negative indices and vectorises."""
    ca, sa, cd, sd, live = ca[lo:hi], sa[lo:hi], cd[lo:hi], sd[lo:hi], live[lo:hi]
    e0, e1, e2, gap = e0[lo:hi], e1[lo:hi], e2[lo:hi], gap[lo:hi]
    for l in range(hi - lo):
        c0, s0, c1, s1 = ca[l], sa[l], cd[l], sd[l]
        x = abs(c0 * dk + s0 * (qk0 * e0[l] + qk1 * e1[l] + qk2 * e2[l]))
        gap[l] = min(max(1.0 - x, 0.0), live[l])
        ca[l] = c0 * c1 - s0 * s1
        sa[l] = s0 * c1 + c0 * s1


@njit(cache=True, nogil=True, fastmath=_EXACT, inline="always")
def _skip_two_frames(
    ca, sa, cd, sd, e0, e1, e2, live, gap, gap2,
    dk, qk0, qk1, qk2, dn, qn0, qn1, qn2, dead, lo, hi,
):  # fmt: skip
    """:func:`_skip_frame` for frames k and k + 1 in one pass over the ends' state, which halves
    its loads and stores (1.10x faster than one frame per pass, four frames were slower: on a
    1,000-frame walk); end ``dead`` (relative to lo; outside [lo, hi) when none) skips frame k
    but ends at k + 1."""
    ca, sa, cd, sd, live = ca[lo:hi], sa[lo:hi], cd[lo:hi], sd[lo:hi], live[lo:hi]
    e0, e1, e2, gap, gap2 = e0[lo:hi], e1[lo:hi], e2[lo:hi], gap[lo:hi], gap2[lo:hi]
    for l in range(hi - lo):
        c0, s0, c1, s1 = ca[l], sa[l], cd[l], sd[l]
        f0, f1, f2 = e0[l], e1[l], e2[l]
        x = abs(c0 * dk + s0 * (qk0 * f0 + qk1 * f1 + qk2 * f2))
        gap[l] = max(1.0 - x, 0.0)
        c2 = c0 * c1 - s0 * s1
        s2 = s0 * c1 + c0 * s1
        x = abs(c2 * dn + s2 * (qn0 * f0 + qn1 * f1 + qn2 * f2))
        gap2[l] = max(1.0 - x, 0.0)
        ca[l] = c2 * c1 - s2 * s1
        sa[l] = s2 * c1 + c2 * s1
    # Lanes that take no part lie in the first vector (ends at or before k, l < 2) and the last
    # (padding): their gaps are zeroed there, not masked in the loop above (3 % of the table).
    for l in range(min(8, hi - lo)):
        if live[l] == 0.0:
            gap[l] = gap2[l] = 0.0
    for l in range(max(8, hi - lo - 8), hi - lo):
        if live[l] == 0.0:
            gap[l] = gap2[l] = 0.0
    if 0 <= dead < hi - lo:  # the end at k + 1
        gap2[dead] = 0.0


@njit(cache=True, nogil=True, fastmath=_EXACT, inline="always")
def _add_dist2_two(acc, gap, gap2, bits, bits2, lo, hi):
    """:func:`_add_dist2` of two frames' gaps in one pass over ``acc`` (their largest gap picks
    the polynomial)."""
    for s0 in range(lo, hi, _SUB):
        s1 = min(hi, s0 + _SUB)
        top = 0
        bv, bw = bits[s0:s1], bits2[s0:s1]
        for l in range(s1 - s0):
            top = max(top, max(bv[l], bw[l]))
        a, g, h = acc[s0:s1], gap[s0:s1], gap2[s0:s1]
        if top <= _U1_BITS:
            for l in range(s1 - s0):
                a[l] += _acos2_near(g[l]) + _acos2_near(h[l])
        elif top <= _U2_BITS:
            for l in range(s1 - s0):
                a[l] += _acos2_mid(g[l]) + _acos2_mid(h[l])
        else:
            for l in range(s1 - s0):
                a[l] += _acos2_far(g[l]) + _acos2_far(h[l])


@njit(cache=True, nogil=True, fastmath=_EXACT, inline="always")
def _add_dist2(acc, gap, bits, lo, hi):
    """acc[l] += arccos(1 − gap[l])² for l in [lo, hi): per sub-block of _SUB ends the polynomial
    that covers its largest gap (``bits``: the gaps' int64 view)."""
    for s0 in range(lo, hi, _SUB):
        s1 = min(hi, s0 + _SUB)
        top = 0
        bv = bits[s0:s1]
        for l in range(s1 - s0):
            top = max(top, bv[l])
        a, g = acc[s0:s1], gap[s0:s1]
        if top <= _U1_BITS:
            for l in range(s1 - s0):
                a[l] += _acos2_near(g[l])
        elif top <= _U2_BITS:
            for l in range(s1 - s0):
                a[l] += _acos2_mid(g[l])
        else:
            for l in range(s1 - s0):
                a[l] += _acos2_far(g[l])


@njit(cache=True, nogil=True, fastmath=_EXACT, inline="always")
def _skip_frame_translation(tr, inv_l, d0, d1, d2, r, pk0, pk1, pk2, lo, hi):
    """Frame k's squared distance to the root's lerp in every segment end l in [lo, hi)."""
    tr, inv_l, d0, d1, d2 = tr[lo:hi], inv_l[lo:hi], d0[lo:hi], d1[lo:hi], d2[lo:hi]
    for l in range(hi - lo):
        t = r * inv_l[l]
        r0 = pk0 - t * d0[l]
        r1 = pk1 - t * d1[l]
        r2 = pk2 - t * d2[l]
        tr[l] += r0 * r0 + r1 * r1 + r2 * r2


@njit(cache=True, nogil=True, fastmath=_EXACT)
def _cost_row(q, p, w, wt, i, j_end, out):
    """out[j] = cost[i, j] for i + 1 < j < j_end.

    Per (i, j, joint b) the slerp arc is s(t) = cos(tΩ) q_i + sin(tΩ) e with e the unit vector of
    ±q_j − cos Ω q_i, so q_k·s needs q_k·q_i and q_k·e; e lies across q_i, so q_k·e takes three
    products, not four, in coordinates across q_i (:func:`_across`: 4-6 % faster). The loops
    run k outer and l = j − i inner: every segment that skips frame k takes its term at once,
    each end l with its own cos and sin of (k − i)·δ_l (δ_l = Ω_l/l ≤ π/4) advanced by a
    rotation step. The inner loop has no dependence between iterations and no branch, so it
    runs in SIMD lanes; it takes two frames per pass. It stores the gaps u = 1 − cos Dist; a
    second pass adds arccos(1 − u)², each sub-block of ends with the shortest of three
    polynomials that is exact over its gaps (on captures ~90 % take the 7-term one). Lanes are
    padded to whole vectors, the ends that do not skip frame k weighted 0.
    """
    n_b = q.shape[0]
    m = j_end - i  # local index l = j − i
    # Lanes padded to whole SIMD vectors: a loop starts and ends on a multiple of 8 from its
    # block's start, a 64-byte boundary, and lanes that take no part (segments that end before
    # frame k, padding, l < 2) have weight 0 in ``live``, so no loop has a scalar remainder. The
    # ends' arrays are rows of one buffer, borrowed (no reference counting in the passes' views);
    # ``total`` keeps the buffer alive to the end.
    mp = m + 8
    lanes = aligned_rows(13, mp)
    total = lanes[12]
    acc, ca, sa = borrowed(lanes[0]), borrowed(lanes[1]), borrowed(lanes[2])
    cd, sd, live = borrowed(lanes[3]), borrowed(lanes[4]), borrowed(lanes[5])
    e0, e1, e2 = borrowed(lanes[6]), borrowed(lanes[7]), borrowed(lanes[8])
    dl, gap, gap2 = borrowed(lanes[9]), borrowed(lanes[10]), borrowed(lanes[11])
    cd[:] = 1.0
    bits = gap.view(np.int64)
    bits2 = gap2.view(np.int64)
    for b in range(n_b):
        qi0, qi1, qi2, qi3 = q[b, i, 0], q[b, i, 1], q[b, i, 2], q[b, i, 3]
        for l in range(2, m):
            c, v0, v1, v2 = _across(q, b, i + l, qi0, qi1, qi2, qi3)
            sign = 1.0
            if c < 0.0:
                sign = -1.0
                c = -c
            c = min(c, 1.0)
            sin_om = np.sqrt((1.0 - c) * (1.0 + c))  # no cancellation when Ω is small
            e0[l] = e1[l] = e2[l] = 0.0
            dl[l] = 0.0
            if sin_om >= 1e-9:  # else q_j ≈ ±q_i: the arc is the point q_i (seed 003's slerp: a line)
                inv = sign / sin_om
                e0[l], e1[l], e2[l] = v0 * inv, v1 * inv, v2 * inv
                dl[l] = np.arccos(c) / l
        for l in range(2, m):
            cd[l], sd[l] = _cos_sin_small(dl[l])
            ca[l], sa[l] = cd[l], sd[l]  # k − i = 1
            acc[l] = 0.0
            live[l] = 2.0  # above any gap: min(gap, live) keeps it
        for l0 in range(0, m, _BLOCK):  # from lane 0, aligned; lanes 0 and 1 weigh 0
            l1 = min(m, l0 + _BLOCK)
            hi = l0 + (l1 - l0 + 7) // 8 * 8
            r = 1
            while r < l1 - 1:  # frame k = i + r, skipped by every segment with l > r
                live[r] = 0.0  # segment l = r ends at k
                k = i + r
                dk, qk0, qk1, qk2 = _across(q, b, k, qi0, qi1, qi2, qi3)
                lo = l0 + max(r + 1 - l0, 0) // 8 * 8
                if r + 1 < l1 - 1:  # two frames per pass over the ends' state
                    dn, qn0, qn1, qn2 = _across(q, b, k + 1, qi0, qi1, qi2, qi3)
                    _skip_two_frames(
                        ca, sa, cd, sd, e0, e1, e2, live, gap, gap2,
                        dk, qk0, qk1, qk2, dn, qn0, qn1, qn2, r + 1 - lo, lo, hi,
                    )
                    _add_dist2_two(acc, gap, gap2, bits, bits2, lo, hi)
                    live[r + 1] = 0.0
                    r += 2
                else:
                    _skip_frame(ca, sa, cd, sd, e0, e1, e2, live, gap, dk, qk0, qk1, qk2, lo, hi)
                    _add_dist2(acc, gap, bits, lo, hi)
                    r += 1
        wb = w[b]
        for l in range(2, m):
            total[l] += wb * acc[l]
    # The root translation against its lerp, k outer and j inner the same way.
    tr = np.zeros(m)
    inv_l = np.zeros(m)
    d0 = np.zeros(m)
    d1 = np.zeros(m)
    d2 = np.zeros(m)
    for l in range(2, m):
        inv_l[l] = 1.0 / l
        d0[l] = p[i + l, 0] - p[i, 0]
        d1[l] = p[i + l, 1] - p[i, 1]
        d2[l] = p[i + l, 2] - p[i, 2]
    for r in range(1, m - 1):
        k = i + r
        pk0, pk1, pk2 = p[k, 0] - p[i, 0], p[k, 1] - p[i, 1], p[k, 2] - p[i, 2]
        _skip_frame_translation(tr, inv_l, d0, d1, d2, float(r), pk0, pk1, pk2, r + 1, m)
    for l in range(2, m):
        out[i + l] = total[l] + wt * tr[l]


# ---------------------------------------------------------------------------------------
# Reconstruction from keys
# ---------------------------------------------------------------------------------------
def _check_keys(keys: ArrayLike, n_frames: int) -> NDArray[np.int64]:
    k = np.asarray(keys)
    if k.ndim != 1 or k.size == 0:
        raise ParameterError("keys", k.shape, "a non-empty 1-D list of frame indices")
    if not np.issubdtype(k.dtype, np.integer):
        if not np.all(np.isfinite(k)) or np.any(k != np.round(k)):
            raise ParameterError("keys", "…", "whole frame numbers")
    k = np.unique(k.astype(np.int64))
    if k[0] < 0 or k[-1] >= n_frames:
        raise ParameterError("keys", f"{k[0]}..{k[-1]}", f"frames in [0, {n_frames - 1}]")
    return k


def _segments(keys: NDArray[np.int64], n: int):
    """For each frame: the key segment (a, b) it lies in and t ∈ [0, 1]; frames outside hold the end key."""
    f = np.arange(n)
    seg = np.clip(np.searchsorted(keys, f, side="right") - 1, 0, max(len(keys) - 2, 0))
    a = keys[seg]
    b = keys[np.minimum(seg + 1, len(keys) - 1)]
    span = np.maximum(b - a, 1)
    t = np.clip((f - a) / span, 0.0, 1.0)
    return a, b, t


def _sample_tangents(x: F64) -> F64:
    """Seed 003's tangents: the mean of the vectors to the previous and next sample, one-sided at the ends."""
    m = np.empty_like(x)
    if len(x) == 1:
        m[:] = 0.0
        return m
    m[1:-1] = 0.5 * (x[2:] - x[:-2])
    m[0] = x[1] - x[0]
    m[-1] = x[-1] - x[-2]
    return m


def _hermite(x: F64, keys: NDArray[np.int64]) -> F64:
    """Cubic Hermite through the key samples of ``x`` (frames on axis 0), tangents per frame."""
    n = len(x)
    a, b, t = _segments(keys, n)
    m = _sample_tangents(x)
    span = (b - a).astype(np.float64)
    t = t.reshape((-1,) + (1,) * (x.ndim - 1))
    span = span.reshape(t.shape)
    t2, t3 = t * t, t * t * t
    h00 = 2 * t3 - 3 * t2 + 1
    h10 = t3 - 2 * t2 + t
    h01 = -2 * t3 + 3 * t2
    h11 = t3 - t2
    return h00 * x[a] + h10 * span * m[a] + h01 * x[b] + h11 * span * m[b]


def _linear(x: F64, keys: NDArray[np.int64]) -> F64:
    a, b, t = _segments(keys, len(x))
    t = t.reshape((-1,) + (1,) * (x.ndim - 1))
    return x[a] + t * (x[b] - x[a])


def _fitted(x: F64, keys: NDArray[np.int64]) -> F64:
    """Hermite with each segment's handles fitted to its samples (:mod:`hairtool.keys.segment_fit`)."""
    from hairtool.keys.reconstruct import interpolate_keys, key_poses

    flat = x.reshape(len(x), -1)
    return interpolate_keys(key_poses(flat, keys, "hermite-fit")).reshape(x.shape)


def _unwrap_near(angles: F64, reference: F64) -> F64:
    """Shift angles (degrees) by whole turns to lie nearest the original channel values."""
    return angles + 360.0 * np.round((reference - angles) / 360.0)


def reconstruct_motion(motion: Motion, keys: ArrayLike, interp: str = "linear") -> Motion:
    """The motion rebuilt from its key frames alone, with the same skeleton and channel layout.

    - "linear": slerp of each joint's local rotation between keys; lerp of position channels.
    - "hermite": seed 003's cubic Hermite (tangents from the neighbouring samples at each key)
      applied to the hemisphere-aligned quaternion components, then renormalised; the same
      Hermite on position channels.
    - "hermite-fit": the same with each segment's handles fitted to its samples by least squares
      (keys must then include the first and last frame, as the DP's always do).
    Rotations go back to Euler angles in each joint's channel order (nearest the original values
    by whole turns). Joints with one or two rotation channels interpolate their angles directly.
    Frames before the first key or after the last hold that key.

    Parameters
    ----------
    motion : Motion
        The capture.
    keys : array_like
        Key frame numbers, ascending.
    interp : {"linear", "hermite", "hermite-fit"}, default "linear"
        The curve through the keys.

    Returns
    -------
    Motion
        Every frame rebuilt from the keys.
    """
    if interp not in INTERPS:
        raise ParameterError("interp", interp, f"one of {', '.join(INTERPS)}")
    keys = _check_keys(keys, motion.n_frames)
    values = motion.values.copy()
    q_all = quat.align_hemisphere(motion.local_rotations(), axis=0)
    a, b, t = _segments(keys, motion.n_frames)
    start = 0
    for j, chans in enumerate(motion.channels):
        cols = np.arange(start, start + len(chans))
        start += len(chans)
        rot = [c for c, name in zip(cols, chans, strict=True) if name.endswith("rotation")]
        pos = [c for c, name in zip(cols, chans, strict=True) if name.endswith("position")]
        interpolate = {"linear": _linear, "hermite": _hermite, "hermite-fit": _fitted}[interp]
        if pos:
            values[:, pos] = interpolate(motion.values[:, pos], keys)
        if not rot:
            continue
        order = "".join(motion.channels[j][c - cols[0]][0] for c in rot)
        if len(set(order)) < 3:
            values[:, rot] = interpolate(motion.values[:, rot], keys)
            continue
        q = q_all[:, j]
        if interp == "linear":
            qr = quat.slerp(q[a], q[b], t)
        else:
            qr = quat.normalize(interpolate(q, keys))
        values[:, rot] = _unwrap_near(quat.to_euler(qr, order), motion.values[:, rot])
    return motion.with_values(values)


def joint_position_errors(motion: Motion, reconstructed: Motion) -> F64:
    """``(F, J)`` distances (scene units) between the joints of two motions of one skeleton.

    Parameters
    ----------
    motion, reconstructed : Motion
        Two motions of one skeleton and frame count.

    Returns
    -------
    ndarray
        ``(F, J)`` float64 distances.
    """
    if reconstructed.n_joints != motion.n_joints or reconstructed.n_frames != motion.n_frames:
        raise ParameterError(
            "reconstructed",
            f"{reconstructed.n_frames} frames × {reconstructed.n_joints} joints",
            f"{motion.n_frames} frames × {motion.n_joints} joints",
        )
    d = motion.joint_positions() - reconstructed.joint_positions()
    return np.sqrt(np.einsum("fjc,fjc->fj", d, d))
