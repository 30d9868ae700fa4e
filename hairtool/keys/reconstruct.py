"""Rebuild every frame from key poses, measure position errors, and describe where keys fall.

Works on the original vertices (scene units), not on the features: ``frames`` is any
``(F, ...)`` array, usually an Animation's ``(F, V, 3)``. Hermite tangents at a key are the
averaged neighbouring differences of the original samples (seed 003), stored with the key.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.groom import Animation
from hairtool.kernel_arrays import readonly
from hairtool.keys.costs import INTERPOLATIONS
from hairtool.keys.dp import uniform_keys
from hairtool.keys.gram import tangent_stencil

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

_CHUNK_VALUES = 8_000_000  # float64 values rebuilt per chunk of frames


def check_keys(keys: ArrayLike, n_frames: int) -> I64:
    """Strictly increasing whole frame numbers from 0 to n_frames − 1.

    Parameters
    ----------
    keys : array_like
        Key frames.
    n_frames : int
        The animation's frame count.

    Returns
    -------
    ndarray
        The keys, int64 (ParameterError otherwise).
    """
    k = np.asarray(keys)
    if k.ndim != 1 or k.size < 2:
        raise ParameterError("keys", k.tolist() if k.size < 8 else "array", "at least 2 frame numbers")
    if not np.issubdtype(k.dtype, np.integer):
        if not np.all(np.isfinite(k)) or np.any(k != np.round(k)):
            raise ParameterError("keys", k.tolist(), "whole frame numbers")
    k = k.astype(np.int64)
    if k[0] != 0 or k[-1] != n_frames - 1 or np.any(np.diff(k) <= 0):
        raise ParameterError("keys", k.tolist(), f"strictly increasing frames from 0 to {n_frames - 1}")
    return k


@dataclass
class KeyPoses:
    """Key frames, their poses ``(K, ...)`` and, for Hermite, tangents ``(K, ...)`` per frame.

    ``tangents`` leave each key (the start of the segment after it); ``tangents_in`` arrive at
    each key (the end of the segment before it), for broken handles ("hermite-fit"); None means
    the same as ``tangents`` (seed 003's data tangents are one per key).
    """

    keys: I64
    poses: F64
    tangents: F64 | None
    n_frames: int
    interp: str
    tangents_in: F64 | None = None

    def with_pose(self, key_frame: int, pose: ArrayLike) -> KeyPoses:
        """A copy with the pose at ``key_frame`` (a frame number that is a key) replaced.

        Parameters
        ----------
        key_frame : int
            A frame that is a key.
        pose : array_like
            The new pose, shaped as one frame.

        Returns
        -------
        KeyPoses
            The copy; its tangents stay as they were.
        """
        hit = np.flatnonzero(self.keys == key_frame)
        if hit.size == 0:
            raise ParameterError("key_frame", key_frame, f"one of the keys {self.keys.tolist()}")
        p = np.asarray(pose, dtype=np.float64)
        if p.shape != self.poses.shape[1:] or not np.all(np.isfinite(p)):
            raise ParameterError("pose", f"shape {p.shape}", f"finite values of shape {self.poses.shape[1:]}")
        poses = self.poses.copy()
        poses[hit[0]] = p
        return KeyPoses(self.keys, poses, self.tangents, self.n_frames, self.interp, self.tangents_in)


def key_poses(frames: ArrayLike, keys: ArrayLike, interp: str = "linear") -> KeyPoses:
    """Take the key poses (and Hermite tangents) out of the full-rate frames; "hermite-fit"
    fits each segment's two handles to its frames by least squares
    (:func:`hairtool.keys.segment_fit.fit_segment`).

    Parameters
    ----------
    frames : array_like
        ``(F, ...)`` the full-rate frames.
    keys : array_like
        Key frame numbers, ascending, first and last frame included.
    interp : {"linear", "hermite", "hermite-fit"}, default "linear"
        The curve through the keys.

    Returns
    -------
    KeyPoses
        The keys' poses and, for Hermite curves, their tangents.
    """
    if interp not in INTERPOLATIONS:
        raise ParameterError("interp", interp, " or ".join(INTERPOLATIONS))
    f = np.asarray(frames)
    k = check_keys(keys, f.shape[0])
    if interp == "hermite-fit":
        return _fitted_key_poses(f, k)
    tangents = None
    if interp == "hermite":
        lo, hi, w = (a[k] for a in tangent_stencil(f.shape[0]))
        tangents = (f[hi].astype(np.float64) - f[lo]) * w.reshape((-1,) + (1,) * (f.ndim - 1))
    return KeyPoses(k, f[k].astype(np.float64), tangents, int(f.shape[0]), interp)


def _fitted_key_poses(f: NDArray, k: I64) -> KeyPoses:
    from hairtool.keys.segment_fit import fit_segment

    flat = f.reshape(f.shape[0], -1)
    out_t = np.empty((k.size, flat.shape[1]))
    in_t = np.empty((k.size, flat.shape[1]))
    for a in range(k.size - 1):
        el = float(k[a + 1] - k[a])
        start, end, _ = fit_segment(flat, int(k[a]), int(k[a + 1]))
        out_t[a], in_t[a + 1] = start / el, end / el
    out_t[-1], in_t[0] = in_t[-1], out_t[0]  # the ends have one side: both handles the same
    shape = (k.size, *f.shape[1:])
    return KeyPoses(
        k, f[k].astype(np.float64), out_t.reshape(shape), int(f.shape[0]), "hermite-fit", in_t.reshape(shape)
    )


def interpolate_keys(kp: KeyPoses, dtype: type = np.float64) -> NDArray:
    """``(F, ...)`` frames rebuilt from the key poses; exact at the keys.

    Parameters
    ----------
    kp : KeyPoses
        The key poses and tangents.
    dtype : type, default numpy.float64
        The result's dtype.

    Returns
    -------
    ndarray
        ``(F, ...)`` frames.
    """
    n = kp.n_frames
    out = np.empty((n, *kp.poses.shape[1:]), dtype=dtype)
    chunk = max(1, _CHUNK_VALUES // max(1, int(np.prod(kp.poses.shape[1:]))))
    for f0 in range(0, n, chunk):
        t = np.arange(f0, min(n, f0 + chunk))
        out[t] = interpolate_at(kp, t)
    return out


def interpolate_at(kp: KeyPoses, frames: ArrayLike, dtype: type = np.float64) -> NDArray:
    """``(len(frames), ...)`` the key curve (linear or Hermite) at the given frame numbers only:
    what a studio scrubbing through a long animation asks for, one frame at a time.

    Parameters
    ----------
    kp : KeyPoses
        The key poses and tangents.
    frames : array_like
        Frame numbers, each in [0, F).
    dtype : type, default numpy.float64
        The result's dtype.

    Returns
    -------
    ndarray
        ``(len(frames), ...)``.
    """
    t = np.asarray(frames, dtype=np.int64).reshape(-1)
    if t.size and (t.min() < 0 or t.max() >= kp.n_frames):
        raise ParameterError("frames", f"{t.min()}..{t.max()}", f"frame numbers in [0, {kp.n_frames - 1}]")
    shape = kp.poses.shape[1:]
    flat_p = kp.poses.reshape(kp.keys.size, -1)
    a, w = _segment_weights(kp, t)
    if kp.tangents is None:
        v = w[:, 0:1] * flat_p[a] + w[:, 2:3] * flat_p[a + 1]
    else:
        flat_m = kp.tangents.reshape(kp.keys.size, -1)
        flat_in = flat_m if kp.tangents_in is None else kp.tangents_in.reshape(kp.keys.size, -1)
        v = w[:, 0:1] * flat_p[a] + w[:, 1:2] * flat_m[a]
        v = v + w[:, 2:3] * flat_p[a + 1] + w[:, 3:4] * flat_in[a + 1]
    return v.reshape(t.size, *shape).astype(dtype, copy=False)


def reconstruct(animation: Animation, keys: ArrayLike, interp: str = "linear") -> Animation:
    """The full-rate animation rebuilt from its key poses (all original vertices).

    Parameters
    ----------
    animation : Animation
        The full-rate animation.
    keys : array_like
        Its key frames.
    interp : {"linear", "hermite", "hermite-fit"}, default "linear"
        The curve through the keys.

    Returns
    -------
    Animation
        Every frame rebuilt, float32 as a groom's points are.
    """
    kp = key_poses(animation.frames, keys, interp)
    return animation.with_frames(interpolate_keys(kp, np.float32))


@dataclass
class PositionErrors:
    """Vertex distances |p − p̂| in scene units, per frame and per vertex."""

    per_frame_mean: F64  # (F,)
    per_frame_max: F64  # (F,)
    per_frame_tip: F64  # (F,) mean over strand tips
    per_vertex_mean: F64  # (V,) mean over frames
    per_vertex_max: F64  # (V,)

    def summary(self) -> dict:
        return {
            "mean": float(self.per_frame_mean.mean()),
            "max": float(self.per_frame_max.max()),
            "tip_mean": float(self.per_frame_tip.mean()),
            "tip_max_frame": float(self.per_frame_tip.max()),
        }


def position_errors(original: Animation, rebuilt: Animation | ArrayLike) -> PositionErrors:
    """Distances between every original vertex and its rebuilt position (float64).

    Parameters
    ----------
    original : Animation
        The full-rate animation.
    rebuilt : Animation or array_like
        ``(F, V, 3)`` its frames rebuilt.

    Returns
    -------
    PositionErrors
        Per-frame mean, worst and tip distances, in the groom's units.
    """
    b = rebuilt.frames if isinstance(rebuilt, Animation) else np.asarray(rebuilt)
    if b.shape != original.frames.shape:
        raise ParameterError("rebuilt", f"shape {b.shape}", f"{original.frames.shape}")
    d = np.sqrt(np.sum((original.frames.astype(np.float64) - b) ** 2, axis=2))  # (F, V)
    tips = original.topology.tip_indices
    return PositionErrors(
        d.mean(axis=1), d.max(axis=1), d[:, tips].mean(axis=1), d.mean(axis=0), d.max(axis=0)
    )


def _segment_weights(kp: KeyPoses, t: NDArray[np.int64]) -> tuple[NDArray[np.int64], F64]:
    """Per frame of ``t``: the key a before it and the weights of p_a, out_a, p_b, in_b in its
    curve value (linear: 1 − s and s, tangents weighted 0; Hermite: the basis h00, h10·L, h01,
    h11·L), shared by :func:`interpolate_at` and the error kernel."""
    a = np.clip(np.searchsorted(kp.keys, t, side="right") - 1, 0, kp.keys.size - 2)
    el = (kp.keys[a + 1] - kp.keys[a]).astype(np.float64)
    s = (t - kp.keys[a]) / el
    w = np.zeros((t.size, 4))
    if kp.tangents is None:
        w[:, 0], w[:, 2] = 1.0 - s, s
    else:
        w[:, 0] = 2 * s**3 - 3 * s**2 + 1
        w[:, 1] = (s**3 - 2 * s**2 + s) * el
        w[:, 2] = -2 * s**3 + 3 * s**2
        w[:, 3] = (s**3 - s**2) * el
    return a, w


@njit(cache=True, nogil=True, parallel=True)
def _curve_distances(frames, t0, a, w, poses, out_t, in_t, hermite, e):
    """e[c, v] = |frames[t0 + c, v] − curve(t0 + c)[v]| in float64, the curve value
    w0·p_a + w1·out_a + w2·p_b + w3·in_b summed in that order (linear: the first and third
    terms only), one frame per task: the key curve is never stored."""
    for c in prange(e.shape[0]):
        f, k = t0 + c, a[c]
        w0, w1, w2, w3 = w[c, 0], w[c, 1], w[c, 2], w[c, 3]
        for v in range(e.shape[1]):
            sq = 0.0
            for i in range(3):
                if hermite:
                    x = w0 * poses[k, v, i] + w1 * out_t[k, v, i]
                    x = x + w2 * poses[k + 1, v, i] + w3 * in_t[k + 1, v, i]
                else:
                    x = w0 * poses[k, v, i] + w2 * poses[k + 1, v, i]
                d = np.float64(frames[f, v, i]) - x
                sq += d * d
            e[c, v] = np.sqrt(sq)


def key_curve_errors(
    animation: Animation,
    kp: KeyPoses,
    *,
    cancelled: Callable[[], bool] | None = None,
    progress: Callable[[float], None] | None = None,
) -> PositionErrors | None:
    """:func:`position_errors` against the key curve itself, in float64, a chunk of frames at a
    time, the curve never stored (a 2,000 × 24 × 240 animation rebuilt whole is 138 MB in
    float32): what the CLI and the studio's timeline both report. None as soon as
    ``cancelled()`` turns True. The distances come from one kernel (:func:`_curve_distances`),
    the sums from numpy as :func:`key_curve_errors_reference` takes them; the two agree to
    rounding (the kernel may fuse a multiply and an add).

    Parameters
    ----------
    animation : Animation
        The full-rate animation.
    kp : KeyPoses
        Its key poses.
    cancelled : callable, optional
        Asked between chunks; True stops.
    progress : callable, optional
        ``progress(share)`` after each chunk.

    Returns
    -------
    PositionErrors or None
        The errors, or None once cancelled.
    """
    return _curve_errors(animation, kp, cancelled, progress, reference=False)


def key_curve_errors_reference(
    animation: Animation,
    kp: KeyPoses,
    *,
    cancelled: Callable[[], bool] | None = None,
    progress: Callable[[float], None] | None = None,
) -> PositionErrors | None:
    """The numpy twin of :func:`key_curve_errors`: each chunk of the curve rebuilt by
    :func:`interpolate_at`, then its distances.

    Parameters
    ----------
    animation, kp, cancelled, progress
        As :func:`key_curve_errors` takes them.

    Returns
    -------
    PositionErrors or None
        As :func:`key_curve_errors` gives them.
    """
    return _curve_errors(animation, kp, cancelled, progress, reference=True)


def _curve_errors(animation, kp, cancelled, progress, reference: bool) -> PositionErrors | None:
    f = animation.frames
    n, v = f.shape[0], f.shape[1]
    if kp.n_frames != n or kp.poses.shape[1:] != f.shape[1:]:
        raise ParameterError("key poses", f"{kp.n_frames} × {kp.poses.shape[1:]}", f"{n} × {f.shape[1:]}")
    tips = animation.topology.tip_indices
    mean, tip, worst = np.empty(n), np.empty(n), np.empty(n)
    v_sum, v_max = np.zeros(v), np.zeros(v)
    chunk = max(1, _CHUNK_VALUES // max(3 * v, 1))
    poses = np.ascontiguousarray(kp.poses, np.float64)
    hermite = kp.tangents is not None
    out_t = np.ascontiguousarray(kp.tangents, np.float64) if hermite else np.zeros((0, 0, 0))
    in_t = out_t if kp.tangents_in is None else np.ascontiguousarray(kp.tangents_in, np.float64)
    buffer = np.empty((min(chunk, n), v))
    for f0 in range(0, n, chunk):
        if cancelled is not None and cancelled():
            return None
        t = np.arange(f0, min(n, f0 + chunk))
        if reference:
            d = f[t].astype(np.float64) - interpolate_at(kp, t)
            e = np.sqrt(np.einsum("fvi,fvi->fv", d, d))  # (chunk, V)
        else:
            e = buffer[: t.size]
            a, w = _segment_weights(kp, t)
            # C-ordered, read-only: one compilation (a capture's frames are a strided gather)
            _curve_distances(readonly(f[f0 : f0 + t.size]), 0, a, w, poses, out_t, in_t, hermite, e)
        mean[t], tip[t], worst[t] = e.mean(axis=1), e[:, tips].mean(axis=1), e.max(axis=1)
        v_sum += e.sum(axis=0)
        np.maximum(v_max, e.max(axis=0), out=v_max)
        if progress is not None:
            progress(t[-1] / max(n - 1, 1))
    return PositionErrors(mean, worst, tip, v_sum / n, v_max)


def compare_with_uniform(animation: Animation, keys: ArrayLike, interp: str = "linear") -> dict:
    """Position errors of the given keys and of uniform keys of the same count.

    Parameters
    ----------
    animation : Animation
        The full-rate animation.
    keys : array_like
        The key frames to judge.
    interp : {"linear", "hermite", "hermite-fit"}, default "linear"
        The curve through the keys.

    Returns
    -------
    dict
        ``{"keys": ..., "uniform": ...}``: each set's frames and its mean, worst and tip
        position errors, in the groom's units.
    """
    k = check_keys(keys, animation.n_frames)
    uni = uniform_keys(animation.n_frames, k.size)
    out = {}
    for name, kk in (("keys", k), ("uniform", uni)):
        err = key_curve_errors(animation, key_poses(animation.frames, kk, interp))
        out[name] = {"keys": kk.tolist(), **err.summary()}
    return out


def motion_speed(
    frames: ArrayLike, fps: float = 1.0, cancelled: Callable[[], bool] | None = None
) -> F64 | None:
    """``(F,)`` mean speed of all points per second (central differences, one-sided at the ends),
    units/s, a chunk of frames at a time in float64. An ``(F, V, 3)`` array is V points; a flat
    ``(F, D)`` feature array counts every dimension as a point on a line. None once ``cancelled()``.

    Parameters
    ----------
    frames : array_like
        ``(F, V, 3)`` points or ``(F, D)`` features.
    fps : float, default 1.0
        Frames per second.
    cancelled : callable, optional
        Asked between chunks; True stops.

    Returns
    -------
    ndarray or None
        ``(F,)`` float64 speeds, or None once cancelled.
    """
    f = np.asarray(frames)
    n = f.shape[0]
    f = f.reshape(n, -1, 3) if f.ndim == 3 else f.reshape(n, -1, 1)
    out = np.zeros(n)
    if n < 2:
        return out
    chunk = max(1, _CHUNK_VALUES // max(f.shape[1] * f.shape[2], 1))
    lo, hi, w = tangent_stencil(n)  # the central difference, one-sided at the ends
    for f0 in range(0, n, chunk):
        if cancelled is not None and cancelled():
            return None
        t = np.arange(f0, min(n, f0 + chunk))
        d = f[hi[t]].astype(np.float64) - f[lo[t]]
        out[t] = np.sqrt(np.einsum("fvi,fvi->fv", d, d)).mean(axis=1) * w[t]
    return out * fps


def key_distribution(frames: ArrayLike, keys: ArrayLike, fps: float = 1.0, window: int | None = None) -> dict:
    """Where keys fall against the motion: data for the timeline to draw.

    ``speed`` per frame, the ``motion`` covered so far (cumulative path, 0 → 1), the fraction
    of motion at each key, and key density (keys per frame) in sliding windows; a good key
    set has keys where ``speed`` is high, and key fractions that track the motion fraction.

    Parameters
    ----------
    frames : array_like
        ``(F, V, 3)`` points or ``(F, D)`` features.
    keys : array_like
        Key frames.
    fps : float, default 1.0
        Frames per second.
    window : int, optional
        The sliding window's length in frames (None: max(3, F // 20)).

    Returns
    -------
    dict
        ``speed``, ``motion``, the keys' motion fractions and the key density, as lists.
    """
    f = np.asarray(frames)
    k = check_keys(keys, f.shape[0])
    speed = motion_speed(f, fps)
    path = np.concatenate([[0.0], np.cumsum((speed[1:] + speed[:-1]) / 2.0)])
    motion = path / path[-1] if path[-1] > 0 else np.linspace(0.0, 1.0, f.shape[0])
    n = f.shape[0]
    window = int(window or max(3, n // 20))
    is_key = np.zeros(n)
    is_key[k] = 1.0
    density = np.convolve(is_key, np.ones(window) / window, mode="same")
    uni = uniform_keys(n, k.size)
    return {
        "frames": n,
        "keys": k.tolist(),
        "uniform_keys": uni.tolist(),
        "speed": speed.tolist(),
        "motion": motion.tolist(),
        "key_motion": motion[k].tolist(),
        "density": density.tolist(),
        "window": window,
        # mean speed at the keys over mean speed overall: > 1 when keys gather where things move
        "speed_at_keys": float(speed[k].mean() / speed.mean()) if speed.mean() > 0 else 1.0,
    }
