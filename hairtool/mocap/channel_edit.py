"""Per-channel keys of a capture (seed 003: each degree of freedom a curve with its own keys) and
key-pose edits by IK on them.

The degrees of freedom are the BVH's own channels, as a DCC keys them: rotation angles in
degrees (unwrapped along time, so a capture's ±180° wraps are not motion) and position channels
in scene units. Each channel c is a curve through its own keys K_c plus the residual of every
frame against it. An edit at frame f solves the IK on the edited pose there, and for each channel
it turns moves that channel's key at f by Δ_c — adding f to K_c when it was not a key of that
channel (a knot inserted, as a DCC inserts a key where a handle is dragged). The capture's value
then changes by Δ_c times the curve's basis (linear: the hat 1 − s; Hermite: h00 / h01, the
tangents being the same before and after), so only the frames strictly between c's neighbouring
keys around f change, fading to nothing at them; every other frame and channel stays the capture
bit for bit. Angles add directly: continuous by construction, with no Euler representation to
choose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.keys.reconstruct import KeyPoses, interpolate_at, interpolate_keys, key_poses
from hairtool.mocap import ik
from hairtool.mocap.bvh import Motion
from hairtool.mocap.pose_edit import INTERPS, EditReport, PoseEdit

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


def channel_features(motion: Motion) -> F64:
    """``(F, C)`` the capture's channels, rotation angles unwrapped along time (period 360°)."""
    x = motion.values.copy()
    rot = [c for j in range(motion.n_joints) for c in ik.rotation_columns(motion, j)[0]]
    if rot and motion.n_frames > 1:
        x[:, rot] = np.unwrap(x[:, rot], period=360.0, axis=0)
    return x


def _check_channel_keys(motion: Motion, keys: list[ArrayLike]) -> list[I64]:
    if len(keys) != motion.n_channels:
        raise ParameterError("channel keys", len(keys), f"one key list per channel ({motion.n_channels})")
    out = []
    last = motion.n_frames - 1
    for c, k in enumerate(keys):
        a = np.unique(np.asarray(k, dtype=np.int64))
        if a.size < 2 or a[0] != 0 or a[-1] != last:
            raise ParameterError(f"keys of channel {c}", a.tolist()[:6], f"frames from 0 to {last}")
        out.append(a)
    return out


def channel_key_curve(motion: Motion, keys: list[ArrayLike], interp: str = "hermite") -> Motion:
    """The reduced motion: every channel its key curve through its own keys (on the unwrapped
    angles), the angles written back within whole turns of the capture's."""
    if interp not in INTERPS:
        raise ParameterError("interp", interp, " or ".join(INTERPS))
    ks = _check_channel_keys(motion, keys)
    x = channel_features(motion)
    values = motion.values.copy()
    for c, k in enumerate(ks):
        curve = interpolate_keys(key_poses(x[:, c : c + 1], k, interp))[:, 0]
        values[:, c] = curve + (motion.values[:, c] - x[:, c])  # the capture's own whole turns
    return motion.with_values(values)


@dataclass
class _Step:
    report: EditReport
    changes: dict[int, dict[int, float]]


class ChannelEditor:
    """A capture, each channel's keys, and the key changes of the edits so far (undoable)."""

    def __init__(self, motion: Motion, keys: list[ArrayLike], interp: str = "hermite") -> None:
        if interp not in INTERPS:
            raise ParameterError("interp", interp, " or ".join(INTERPS))
        self.original = motion
        self.interp = interp
        self._keys0 = _check_channel_keys(motion, keys)
        self.height = ik.figure_height(motion)
        self._history: list[_Step] = []

    # -- state -----------------------------------------------------------------------------
    def _changes(self) -> dict[int, dict[int, float]]:
        """Channel → {key frame: Δ} summed over the edits so far."""
        total: dict[int, dict[int, float]] = {}
        for step in self._history:
            for c, moves in step.changes.items():
                for f, d in moves.items():
                    total.setdefault(c, {})[f] = total.get(c, {}).get(f, 0.0) + d
        return total

    def keys(self, channel: int) -> I64:
        """A channel's keys: its solved keys and the frames edits added to it."""
        added = [f for step in self._history for f in step.changes.get(channel, {})]
        return np.union1d(self._keys0[channel], np.asarray(added, dtype=np.int64))

    @property
    def union(self) -> I64:
        """Frames that are a key of at least one channel (where an edit may be made)."""
        return np.unique(np.concatenate([self.keys(c) for c in range(self.original.n_channels)]))

    @property
    def reports(self) -> list[EditReport]:
        return [s.report for s in self._history]

    def _delta(self, c: int, moves: dict[int, float], frames: I64) -> F64:
        k = self.keys(c)
        change = np.zeros((k.size, 1))
        for f, d in moves.items():
            change[np.searchsorted(k, f), 0] = d
        zero = None if self.interp == "linear" else np.zeros_like(change)
        kind = "linear" if self.interp == "linear" else "hermite"
        return interpolate_at(KeyPoses(k, change, zero, self.original.n_frames, kind), frames)[:, 0]

    def _span(self, c: int, f: int) -> tuple[int, int]:
        """``[start, stop)``: the frames a move of channel c's key at f changes."""
        k = self.keys(c)
        a = int(np.searchsorted(k, f))
        start = int(k[a - 1]) + 1 if a > 0 else 0
        stop = int(k[a + 1]) if a < k.size - 1 else self.original.n_frames
        return start, stop

    def pose(self, frame: int) -> F64:
        """``(C,)`` the edited capture's channels at one frame."""
        v = self.original.values[frame].copy()
        for c, moves in self._changes().items():
            v[c] += self._delta(c, moves, np.array([frame]))[0]
        return v

    # -- editing ---------------------------------------------------------------------------
    def apply(self, edit: PoseEdit, method: str = "auto") -> EditReport:
        m = self.original
        union = self.union
        if edit.frame not in union:
            listed = " ".join(map(str, union.tolist()))
            raise ParameterError("frame", edit.frame, f"a key of some channel: {listed}")
        if edit.joint not in m.joint_names:
            raise ParameterError("joint", edit.joint, "a joint of the skeleton")
        e = m.joint_names.index(edit.joint)
        current = self.pose(edit.frame)
        s = ik.solve(m, current, e, edit.chain, edit.target, ik.TOLERANCE * self.height, method)
        turned = ik.ancestors(m, e, edit.chain)
        # A channel's key at the frame moves by what the IK changed; where the frame was not one
        # of its keys it becomes one, holding the value the edits before gave it there too.
        moves: dict[int, dict[int, float]] = {}
        for c in np.flatnonzero(s.values != current).tolist():
            knot = edit.frame in self.keys(c)
            moves[c] = {edit.frame: float(s.values[c] - (current[c] if knot else m.values[edit.frame, c]))}
        names = [m.joint_names[j] for j in turned]
        f = edit.frame
        report = EditReport(edit, names, s.method, s.iterations, s.miss, s.miss / self.height, f, f)
        step = _Step(report, moves)
        self._history.append(step)
        if moves:
            spans = [self._span(c, edit.frame) for c in moves]
            report.first = min(a for a, _ in spans)
            report.last = max(b for _, b in spans) - 1
        return step.report

    def apply_all(self, edits: list[PoseEdit], method: str = "auto") -> list[EditReport]:
        return [self.apply(e, method) for e in edits]

    def undo(self) -> PoseEdit | None:
        return self._history.pop().report.edit if self._history else None

    def reset(self) -> None:
        self._history.clear()

    def motion(self) -> Motion:
        """The edited capture: each moved channel plus its keys' changes spread by the basis,
        only between the neighbouring keys of each moved key (elsewhere the capture itself)."""
        m = self.original
        values = m.values.copy()
        for c, moves in self._changes().items():
            frames = np.unique(np.concatenate([np.arange(*self._span(c, f)) for f in moves]))
            values[frames, c] = m.values[frames, c] + self._delta(c, moves, frames)
        return m.with_values(values)
