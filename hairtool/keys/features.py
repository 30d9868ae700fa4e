"""Frame features for hair keyframing (seed 000, steps 1–5): one float64 vector per frame.

Each step can be switched off so its effect on the selected keys can be measured:
arc-length resampling to M points per strand, removal of the frame's mean root position,
root-relative coordinates, and a root-to-tip weight w(u) that makes tip motion count more.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import GroomError, ParameterError
from hairtool.groom import Animation
from hairtool.kernel_arrays import readonly

F64 = NDArray[np.float64]

# Frames per resampling chunk are chosen so one chunk holds about this many vertices.
_CHUNK_VERTICES = 2_000_000


@dataclass(frozen=True)
class FeatureOptions:
    """How an animation becomes frame vectors; every step can be switched off.

    ``weight(u) = root_weight + (tip_weight − root_weight)·u**exponent`` with u the arc-length
    fraction (0 at the root, 1 at the tip); it multiplies coordinates, so squared errors scale by w².
    """

    samples: int | None = 16  # M points per strand by arc length; None keeps the original vertices
    center: bool = True  # subtract the frame's mean root position (removes global translation)
    relative: bool = True  # each point relative to its own strand's root
    weighting: bool = True
    root_weight: float = 1.0
    tip_weight: float = 2.0
    exponent: float = 1.0

    def validate(self) -> None:
        if self.samples is not None and (
            not np.isfinite(self.samples) or int(self.samples) != self.samples or self.samples < 2
        ):
            raise ParameterError("samples", self.samples, "a whole number of at least 2")
        for name in ("root_weight", "tip_weight"):
            v = getattr(self, name)
            if not np.isfinite(v) or v < 0:
                raise ParameterError(name, v, "a finite number >= 0")
        if self.weighting and self.root_weight == 0 and self.tip_weight == 0:
            raise ParameterError("tip_weight", self.tip_weight, "a positive weight somewhere on the strand")
        if not np.isfinite(self.exponent) or self.exponent <= 0:
            raise ParameterError("exponent", self.exponent, "a finite number > 0")

    def to_dict(self) -> dict:
        return asdict(self)


def resample_frames_reference(frames: ArrayLike, counts: ArrayLike, m: int) -> F64:
    """Numpy twin of :func:`resample_frames`, vectorised over chunks of frames.

    ``frames`` is ``(F, V, 3)``. One monotone key over all frames and strands (strand s of
    chunk frame f occupies [2(f·S+s), 2(f·S+s)+1]) turns the whole chunk into one
    ``searchsorted``; zero-length strands fall back to the vertex-index parameter.

    Parameters
    ----------
    frames, counts, m
        As :func:`resample_frames` takes them.

    Returns
    -------
    ndarray
        ``(F, S, m, 3)`` float64.
    """
    if not np.isfinite(m) or int(m) != m or m < 2:
        raise ParameterError("samples", m, "a whole number of at least 2")
    m = int(m)
    p = np.asarray(frames)
    c = np.asarray(counts, dtype=np.int64)
    n_frames, v_count = p.shape[0], p.shape[1]
    s_count = c.size
    off = np.zeros(s_count + 1, dtype=np.int64)
    np.cumsum(c, out=off[1:])
    strand = np.repeat(np.arange(s_count), c)
    roots, tips = off[:-1], off[1:] - 1
    vparam = (np.arange(v_count) - off[strand]) / (c[strand] - 1)
    q = np.linspace(0.0, 1.0, m)
    out = np.empty((n_frames, s_count, m, 3), dtype=np.float64)
    chunk = max(1, _CHUNK_VERTICES // max(v_count, 1))
    for f0 in range(0, n_frames, chunk):
        f1 = min(n_frames, f0 + chunk)
        nf = f1 - f0
        pts = p[f0:f1].astype(np.float64)  # (nf, V, 3)
        seg = np.zeros((nf, v_count))
        seg[:, 1:] = np.sqrt(np.einsum("fvi,fvi->fv", np.diff(pts, axis=1), np.diff(pts, axis=1)))
        seg[:, roots] = 0.0  # the "segment" into a root crosses from the previous strand
        arc = np.cumsum(seg, axis=1)
        arc -= arc[:, roots][:, strand]
        length = arc[:, tips][:, strand]
        with np.errstate(invalid="ignore", divide="ignore"):
            u = np.where(length > 0, arc / length, vparam[None, :])
        block = 2.0 * (np.arange(nf)[:, None] * s_count + strand[None, :])
        key = (block + u).reshape(-1)
        sid = 2.0 * (np.arange(nf)[:, None] * s_count + np.arange(s_count)[None, :])
        target = (sid[:, :, None] + q[None, None, :]).reshape(-1)
        idx = np.searchsorted(key, target, side="right") - 1
        base = (np.arange(nf) * v_count)[:, None, None]
        first = (base + roots[None, :, None]).repeat(m, axis=2).reshape(-1)
        last = (base + tips[None, :, None] - 1).repeat(m, axis=2).reshape(-1)
        idx = np.clip(idx, first, last)
        k0, k1 = key[idx], key[idx + 1]
        span = k1 - k0
        with np.errstate(invalid="ignore", divide="ignore"):
            frac = np.where(span > 0, (target - k0) / span, 0.0)
        frac = np.clip(frac, 0.0, 1.0)[:, None]
        flat = pts.reshape(-1, 3)
        out[f0:f1] = (flat[idx] * (1.0 - frac) + flat[idx + 1] * frac).reshape(nf, s_count, m, 3)
    return out


@njit(cache=True, nogil=True, parallel=True)
def _resample_kernel(frames, offsets, q, out):  # pragma: no cover - compiled
    n_frames = frames.shape[0]
    s_count = offsets.size - 1
    longest = 0
    for s in range(s_count):
        longest = max(longest, offsets[s + 1] - offsets[s])
    for f in prange(n_frames):
        u = np.empty(longest)
        for s in range(s_count):
            a = offsets[s]
            nv = offsets[s + 1] - a
            u[0] = 0.0
            for i in range(1, nv):
                d0 = np.float64(frames[f, a + i, 0]) - np.float64(frames[f, a + i - 1, 0])
                d1 = np.float64(frames[f, a + i, 1]) - np.float64(frames[f, a + i - 1, 1])
                d2 = np.float64(frames[f, a + i, 2]) - np.float64(frames[f, a + i - 1, 2])
                u[i] = u[i - 1] + np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            length = u[nv - 1]
            for i in range(nv):
                u[i] = u[i] / length if length > 0 else i / (nv - 1)
            seg = 0
            for t in range(q.size):
                while seg < nv - 2 and u[seg + 1] <= q[t]:  # last vertex at or before q
                    seg += 1
                span = u[seg + 1] - u[seg]
                frac = (q[t] - u[seg]) / span if span > 0 else 0.0
                frac = min(max(frac, 0.0), 1.0)
                for c in range(3):
                    p0 = np.float64(frames[f, a + seg, c])
                    p1 = np.float64(frames[f, a + seg + 1, c])
                    out[f, s, t, c] = p0 * (1.0 - frac) + p1 * frac


def resample_frames(frames: ArrayLike, counts: ArrayLike, m: int, use_numba: bool = True) -> F64:
    """``(F, S, m, 3)`` float64: every strand of every frame resampled by arc length to m points.

    ``frames`` is ``(F, V, 3)``; the points sit at arc-length fractions 0, 1/(m−1), …, 1 of each
    strand in each frame; strands of zero length fall back to the vertex-index parameter.
    One pass per strand (vertices and samples walked together), in parallel over frames.

    Parameters
    ----------
    frames : array_like
        ``(F, V, 3)`` points.
    counts : array_like
        ``(S,)`` vertices per strand.
    m : int
        Points per strand, ≥ 2.
    use_numba : bool, default True
        False runs the numpy twin.

    Returns
    -------
    ndarray
        ``(F, S, m, 3)`` float64.
    """
    if not use_numba:
        return resample_frames_reference(frames, counts, m)
    if not np.isfinite(m) or int(m) != m or m < 2:
        raise ParameterError("samples", m, "a whole number of at least 2")
    p = readonly(np.ascontiguousarray(frames))
    c = np.asarray(counts, dtype=np.int64)
    off = np.zeros(c.size + 1, dtype=np.int64)
    np.cumsum(c, out=off[1:])
    out = np.empty((p.shape[0], c.size, int(m), 3), dtype=np.float64)
    _resample_kernel(p, off, np.linspace(0.0, 1.0, int(m)), out)
    return out


def strand_weights(u: ArrayLike, options: FeatureOptions) -> F64:
    """w(u) of seed 000's root–tip weighting at arc-length fractions u ∈ [0, 1].

    Parameters
    ----------
    u : array_like
        Arc-length fractions.
    options : FeatureOptions
        The weighting.

    Returns
    -------
    ndarray
        float64 weights.
    """
    u = np.asarray(u, dtype=np.float64)
    o = options
    return o.root_weight + (o.tip_weight - o.root_weight) * u**o.exponent


def hair_features(animation: Animation, options: FeatureOptions | None = None) -> F64:
    """``(F, D)`` float64 frame vectors of an animation; D = S·M·3 (S·N·3 without resampling).

    Parameters
    ----------
    animation : Animation
        The hair's frames.
    options : FeatureOptions, optional
        Resampling, root removal and weights (None: seed 000's defaults).

    Returns
    -------
    ndarray
        ``(F, D)`` float64 frame vectors.
    """
    o = options or FeatureOptions()
    o.validate()
    if o.samples is not None:
        pts = resample_frames(animation.frames, animation.counts, int(o.samples))  # (F, S, M, 3)
        u = np.linspace(0.0, 1.0, int(o.samples))[None, :]
        roots = pts[:, :, 0, :].copy()
    else:
        counts = animation.counts
        if np.any(counts != counts[0]):
            # Strands of different lengths: keep the flat vertex layout, weight by vertex parameter.
            pts = animation.frames.astype(np.float64)[:, :, None, :]  # (F, V, 1, 3)
            u = animation.topology.vertex_param.astype(np.float64)[:, None]
            ridx = animation.topology.root_indices
            roots_v = animation.frames[:, ridx].astype(np.float64)
            if o.relative:
                pts = pts - roots_v[:, animation.topology.strand_index][:, :, None, :]
            if o.center:
                pts = pts - roots_v.mean(axis=1)[:, None, None, :]
            if o.weighting:
                pts = pts * strand_weights(u, o)[None, :, :, None]
            return np.ascontiguousarray(pts.reshape(animation.n_frames, -1))
        n = int(counts[0])
        pts = animation.frames.astype(np.float64).reshape(animation.n_frames, counts.size, n, 3)
        u = np.linspace(0.0, 1.0, n)[None, :]
        roots = pts[:, :, 0, :].copy()
    # pts is a fresh float64 array here: update it in place (the large case is ~100M values)
    if o.relative:
        pts -= roots[:, :, None, :]
    if o.center:
        pts -= roots.mean(axis=1)[:, None, None, :]
    if o.weighting:
        pts *= strand_weights(u, o)[None, :, :, None]
    return pts.reshape(animation.n_frames, -1)


def raw_features(x: ArrayLike, name: str = "X") -> F64:
    """An ``(n_frames, D)`` array used as is (float64, checked for shape and NaN).

    Parameters
    ----------
    x : array_like
        ``(n_frames, D)``.
    name : str, default "X"
        Its name in a refusal.

    Returns
    -------
    ndarray
        float64.
    """
    a = np.asarray(x)
    if a.ndim == 1:
        a = a[:, None]
    if a.ndim != 2:
        raise ParameterError(name, f"array of shape {a.shape}", "shape (frames, dims)")
    if a.shape[0] < 2:
        raise ParameterError(name, f"{a.shape[0]} frame(s)", "at least 2 frames")
    if a.shape[1] < 1:
        raise ParameterError(name, "0 dims", "at least 1 dimension")
    if not np.issubdtype(a.dtype, np.number):
        raise ParameterError(name, f"dtype {a.dtype}", "a numeric array")
    a = a.astype(np.float64)
    if not np.all(np.isfinite(a)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(a), axis=1))[0])
        raise ParameterError(name, f"non-finite value in frame {bad}", "finite numbers")
    return np.ascontiguousarray(a)


def frame_features(source: Animation | ArrayLike, options: FeatureOptions | None = None) -> F64:
    """Features of an animation (hair_features) or a raw ``(n_frames, D)`` array (as is).

    Parameters
    ----------
    source : Animation or array_like
        An animation, or ``(n_frames, D)`` features used as they are.
    options : FeatureOptions, optional
        For an animation: see :func:`hair_features`.

    Returns
    -------
    ndarray
        ``(n_frames, D)`` float64.
    """
    if isinstance(source, Animation):
        if source.n_frames < 2:
            raise GroomError(f"keyframes need an animation of at least 2 frames, got {source.n_frames}")
        return hair_features(source, options)
    return raw_features(source)


def strand_features(animation: Animation, strand: int, options: FeatureOptions | None = None) -> F64:
    """``(F, M, 3)`` one strand's part of :func:`hair_features` (its M points; its vertices
    without resampling), computed from that strand and the roots alone: what a graph editor
    draws of the space the keys are fitted in.

    Parameters
    ----------
    animation : Animation
        The hair's frames.
    strand : int
        The strand.
    options : FeatureOptions, optional
        As :func:`hair_features` takes them.

    Returns
    -------
    ndarray
        ``(F, M, 3)`` float64.
    """
    o = options or FeatureOptions()
    o.validate()
    topo = animation.topology
    if not 0 <= strand < topo.strand_count:
        raise ParameterError("strand", strand, f"a strand 0..{topo.strand_count - 1}")
    lo, hi = int(topo.offsets[strand]), int(topo.offsets[strand + 1])
    own = animation.frames[:, lo:hi]
    if o.samples is not None:
        pts = resample_frames(own, np.array([hi - lo]), int(o.samples))[:, 0]  # (F, M, 3)
        u = np.linspace(0.0, 1.0, int(o.samples))
    else:
        pts = own.astype(np.float64)
        counts = animation.counts
        u = (
            topo.vertex_param[lo:hi].astype(np.float64)
            if np.any(counts != counts[0])
            else np.linspace(0.0, 1.0, hi - lo)
        )
    roots = animation.frames[:, topo.root_indices].astype(np.float64)  # (F, S, 3)
    if o.relative:
        pts = pts - pts[:, :1] if o.samples is not None else pts - roots[:, strand][:, None]
    if o.center:
        pts = pts - roots.mean(axis=1)[:, None, :]
    if o.weighting:
        pts = pts * strand_weights(u, o)[None, :, None]
    return pts
