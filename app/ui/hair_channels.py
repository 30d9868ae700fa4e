"""A hair animation's channels for the graph editor: one strand vertex's x, y and z over the
frames (the strand and vertex chosen in the dock; the tip by default).

The curves are the animation as it was opened (faint), as edited (the key curve plus the
residuals) and the key curve alone through the timeline's DP keys, with the key poses' Hermite
tangents as handles. A key dragged in value is the timeline's own residual-keeping key edit
(:func:`hairtool.keys.session.key_edit_block`, the same as brushing the key pose, one undo step):
the vertex moves at the key and the frames between its neighbouring keys follow. Hair handles
show the sampled tangents and are not dragged (the hair key edit keeps them).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from app.ui.animation_ui import KeyEditCommand
from hairtool.keys.reconstruct import KeyPoses, interpolate_at
from hairtool.keys.session import key_edit_block

if TYPE_CHECKING:
    from app.ui.host import StudioHost

AXES = ("x", "y", "z")


class HairChannels:
    """Owned by the graph editor dock; ``strand`` and ``vertex`` (−1: the tip) pick the vertex."""

    def __init__(self, window: StudioHost) -> None:
        self.window, self.model = window, window.animation
        self.strand, self.vertex = 0, -1
        self.loaded = None  # the animation as opened (the faint curves)
        self.model.animation_changed.connect(self._on_animation_changed)
        self._on_animation_changed()

    def _on_animation_changed(self) -> None:
        self.loaded = self.model.animation

    @property
    def active(self) -> bool:
        capture = getattr(self.window, "capture", None)
        return (
            self.model.animation is not None
            and self.model.dp_poses is not None
            and not (capture is not None and capture.attached)
        )

    def index(self) -> int:
        """The chosen vertex's index in the animation's points (strand and vertex clamped)."""
        topo = self.model.animation.topology
        s = int(np.clip(self.strand, 0, topo.strand_count - 1))
        lo, hi = int(topo.offsets[s]), int(topo.offsets[s + 1])
        v = hi - 1 if self.vertex < 0 else min(lo + int(self.vertex), hi - 1)
        return v

    def _vertex_keys(self, v: int) -> KeyPoses:
        kp = self.model.dp_poses
        pick = None if kp.tangents is None else kp.tangents[:, v]
        pick_in = None if kp.tangents_in is None else kp.tangents_in[:, v]
        return KeyPoses(kp.keys, kp.poses[:, v], pick, kp.n_frames, kp.interp, pick_in)

    def channels(self) -> list[tuple]:
        """Per axis: (name, original, result, key curve, keys, key values, slope in, slope out)."""
        anim = self.model.animation
        v = self.index()
        kp = self._vertex_keys(v)
        key_curve = interpolate_at(kp, np.arange(anim.n_frames))
        result = anim.frames[:, v].astype(np.float64)
        loaded = self.loaded
        same = loaded is not None and loaded.frames.shape == anim.frames.shape
        original = loaded.frames[:, v].astype(np.float64) if same else result
        out = []
        for i, name in enumerate(AXES):
            s_out = None if kp.tangents is None else kp.tangents[:, i]
            s_in = (
                None
                if kp.tangents is None
                else (kp.tangents if kp.tangents_in is None else kp.tangents_in)[:, i]
            )
            out.append(
                (name, original[:, i], result[:, i], key_curve[:, i], kp.keys, kp.poses[:, i], s_in, s_out)
            )
        return out

    def edited_block(self, axis: int, key: int, value: float) -> tuple[int, np.ndarray, np.ndarray]:
        """``(start, block, pose)``: the frames after the vertex's ``axis`` at key frame ``key``
        is set to ``value`` (the timeline's key edit), and the key pose."""
        m = self.model
        frames = m.animation.frames
        pose = np.array(frames[key])
        pose[self.index(), axis] = value
        start, block = key_edit_block(frames, m.dp_keys, m.dp_poses.interp, key, pose)
        return start, block, pose

    def preview(self, axis: int | None, key: int = 0, value: float = 0.0) -> np.ndarray | None:
        """Show the key pose being dragged in the viewport (None: stop); the dragged axis's
        edited curve is returned."""
        m = self.model
        if axis is None:
            m.set_preview(m.frame, None)
            return None
        start, block, pose = self.edited_block(axis, key, value)
        m.set_preview(key, pose.astype(np.float32))
        result = m.animation.frames[:, self.index(), axis].astype(np.float64)
        result[start : start + len(block)] = block[:, self.index(), axis]
        return result

    def commit(self, axis: int, key: int, value: float) -> None:
        m = self.model
        start, block, _ = self.edited_block(axis, key, value)
        before = np.array(m.animation.frames[start : start + len(block)])
        command = KeyEditCommand(m, m.generation, key, start, before, block)
        command.setText(f"Move vertex {AXES[axis]} key at {key}")
        self.window.undo_stack.push(command)
