"""The numbers behind the studio's keyframe timeline (numpy only: no Qt, no GL).

One :func:`solve` per animation and table setting (features → segment cost table → the layered
DP for every key count up to :data:`MAX_CURVE_KEYS`); after it, the keys for any count are a
back-pointer trace (instant, so the key-count slider needs no new solve), and tau and
error-budget keys come from the same table. Per-frame position errors and single reconstructed
frames are computed in chunks of frames in float32, so nothing of the size of a whole
reconstruction is ever held (a 2,000-strand × 24-vertex × 240-frame animation is 138 MB).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.groom import Animation
from hairtool.keys.costs import INTERPOLATIONS, OBJECTIVES, cost_table
from hairtool.keys.dp import select_keys, solve_layers, uniform_keys
from hairtool.keys.edit import KeyEditor
from hairtool.keys.features import FeatureOptions, hair_features
from hairtool.keys.reconstruct import KeyPoses, check_keys, interpolate_at, key_poses

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

KEY_MODES = {"count": "Key count", "tau": "Price per key (tau)", "budget": "Error budget"}
MAX_CURVE_KEYS = 200  # the slider and the error-vs-count curve cover K = 2..min(frames, this)
_CHUNK_VALUES = 4_000_000  # float32 values per chunk of frames in the error and speed passes


@dataclass(frozen=True)
class KeySettings:
    """What the artist chose in the timeline's key controls.

    ``count`` 0 means "a tenth of the frames" (as ``hairtool keys``); ``samples`` 0 keeps the
    original vertices instead of resampling M points per strand; ``tip_weight`` is seed 000's
    root-to-tip weight at the tip (1 at the root); ``curvature`` is its λ. ``budget`` bounds the
    total feature-space error (objective "total") or the worst frame's (objective "worst").
    """

    mode: str = "count"
    count: int = 0
    tau: float = 1.0
    budget: float = 1.0
    objective: str = "total"
    interp: str = "linear"
    samples: int = 16
    tip_weight: float = 2.0
    curvature: float = 0.0

    def validate(self) -> KeySettings:
        if self.mode not in KEY_MODES:
            raise ParameterError("key mode", self.mode, f"one of {', '.join(KEY_MODES)}")
        if self.objective not in OBJECTIVES:
            raise ParameterError("objective", self.objective, " or ".join(OBJECTIVES))
        if self.interp not in INTERPOLATIONS:
            raise ParameterError("interpolation", self.interp, " or ".join(INTERPOLATIONS))
        if self.mode == "tau" and self.objective != "total":
            raise ParameterError("tau", self.tau, "the total-error objective (a price per key adds up)")
        if int(self.count) != self.count or self.count < 0:
            raise ParameterError("key count", self.count, "a whole number >= 2 (0: a tenth of the frames)")
        for name in ("tau", "budget", "curvature"):
            v = getattr(self, name)
            if not np.isfinite(v) or v < 0:
                raise ParameterError(name, v, "a finite number >= 0")
        if int(self.samples) != self.samples or self.samples == 1 or self.samples < 0:
            raise ParameterError("samples", self.samples, "a whole number >= 2 (0: the original vertices)")
        if not np.isfinite(self.tip_weight) or self.tip_weight <= 0:
            raise ParameterError("tip weight", self.tip_weight, "a finite number > 0")
        return self

    def replace(self, **changes: object) -> KeySettings:
        return replace(self, **changes).validate()

    @property
    def table_key(self) -> tuple:
        """The settings a cost table depends on: a change here needs a new :func:`solve`."""
        return (self.objective, self.interp, self.samples, self.tip_weight, self.curvature)

    def feature_options(self) -> FeatureOptions:
        return FeatureOptions(samples=self.samples or None, tip_weight=float(self.tip_weight))

    def count_for(self, n_frames: int) -> int:
        k = self.count or max(2, round(n_frames / 10))
        return int(min(max(k, 2), n_frames))


@dataclass
class KeySolve:
    """A cost table and its layered DP: ``energy[K, n−1]`` is the best error with K keys."""

    table: F64
    energy: F64  # (kmax + 1, n)
    back: I64  # (kmax + 1, n)
    kmax: int
    table_key: tuple

    @property
    def n_frames(self) -> int:
        return int(self.table.shape[0])

    @property
    def objective(self) -> str:
        return self.table_key[0]

    @property
    def curve(self) -> F64:
        """``(m, 2)`` rows (K, optimal error with K keys) for K = 2..kmax (feature units)."""
        ks = np.arange(2, self.kmax + 1)
        return np.column_stack([ks, self.energy[ks, self.n_frames - 1]])

    def keys_for_count(self, k: int) -> I64:
        """The DP keys for exactly ``k`` keys, traced back through the stored layers."""
        if not 2 <= k <= self.kmax:
            raise ParameterError("key count", k, f"a whole number in [2, {self.kmax}]")
        keys = [self.n_frames - 1]
        for depth in range(k, 1, -1):
            keys.append(int(self.back[depth, keys[-1]]))
        return np.array(keys[::-1], dtype=np.int64)

    def keys_for_tau(self, tau: float) -> I64:
        """Seed 003's keys with a price tau per key (total objective only)."""
        return select_keys(self.table, penalty=float(tau), curve_keys=0).keys

    def keys_for_budget(self, budget: float) -> I64:
        """The fewest keys whose error (total, or worst frame) is within ``budget``."""
        e = self.energy[2 : self.kmax + 1, self.n_frames - 1]
        fits = np.flatnonzero(e <= budget)
        if fits.size:
            return self.keys_for_count(int(fits[0]) + 2)
        bound = {"budget": budget} if self.objective == "total" else {"max_error": budget}
        return select_keys(self.table, objective=self.objective, curve_keys=0, **bound).keys


def solve(
    animation: Animation,
    settings: KeySettings,
    progress: Callable[..., None] | None = None,
    cancelled: Callable[[], bool] | None = None,
) -> KeySolve | None:
    """Features, cost table and the layered DP; None when ``cancelled()`` turned True."""
    settings.validate()
    progress = progress or (lambda *a, **k: None)
    cancelled = cancelled or (lambda: False)
    progress(0.0, "features")
    x = hair_features(animation, settings.feature_options())
    if cancelled():
        return None
    progress(0.3, "cost table")
    table = cost_table(x, settings.interp, settings.curvature, settings.objective)
    del x
    if cancelled():
        return None
    progress(0.9, "dynamic programming")
    n = table.shape[0]
    kmax = int(min(n, MAX_CURVE_KEYS))
    energy, back, _ = solve_layers(table, kmax, settings.objective)
    progress(1.0, "")
    return KeySolve(table, energy, back, kmax, settings.table_key)


def choose_keys(key_solve: KeySolve, settings: KeySettings) -> I64:
    """The DP keys the settings ask for (count, tau or budget), from an existing solve."""
    if settings.mode == "tau":
        return key_solve.keys_for_tau(settings.tau)
    if settings.mode == "budget":
        return key_solve.keys_for_budget(settings.budget)
    return key_solve.keys_for_count(min(settings.count_for(key_solve.n_frames), key_solve.kmax))


# -- reconstruction and errors, chunked ---------------------------------------------------------
@dataclass
class FrameErrors:
    """Per-frame vertex distances |p − p̂| (scene units) of one reconstruction."""

    keys: I64
    mean: F64  # (F,) mean over all vertices
    tip: F64  # (F,) mean over strand tips
    max: F64  # (F,) worst vertex

    def summary(self) -> dict:
        return {"mean": float(self.mean.mean()), "tip": float(self.tip.mean()), "max": float(self.max.max())}


@dataclass
class Analysis:
    """Everything the timeline draws for one key set: both reconstructions' errors and the speed."""

    dp: FrameErrors
    uniform: FrameErrors
    speed: F64 | None = None
    extra: dict = field(default_factory=dict)


def frame_errors(
    animation: Animation,
    kp: KeyPoses,
    cancelled: Callable[[], bool] | None = None,
    progress: Callable[[float], None] | None = None,
) -> FrameErrors | None:
    """Mean, tip-mean and max vertex error per frame of the key curve (float32 arithmetic)."""
    f = animation.frames
    n, v = f.shape[0], f.shape[1]
    tips = animation.topology.tip_indices
    mean, tip, worst = np.empty(n), np.empty(n), np.empty(n)
    chunk = max(1, _CHUNK_VALUES // max(3 * v, 1))
    small = _as_float32(kp)
    for f0 in range(0, n, chunk):
        if cancelled is not None and cancelled():
            return None
        t = np.arange(f0, min(n, f0 + chunk))
        d = f[t] - interpolate_at(small, t, np.float32)
        e = np.sqrt(np.einsum("fvi,fvi->fv", d, d))
        mean[t] = e.mean(axis=1, dtype=np.float64)
        tip[t] = e[:, tips].mean(axis=1, dtype=np.float64)
        worst[t] = e.max(axis=1)
        if progress is not None:
            progress(t[-1] / max(n - 1, 1))
    return FrameErrors(kp.keys, mean, tip, worst)


def vertex_errors(animation: Animation, kp: KeyPoses, frame: int) -> F32:
    """``(V,)`` distance of each vertex from the key curve at one frame."""
    d = animation.frames[frame] - interpolate_at(kp, [frame], np.float32)[0]
    return np.sqrt(np.einsum("vi,vi->v", d, d))


def speed(animation: Animation, cancelled: Callable[[], bool] | None = None) -> F64 | None:
    """``(F,)`` mean vertex speed in units/s: :func:`hairtool.keys.reconstruct.motion_speed`, chunked, float32."""
    f = animation.frames
    n, v = f.shape[0], f.shape[1]
    if n < 2:
        return np.zeros(n)
    out = np.empty(n)
    chunk = max(1, _CHUNK_VALUES // max(3 * v, 1))
    for f0 in range(0, n, chunk):
        if cancelled is not None and cancelled():
            return None
        t = np.arange(f0, min(n, f0 + chunk))
        lo, hi = np.clip(t - 1, 0, n - 1), np.clip(t + 1, 0, n - 1)
        d = f[hi] - f[lo]
        w = np.where((t == 0) | (t == n - 1), 1.0, 0.5)
        out[t] = np.sqrt(np.einsum("fvi,fvi->fv", d, d)).mean(axis=1, dtype=np.float64) * w
    return out * animation.fps


def analyse(
    animation: Animation,
    dp_keys: ArrayLike,
    interp: str,
    *,
    with_speed: bool = True,
    progress: Callable[..., None] | None = None,
    cancelled: Callable[[], bool] | None = None,
) -> Analysis | None:
    """Errors of the DP keys and of uniform keys of the same count (and the motion speed)."""
    k = check_keys(dp_keys, animation.n_frames)
    uni = uniform_keys(animation.n_frames, k.size)
    parts = []
    for i, keys in enumerate((k, uni)):
        step = (lambda x, i=i: progress(0.45 * (i + x), "errors")) if progress is not None else None
        err = frame_errors(animation, key_poses(animation.frames, keys, interp), cancelled, step)
        if err is None:
            return None
        parts.append(err)
    v = speed(animation, cancelled) if with_speed else None
    if with_speed and v is None:
        return None
    return Analysis(parts[0], parts[1], v)


def _as_float32(kp: KeyPoses) -> KeyPoses:
    tangents = None if kp.tangents is None else kp.tangents.astype(np.float32, copy=False)
    return KeyPoses(kp.keys, kp.poses.astype(np.float32, copy=False), tangents, kp.n_frames, kp.interp)


def key_poses_of(animation: Animation, keys: ArrayLike, interp: str) -> KeyPoses:
    """Key poses (and Hermite tangents) of an animation, kept as float32 to halve their size."""
    return _as_float32(key_poses(animation.frames, keys, interp))


def key_edit_block(
    frames: NDArray, keys: ArrayLike, interp: str, key_frame: int, pose: ArrayLike
) -> tuple[int, NDArray]:
    """``(start, block)``: the frames ``start .. start + len(block) − 1`` after the pose at
    ``key_frame`` is replaced, through :class:`hairtool.keys.edit.KeyEditor`'s residual scheme.

    An edit changes only the frames between the key's neighbouring keys, so the editor runs on
    that stretch plus one frame each side (which keeps the Hermite tangents at the neighbouring
    keys those of the whole animation): the result equals editing the whole animation.
    """
    n = frames.shape[0]
    k = check_keys(keys, n)
    hit = np.flatnonzero(k == key_frame)
    if hit.size == 0:
        raise ParameterError("key frame", key_frame, f"one of the keys {k.tolist()}")
    a = int(hit[0])
    lo = int(k[a - 1]) if a > 0 else int(key_frame)
    hi = int(k[a + 1]) if a < k.size - 1 else int(key_frame)
    s0, s1 = max(lo - 1, 0), min(hi + 1, n - 1)
    sub_keys = np.array(sorted({s0, lo, int(key_frame), hi, s1}), dtype=np.int64) - s0
    editor = KeyEditor(frames[s0 : s1 + 1], sub_keys, interp)
    editor.set_key_pose(int(key_frame) - s0, pose)
    return s0, editor.frames(frames.dtype)
