"""A hair animation's channels for the graph editor: one strand vertex's x, y and z over the
frames (the strand and vertex chosen in the dock; the tip by default).

The curves are the animation as it was opened (faint), as edited (the key curve plus the
residuals) and the key curve alone through the timeline's DP keys, with the key poses' Hermite
tangents as handles. A key dragged in value is the timeline's own residual-keeping key edit
(:func:`hairtool.keys.session.key_edit_block`, the same as brushing the key pose, one undo step):
the vertex moves at the key and the frames between its neighbouring keys follow. A key dragged
sideways moves in time (:func:`hairtool.keys.edit.retime_key`: the frames between its neighbours
retimed with it, the timeline's keys the moved ones). The handles are the key poses' Hermite
tangents, which the timeline takes from the frames themselves; a handle dragged turns the
frames between the neighbouring keys so that their own tangent at the key is the slope dragged
to (:func:`hairtool.keys.edit.key_slope_block`), so the handle stays where it was dropped.

Beside them, the chosen strand's feature channels (seed 000: what the key choice measures, the
strand resampled by arc length, root-relative, the mean root removed, weighted toward the tip;
:func:`hairtool.keys.features.strand_features`) at the sample as far along the strand as the
chosen vertex: as opened (faint), as edited, and the key curve the DP fits through the keys in
that space. They are read-only: a resampled point lies between vertices and slides along the
strand as its segments stretch, so a feature value set at a key names no single pose of the
strand's vertices (many poses resample to it), and there is no residual-keeping edit to give
it; without resampling a feature is a vertex's coordinates moved and scaled, which the vertex
curves edit already.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from hairtool.keys.edit import check_retime, key_slope_block, retime_key
from hairtool.keys.features import strand_features
from hairtool.keys.reconstruct import KeyPoses, interpolate_at, key_poses
from hairtool.keys.session import key_edit_block

if TYPE_CHECKING:
    from app.ui.host import StudioHost

AXES = ("x", "y", "z")
READ_ONLY = (
    "Feature channels are what the key choice measures (the strand resampled along its length, "
    "relative to its root, weighted toward the tip): shown, not edited, because a resampled "
    "point slides between the strand's vertices, so a value set here names no single pose. "
    "Drag the vertex's x, y and z keys to edit"
)


class HairChannels:
    """Owned by the graph editor dock; ``strand`` and ``vertex`` (−1: the tip) pick the vertex."""

    def __init__(self, window: StudioHost) -> None:
        self.window, self.model = window, window.animation
        self.strand, self.vertex = 0, -1
        self.features = True  # the strand's feature channels beside the vertex's coordinates
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

    def sample(self) -> int:
        """The feature sample shown: as far along the strand as the chosen vertex (the tip: the
        last sample; the original vertices when the features do not resample)."""
        topo = self.model.animation.topology
        s = int(np.clip(self.strand, 0, topo.strand_count - 1))
        n = int(topo.offsets[s + 1] - topo.offsets[s])
        v = self.index() - int(topo.offsets[s])
        m = self.model.settings.feature_options().samples
        if m is None:
            return v
        return round(v / max(n - 1, 1) * (int(m) - 1))

    def feature_channels(self) -> list[tuple]:
        """Per axis of the chosen strand's feature sample (:meth:`sample`): (name, original,
        result, key curve, keys, key values, slope in, slope out), the key curve and its handles
        those the key choice fits through the timeline's keys in feature space
        (:func:`hairtool.keys.features.strand_features` of the animation as opened and as now)."""
        m = self.model
        anim, options = m.animation, m.settings.feature_options()
        s = int(np.clip(self.strand, 0, anim.topology.strand_count - 1))
        i = self.sample()
        result = strand_features(anim, s, options)[:, i]
        loaded = self.loaded
        same = loaded is not None and loaded.frames.shape == anim.frames.shape
        original = strand_features(loaded, s, options)[:, i] if same else result
        kp = key_poses(result, m.dp_keys, m.dp_poses.interp)
        key_curve = interpolate_at(kp, np.arange(anim.n_frames))
        arriving = kp.tangents if kp.tangents_in is None else kp.tangents_in
        out = []
        for a, name in enumerate(AXES):
            s_in = None if arriving is None else arriving[:, a]
            s_out = None if kp.tangents is None else kp.tangents[:, a]
            curves = (original[:, a], result[:, a], key_curve[:, a])
            out.append((f"feature {name}", *curves, kp.keys, kp.poses[:, a], s_in, s_out))
        return out

    def edited_block(
        self, axis: int, key: int, value: float, to: int | None = None
    ) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
        """``(start, block, pose, keys)``: the frames after the key at ``key`` is moved to the
        frame ``to`` (:func:`hairtool.keys.edit.retime_key`; None: it stays) and the vertex's
        ``axis`` there set to ``value`` (the timeline's key edit), the key pose and the keys.
        Worked on the stretch between the key's neighbours and one frame each side, which gives
        the same frames as the whole animation would."""
        m = self.model
        frames, keys, interp = m.animation.frames, m.dp_keys, m.dp_poses.interp
        to = key if to is None else int(to)
        a = int(np.flatnonzero(keys == key)[0])
        lo = int(keys[a - 1]) if a > 0 else key
        hi = int(keys[a + 1]) if a < keys.size - 1 else key
        s0, s1 = max(lo - 1, 0), min(hi + 1, m.n_frames - 1)
        sub = np.array(frames[s0 : s1 + 1])
        sub_keys = np.array(sorted({0, lo - s0, key - s0, hi - s0, s1 - s0}), dtype=np.int64)
        new_keys = keys
        if to != key:
            start, block, sub_keys = retime_key(sub, sub_keys, interp, key - s0, to - s0)
            sub[start : start + len(block)] = block
            _, new_keys = check_retime(keys, m.n_frames, key, to)
        pose = np.array(sub[to - s0])
        pose[self.index(), axis] = value
        if value != float(sub[to - s0, self.index(), axis]):
            start, block = key_edit_block(sub, sub_keys, interp, to - s0, pose)
            sub[start : start + len(block)] = block
        return s0, sub, pose, new_keys

    def preview(
        self, axis: int | None, key: int = 0, value: float = 0.0, to: int | None = None
    ) -> np.ndarray | None:
        """Show the key pose being dragged in the viewport at its frame (None: stop); the
        dragged axis's edited curve is returned."""
        m = self.model
        if axis is None:
            m.set_preview(m.frame, None)
            return None
        start, block, pose, _ = self.edited_block(axis, key, value, to)
        m.set_preview(key if to is None else to, pose.astype(np.float32))
        result = m.animation.frames[:, self.index(), axis].astype(np.float64)
        result[start : start + len(block)] = block[:, self.index(), axis]
        return result

    def commit(self, axis: int, key: int, value: float, to: int | None = None) -> None:
        """One undo step: the key moved (in value, in time or both)."""
        m = self.model
        start, block, _, keys = self.edited_block(axis, key, value, to)
        if to is None or to == key:
            m.edit_frames(start, block, f"Move vertex {AXES[axis]} key at {key}")
        else:
            m.edit_frames(start, block, f"Move key {key} to {to}", keys=np.array(keys))

    # -- handles --------------------------------------------------------------------------------
    def slope_block(self, axis: int, key: int, slope: float) -> tuple[int, np.ndarray]:
        """The frames after the vertex's ``axis`` handle at key ``key`` is turned to ``slope``
        (per frame, both handles): :func:`hairtool.keys.edit.key_slope_block`, so the key poses
        the timeline takes from the edited frames have that slope there."""
        m = self.model
        index = self.index() * 3 + axis
        return key_slope_block(m.animation.frames, m.dp_keys, m.dp_poses.interp, key, index, slope)

    def preview_slope(self, axis: int, key: int, slope: float) -> np.ndarray:
        """The dragged axis's edited curve while a handle is dragged."""
        start, block = self.slope_block(axis, key, slope)
        result = self.model.animation.frames[:, self.index(), axis].astype(np.float64)
        result[start : start + len(block)] = block[:, self.index(), axis]
        return result

    def commit_slope(self, axis: int, key: int, slope: float) -> None:
        m = self.model
        start, block = self.slope_block(axis, key, slope)
        m.edit_frames(start, block, f"Turn vertex {AXES[axis]} handle at {key}")
