"""Key edits that spread to every frame while the captured detail stays (seed 003 §5).

The residual r_f = x_f − x̂_f between each original frame and its reconstruction from the keys
is stored; after a key pose is replaced, the frames are rebuilt from the keys and r is added
back. It is evaluated as ``x + (x̂_new − x̂_old)``, which is the same sum but exact where no key
moved: with no edit the original comes back bit for bit, and an edit of key k changes only the
frames strictly between k's neighbouring keys. Hermite tangents stay those of the original
samples, so the locality holds for both interpolations.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.groom import Animation
from hairtool.keys.reconstruct import KeyPoses, check_keys, interpolate_at, interpolate_keys, key_poses

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


class KeyEditor:
    """Original frames ``(F, ...)``, their keys, and the key poses as edited so far."""

    def __init__(self, frames: ArrayLike, keys: ArrayLike, interp: str = "linear") -> None:
        """Take the key poses out of ``frames``; the residuals are what the key curve misses.

        Parameters
        ----------
        frames : array_like
            ``(F, ...)`` the animation's frames (points or channels), kept as given.
        keys : array_like
            Key frame numbers, ascending, first and last frame included.
        interp : {"linear", "hermite", "hermite-fit"}, default "linear"
            The key curve.
        """
        self.original = np.asarray(frames)
        self._base = key_poses(self.original, keys, interp)
        self._base_frames = interpolate_keys(self._base)
        self.key_poses: KeyPoses = self._base

    @property
    def keys(self) -> NDArray[np.int64]:
        return self._base.keys

    @property
    def residual(self) -> F64:
        """``(F, ...)`` x_f − x̂_f: what the key curve misses; zero at the keys."""
        return self.original.astype(np.float64) - self._base_frames

    def set_key_pose(self, key_frame: int, pose: ArrayLike) -> None:
        """Replace the pose at a key frame (the frames follow on the next :meth:`frames`).

        Parameters
        ----------
        key_frame : int
            A frame that is a key.
        pose : array_like
            The new pose, shaped as one frame.
        """
        self.key_poses = self.key_poses.with_pose(key_frame, pose)

    def reset(self) -> None:
        self.key_poses = self._base

    def affected_frames(self, key_frame: int) -> tuple[int, int]:
        """``(lo, hi)``: an edit of this key changes frames lo < f < hi only (−1 / F at the ends).

        Parameters
        ----------
        key_frame : int
            A frame that is a key (ParameterError otherwise).

        Returns
        -------
        tuple of (int, int)
            ``(lo, hi)``, the neighbouring keys.
        """
        k = self.keys
        hit = np.flatnonzero(k == key_frame)
        if hit.size == 0:
            raise ParameterError("key_frame", key_frame, f"one of the keys {k.tolist()}")
        a = int(hit[0])
        lo = int(k[a - 1]) if a > 0 else -1
        hi = int(k[a + 1]) if a < k.size - 1 else self.original.shape[0]
        return lo, hi

    def frames(self, dtype: type | None = None) -> NDArray:
        """``(F, ...)`` the edited animation: x̂_new + r, exactly the original where nothing moved.

        Parameters
        ----------
        dtype : type, optional
            The result's dtype (None: the original frames').

        Returns
        -------
        ndarray
            ``(F, ...)`` the edited frames.
        """
        delta = interpolate_keys(self.key_poses) - self._base_frames
        out = self.original.astype(np.float64) + delta
        return out.astype(dtype or self.original.dtype)


def edit_animation(
    animation: Animation, keys: ArrayLike, edits: dict[int, ArrayLike], interp: str = "linear"
) -> Animation:
    """The animation with the given key poses ``{key_frame: (V, 3) points}`` replaced.

    Parameters
    ----------
    animation : Animation
        The captured animation.
    keys : array_like
        Its key frames.
    edits : dict of int to array_like
        New ``(V, 3)`` points by key frame.
    interp : {"linear", "hermite", "hermite-fit"}, default "linear"
        The key curve the edit is carried by.

    Returns
    -------
    Animation
        The edited animation: unchanged outside the edited keys' neighbours.
    """
    editor = KeyEditor(animation.frames, keys, interp)
    for frame, pose in edits.items():
        editor.set_key_pose(int(frame), pose)
    return animation.with_frames(editor.frames(np.float32))


# -- a key moved in time --------------------------------------------------------------------
def time_warp(frames: ArrayLike, keys_now: ArrayLike, keys_then: ArrayLike) -> F64:
    """The (fractional) frame of the motion as keyed before that each frame shows now: the
    piecewise-linear map taking each key's frame now back to its frame before, so a key moved
    in time takes the frames between its neighbouring keys with it (stretched on one side,
    squeezed on the other); the identity wherever no key moved.

    Parameters
    ----------
    frames : array_like
        Frame numbers now.
    keys_now : array_like
        The keys' frames now.
    keys_then : array_like
        Their frames before.

    Returns
    -------
    ndarray
        float64 frames before.
    """
    return np.interp(np.asarray(frames, dtype=np.float64), keys_now, keys_then)


def residual_at(values: NDArray, base_at: Callable[[I64], NDArray], at: ArrayLike) -> F64:
    """The residual ``values − base_at(frames)`` (``values`` ``(F, ...)``, ``base_at`` the key
    curve at whole frames) at fractional frames ``at``, linear between the frames either side;
    at a whole frame, that frame's residual exactly.

    Parameters
    ----------
    values : ndarray
        ``(F, ...)`` the frames.
    base_at : callable
        The key curve at whole frames.
    at : array_like
        Fractional frames.

    Returns
    -------
    ndarray
        ``(len(at), ...)`` float64.
    """
    u = np.asarray(at, dtype=np.float64).reshape(-1)
    n = values.shape[0]
    i0 = np.clip(np.floor(u).astype(np.int64), 0, max(n - 2, 0))
    i1 = np.minimum(i0 + 1, n - 1)
    s = (u - i0).reshape((-1,) + (1,) * (values.ndim - 1))
    r0 = values[i0].astype(np.float64) - base_at(i0)
    r1 = values[i1].astype(np.float64) - base_at(i1)
    return r0 * (1.0 - s) + r1 * s


def check_retime(keys: ArrayLike, n_frames: int, key_frame: int, new_frame: int) -> tuple[int, I64]:
    """``(key index, keys after)`` for moving the key at ``key_frame`` to ``new_frame``: an inner
    key (the first and last frame are always keys) to a frame strictly between its neighbouring
    keys (a key never passes another); :class:`ParameterError` naming the allowed frames.

    Parameters
    ----------
    keys : array_like
        The key frames.
    n_frames : int
        Frames.
    key_frame : int
        The key moved.
    new_frame : int
        Where it goes.

    Returns
    -------
    tuple of (int, ndarray)
        The key's index and the keys after.
    """
    k = check_keys(keys, n_frames)
    hit = np.flatnonzero(k == int(key_frame))
    if hit.size == 0:
        raise ParameterError("key frame", key_frame, f"one of the keys {k.tolist()}")
    a = int(hit[0])
    if a == 0 or a == k.size - 1:
        raise ParameterError("key frame", key_frame, "an inner key (the first and last frame stay keys)")
    lo, hi = int(k[a - 1]), int(k[a + 1])
    if int(new_frame) != new_frame or not lo < new_frame < hi:
        raise ParameterError("new frame", new_frame, f"a frame strictly between the keys {lo} and {hi}")
    out = k.copy()
    out[a] = int(new_frame)
    return a, out


def retime_key(
    frames: NDArray, keys: ArrayLike, interp: str, key_frame: int, new_frame: int
) -> tuple[int, NDArray, I64]:
    """``(start, block, keys after)``: the key at ``key_frame`` moved to ``new_frame`` with the
    residuals kept (seed 003 §5 with a knot moved in time). The key curve keeps every key pose
    and its tangents (per frame) and takes the new knot; each frame t between the neighbouring
    keys gets the curve there plus the residual of the frame it now shows, r(w(t)) with w
    :func:`time_warp` (the captured detail moves with the key). So the pose at the key is the
    key pose exactly, with linear keys the stretch is the old motion retimed, and frames
    outside ``start .. start + len(block) − 1`` (strictly between the neighbours) are untouched.

    Parameters
    ----------
    frames : ndarray
        ``(F, ...)`` the frames.
    keys : array_like
        The key frames.
    interp : str
        The key curve.
    key_frame : int
        The key moved.
    new_frame : int
        Where it goes.

    Returns
    -------
    tuple of (int, ndarray, ndarray)
        The first frame changed, the changed frames and the keys after.
    """
    f = np.asarray(frames)
    n = f.shape[0]
    a, after = check_retime(keys, n, key_frame, new_frame)
    before = check_keys(keys, n)
    lo, hi = int(before[a - 1]), int(before[a + 1])
    s0, s1 = max(lo - 1, 0), min(hi + 1, n - 1)  # one frame each side keeps the tangents
    sub = f[s0 : s1 + 1]
    sub_keys = np.array(sorted({s0, lo, int(key_frame), hi, s1}), dtype=np.int64) - s0
    base = key_poses(sub, sub_keys, interp)
    moved = sub_keys.copy()
    moved[moved == int(key_frame) - s0] = int(new_frame) - s0
    warped = KeyPoses(moved, base.poses, base.tangents, base.n_frames, base.interp, base.tangents_in)
    t = np.arange(lo + 1, hi) - s0
    curve = interpolate_at(warped, t)
    block = curve + residual_at(sub, lambda i: interpolate_at(base, i), time_warp(t, moved, sub_keys))
    return lo + 1, block.astype(f.dtype), after


# -- a key's handle set -----------------------------------------------------------------------
def _stretch(n: int, keys: I64, key_frame: int) -> tuple[int, int, I64]:
    """``(s0, s1, sub keys)``: the frames between the key's neighbours and one more each side
    (which keeps the Hermite tangents at the neighbours those of the whole animation), and the
    keys there counted from s0."""
    hit = np.flatnonzero(keys == int(key_frame))
    if hit.size == 0:
        raise ParameterError("key frame", key_frame, f"one of the keys {keys.tolist()}")
    a = int(hit[0])
    lo = int(keys[a - 1]) if a > 0 else int(key_frame)
    hi = int(keys[a + 1]) if a < keys.size - 1 else int(key_frame)
    s0, s1 = max(lo - 1, 0), min(hi + 1, n - 1)
    return s0, s1, np.array(sorted({s0, lo, int(key_frame), hi, s1}), dtype=np.int64) - s0


def key_slope_block(
    frames: NDArray, keys: ArrayLike, interp: str, key_frame: int, index: int, slope: float
) -> tuple[int, NDArray]:
    """``(start, block)``: the frames after one component's handle at ``key_frame`` is turned so
    that the edited frames' own key tangents there (leaving and arriving, as
    :func:`~hairtool.keys.reconstruct.key_poses` takes them from the frames) are ``slope`` per
    frame: a hair key's handle dragged in a graph editor, both handles aligned.

    ``index`` is the component in a frame's flattened values (vertex·3 + axis). The change is
    the residual-keeping edit of the key's tangents, Δ(t) = h10·L·δ_out + h11·L·δ_in between
    the neighbouring keys (the key poses stay); the tangents read back from the edited frames
    are affine in (δ_out, δ_in), so two trial edits give the δ that reads back ``slope``. Only
    that component changes; linear keys have no handles (ParameterError).

    Parameters
    ----------
    frames : ndarray
        ``(F, ...)`` the frames.
    keys : array_like
        The key frames.
    interp : str
        The key curve (Hermite).
    key_frame : int
        The key whose handle turns.
    index : int
        The component.
    slope : float
        The new slope, per frame.

    Returns
    -------
    tuple of (int, ndarray)
        The first frame changed and the changed frames.
    """
    if interp == "linear":
        raise ParameterError("interp", interp, "hermite or hermite-fit (linear keys have no handles)")
    f = np.asarray(frames)
    n = f.shape[0]
    k = check_keys(keys, n)
    s0, s1, sub_keys = _stretch(n, k, key_frame)
    a = int(np.flatnonzero(sub_keys == int(key_frame) - s0)[0])
    flat = f[s0 : s1 + 1].reshape(s1 - s0 + 1, -1)
    if not 0 <= index < flat.shape[1]:
        raise ParameterError("index", index, f"a component 0..{flat.shape[1] - 1}")
    y = flat[:, index].astype(np.float64)[:, None]
    t = np.arange(y.shape[0])

    def edited(d_out: float, d_in: float) -> F64:
        out, inn = np.zeros((sub_keys.size, 1)), np.zeros((sub_keys.size, 1))
        out[a], inn[a] = d_out, d_in
        zero = np.zeros((sub_keys.size, 1))
        return y + interpolate_at(KeyPoses(sub_keys, zero, out, y.shape[0], "hermite", inn), t)

    def read(z: F64) -> F64:
        kp = key_poses(z, sub_keys, interp)
        arriving = kp.tangents if kp.tangents_in is None else kp.tangents_in
        return np.array([kp.tangents[a, 0], arriving[a, 0]])

    now = read(y)
    gain = np.column_stack([read(edited(1.0, 0.0)) - now, read(edited(0.0, 1.0)) - now])
    want = np.array([slope, slope], dtype=np.float64) - now
    if interp == "hermite":  # one tangent per key: the same δ on both sides
        g = gain.sum(axis=1)
        d = float(g @ want / (g @ g)) if g @ g > 1e-12 else float(want[0])
        delta = (d, d)
    else:
        try:
            delta = tuple(np.linalg.solve(gain, want))
        except np.linalg.LinAlgError:
            delta = (float(want[0]), float(want[1]))
    block = np.array(f[s0 : s1 + 1])
    flat_out = block.reshape(s1 - s0 + 1, -1)
    flat_out[:, index] = edited(*delta)[:, 0].astype(block.dtype)
    return s0, block
