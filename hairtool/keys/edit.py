"""Key edits that spread to every frame while the captured detail stays (seed 003 §5).

The residual r_f = x_f − x̂_f between each original frame and its reconstruction from the keys
is stored; after a key pose is replaced, the frames are rebuilt from the keys and r is added
back. It is evaluated as ``x + (x̂_new − x̂_old)``, which is the same sum but exact where no key
moved: with no edit the original comes back bit for bit, and an edit of key k changes only the
frames strictly between k's neighbouring keys. Hermite tangents stay those of the original
samples, so the locality holds for both interpolations.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.groom import Animation
from hairtool.keys.reconstruct import KeyPoses, interpolate_keys, key_poses

F64 = NDArray[np.float64]


class KeyEditor:
    """Original frames ``(F, ...)``, their keys, and the key poses as edited so far."""

    def __init__(self, frames: ArrayLike, keys: ArrayLike, interp: str = "linear") -> None:
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
        """Replace the pose at a key frame (the frames follow on the next :meth:`frames`)."""
        self.key_poses = self.key_poses.with_pose(key_frame, pose)

    def reset(self) -> None:
        self.key_poses = self._base

    def affected_frames(self, key_frame: int) -> tuple[int, int]:
        """``(lo, hi)``: an edit of this key changes frames lo < f < hi only (−1 / F at the ends)."""
        k = self.keys
        hit = np.flatnonzero(k == key_frame)
        if hit.size == 0:
            raise ParameterError("key_frame", key_frame, f"one of the keys {k.tolist()}")
        a = int(hit[0])
        lo = int(k[a - 1]) if a > 0 else -1
        hi = int(k[a + 1]) if a < k.size - 1 else self.original.shape[0]
        return lo, hi

    def frames(self, dtype: type | None = None) -> NDArray:
        """``(F, ...)`` the edited animation: x̂_new + r, exactly the original where nothing moved."""
        delta = interpolate_keys(self.key_poses) - self._base_frames
        out = self.original.astype(np.float64) + delta
        return out.astype(dtype or self.original.dtype)


def edit_animation(
    animation: Animation, keys: ArrayLike, edits: dict[int, ArrayLike], interp: str = "linear"
) -> Animation:
    """The animation with the given key poses ``{key_frame: (V, 3) points}`` replaced."""
    editor = KeyEditor(animation.frames, keys, interp)
    for frame, pose in edits.items():
        editor.set_key_pose(int(frame), pose)
    return animation.with_frames(editor.frames(np.float32))
