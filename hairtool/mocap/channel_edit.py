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
choose. At a frame inside a stretch a moved key of c retimed (which shows the capture at a
fractional frame, so no captured key can go there) the key is added on top of the stretch: its
change spread by the same basis with flat tangents to c's neighbouring keys there.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import FormatError, ParameterError
from hairtool.keys.edit import check_retime, residual_at, time_warp
from hairtool.keys.reconstruct import KeyPoses, interpolate_at, interpolate_keys, key_poses
from hairtool.mocap import ik
from hairtool.mocap.bvh import MAX_VALUE, Motion
from hairtool.mocap.pose_edit import (
    INTERPS,
    ChannelEdit,
    EditReport,
    PoseEdit,
    TangentEdit,
    apply_edits,
    parse_edit_list,
)

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


def channel_features(motion: Motion) -> F64:
    """``(F, C)`` the capture's channels, rotation angles unwrapped along time (period 360°).

    Parameters
    ----------
    motion : Motion
        The capture.

    Returns
    -------
    ndarray
        ``(F, C)`` float64.
    """
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
    angles), the angles written back within whole turns of the capture's.

    Parameters
    ----------
    motion : Motion
        The capture.
    keys : list of array_like
        Each channel's key frames.
    interp : str, default "hermite"
        The key curve.

    Returns
    -------
    Motion
        The reduced motion.
    """
    if interp not in INTERPS:
        raise ParameterError("interp", interp, " or ".join(INTERPS))
    ks = _check_channel_keys(motion, keys)
    x = channel_features(motion)
    values = motion.values.copy()
    for c, k in enumerate(ks):
        curve = interpolate_keys(key_poses(x[:, c : c + 1], k, interp))[:, 0]
        values[:, c] = curve + (motion.values[:, c] - x[:, c])  # the capture's own whole turns
    return motion.with_values(values)


@dataclass(frozen=True)
class ChannelRetimeEdit:
    """Move one channel's key at ``frame`` to the frame ``to`` (strictly between that channel's
    neighbouring keys): a per-channel key dragged in time; the other channels keep their keys."""

    frame: int
    joint: str
    channel: str
    to: int

    def to_dict(self) -> dict:
        return asdict(self)


ChannelKeyEdit = ChannelEdit | TangentEdit | ChannelRetimeEdit


def parse_channel_edits(data: object, motion: Motion, source: str = "edits") -> list[ChannelKeyEdit]:
    """Per-channel key edits from JSON data (what a studio project keeps): value and handle
    edits as :func:`~hairtool.mocap.pose_edit.parse_edit_list` reads them, and key moves
    ``{"frame", "joint", "channel", "to"}``; faults raise FormatError naming ``source``.

    Parameters
    ----------
    data : object
        The parsed JSON list.
    motion : Motion
        The capture.
    source : str, default "edits"
        The file, named in a refusal.

    Returns
    -------
    list of ChannelKeyEdit
        The edits, in order.
    """
    if not isinstance(data, list):
        raise FormatError(source, "expected a list of per-channel key edits")
    out: list[ChannelKeyEdit] = []
    for i, e in enumerate(data, 1):
        if isinstance(e, dict) and "to" in e and "channel" in e:
            fields = ("frame", "joint", "channel", "to")
            if set(e) != set(fields):
                raise FormatError(source, f"channel edit {i} needs exactly the fields {', '.join(fields)}")
            try:
                (value,) = parse_edit_list([{**{k: e[k] for k in fields[:3]}, "value": 0.0}], motion, source)
            except FormatError as err:
                raise FormatError(source, err.reason.replace("edit 1", f"channel edit {i}", 1)) from None
            to = e["to"]
            if not isinstance(to, int) or isinstance(to, bool) or not 0 <= to < motion.n_frames:
                raise FormatError(source, f"channel edit {i}: to {str(to)[:40]} is not a frame number")
            out.append(ChannelRetimeEdit(value.frame, value.joint, value.channel, int(to)))
            continue
        try:
            (edit,) = parse_edit_list([e], motion, source)
        except FormatError as err:
            raise FormatError(source, err.reason.replace("edit 1", f"channel edit {i}", 1)) from None
        if not isinstance(edit, ChannelEdit | TangentEdit):
            raise FormatError(source, f"channel edit {i} is not a key's value, slope or move of one channel")
        out.append(edit)
    return out


@dataclass
class _Step:
    """One edit: per channel, the value change at its keys ({original frame: Δ}; a frame that
    was no key of the channel becomes one), the slope change ({original frame: δ}) and keys
    moved in time ({original frame: frame now})."""

    report: EditReport
    changes: dict[int, dict[int, float]]
    slopes: dict[int, dict[int, float]] = field(default_factory=dict)
    moves: dict[int, dict[int, int]] = field(default_factory=dict)
    late: dict[int, dict[int, float]] = field(default_factory=dict)  # keys added in a stretch


@dataclass
class _Channel:
    """A channel's keys as edited: ``knots`` the key frames before any move (the residuals are
    measured against the key curve through them), ``keys`` where they are now, the value and
    slope changes at each, and ``late``: keys an edit added at frames a moved key stretched
    ({frame now: the change there}, see :meth:`ChannelEditor.apply`)."""

    knots: I64
    keys: I64
    change: F64
    slope: F64
    late: dict[int, float] = field(default_factory=dict)

    @property
    def all_keys(self) -> I64:
        return np.union1d(self.keys, np.fromiter(self.late, dtype=np.int64)) if self.late else self.keys


def _hermite_slope(kp: KeyPoses, t: float) -> float:
    """d/dt of a one-channel Hermite key curve at frame t strictly inside a segment."""
    a = int(np.searchsorted(kp.keys, t, side="right") - 1)
    k0, k1 = float(kp.keys[a]), float(kp.keys[a + 1])
    span = k1 - k0
    s = (t - k0) / span
    arriving = kp.tangents if kp.tangents_in is None else kp.tangents_in
    p0, p1 = float(kp.poses[a, 0]), float(kp.poses[a + 1, 0])
    m0, m1 = float(kp.tangents[a, 0]), float(arriving[a + 1, 0])
    d00, d10, d01, d11 = 6 * s * s - 6 * s, 3 * s * s - 4 * s + 1, 6 * s - 6 * s * s, 3 * s * s - 2 * s
    return (d00 * p0 + d01 * p1) / span + d10 * m0 + d11 * m1


class ChannelEditor:
    """A capture, each channel's keys, and the edits so far (undoable): IK edits (:meth:`apply`),
    and a channel's key moved in value, slope or time (:meth:`apply_channel`,
    :meth:`apply_tangent`, :meth:`apply_retime`, as a graph editor drags them).

    A channel's edited values are its key curve through the edited keys plus the residual of
    every frame against the captured key curve: where a segment kept its keys, the capture plus
    the key changes spread by the curve's basis (exact elsewhere); in a segment a moved key
    stretched, the curve there plus the residual of the frame it now shows
    (:func:`hairtool.keys.edit.retime_key`), on the unwrapped angles, written back within the
    capture's own whole turns."""

    RETIME = ChannelRetimeEdit  # the key moves it makes: one channel's key
    KINDS = (
        "an edit of per-channel keys: an IK pose, one channel's key value, handle or move in "
        "time (a pose key moved in time moves every channel: the pose keys' edits)"
    )

    def __init__(
        self,
        motion: Motion,
        keys: list[ArrayLike],
        interp: str = "hermite",
        pose_keys: ArrayLike | None = None,
    ) -> None:
        """Every channel of ``motion`` on its own key curve through ``keys``, ready for edits.

        Parameters
        ----------
        motion : Motion
            The capture.
        keys : list of array_like
            Each channel's key frames.
        interp : str, default "hermite"
            The key curve.
        pose_keys : array_like, optional
            The pose keys below this layer, where an IK pose may also be made.
        """
        if interp not in INTERPS:
            raise ParameterError("interp", interp, " or ".join(INTERPS))
        self.original = motion
        self.interp = interp
        self._keys0 = _check_channel_keys(motion, keys)
        # the pose keys below this layer (the studio's handles are drawn at them): an IK pose may
        # be made there too, each channel it turns keyed there (a knot inserted where none was)
        self.pose_keys = np.zeros(0, dtype=np.int64) if pose_keys is None else np.asarray(pose_keys, np.int64)
        self.height = ik.figure_height(motion)
        self._history: list[_Step] = []
        self._unwrapped = channel_features(motion)
        self._base_curves: dict[tuple, KeyPoses] = {}

    # -- state -----------------------------------------------------------------------------
    def _changes(self) -> dict[int, dict[int, float]]:
        """Channel → {key frame: Δ} summed over the edits so far."""
        total: dict[int, dict[int, float]] = {}
        for step in self._history:
            for c, moves in step.changes.items():
                for f, d in moves.items():
                    total.setdefault(c, {})[f] = total.get(c, {}).get(f, 0.0) + d
        return total

    def _touched(self) -> set[int]:
        return {c for s in self._history for part in (s.changes, s.slopes, s.moves, s.late) for c in part}

    def _channel(self, c: int) -> _Channel:
        knots = self._keys0[c]
        added = [f for s in self._history for f in s.changes.get(c, {})]
        if added:
            knots = np.union1d(knots, np.asarray(added, dtype=np.int64))
        change, slope, moved = np.zeros(knots.size), np.zeros(knots.size), knots.copy()
        for s in self._history:
            for f, d in s.changes.get(c, {}).items():
                change[np.searchsorted(knots, f)] += d
            for f, d in s.slopes.get(c, {}).items():
                slope[np.searchsorted(knots, f)] += d
            for f, to in s.moves.get(c, {}).items():
                moved[np.searchsorted(knots, f)] = to
        late = {f: v for s in self._history for f, v in s.late.get(c, {}).items()}  # the last wins
        return _Channel(knots, moved, change, slope, late)

    def keys(self, channel: int) -> I64:
        """A channel's keys now: its solved keys, the frames edits added to it, moved ones where
        they were moved to.

        Parameters
        ----------
        channel : int
            The channel's column.

        Returns
        -------
        ndarray
            int64 key frames.
        """
        return self._channel(channel).all_keys

    @property
    def union(self) -> I64:
        """Frames that are a key of at least one channel (where an edit may be made)."""
        return np.unique(np.concatenate([self.keys(c) for c in range(self.original.n_channels)]))

    @property
    def pose_frames(self) -> I64:
        """Frames an IK pose may be made at: a key of some channel, or one of the pose keys
        below (``pose_keys``)."""
        return np.union1d(self.union, self.pose_keys)

    @property
    def reports(self) -> list[EditReport]:
        return [s.report for s in self._history]

    def _base(self, c: int, knots: I64) -> KeyPoses:
        """Channel c's captured key curve (unwrapped) through ``knots``."""
        key = (c, knots.tobytes())
        if key not in self._base_curves:
            self._base_curves[key] = key_poses(self._unwrapped[:, c : c + 1], knots, self.interp)
        return self._base_curves[key]

    def _warped(self, ch: _Channel) -> I64:
        """Frames in a segment next to a moved key (its own frame included)."""
        moved = np.flatnonzero(ch.keys != ch.knots)
        if moved.size == 0:
            return np.zeros(0, dtype=np.int64)
        k = ch.keys
        return np.unique(np.concatenate([np.arange(k[a - 1] + 1, k[a + 1]) for a in moved]))

    def _edited_curve(self, c: int, ch: _Channel) -> KeyPoses:
        """Channel c's key curve as edited (unwrapped): the captured key poses and tangents plus
        the changes, at the keys' frames now."""
        base = self._base(c, ch.knots)
        poses = base.poses + ch.change[:, None]
        if base.tangents is None:
            return KeyPoses(ch.keys, poses, None, base.n_frames, base.interp)
        out = base.tangents + ch.slope[:, None]
        inn = None if base.tangents_in is None else base.tangents_in + ch.slope[:, None]
        return KeyPoses(ch.keys, poses, out, base.n_frames, base.interp, inn)

    def _values(self, c: int, ch: _Channel, frames: I64) -> F64:
        """The edited channel at ``frames``."""
        m = self.original
        out = m.values[frames, c].astype(np.float64)
        warped = np.isin(frames, self._warped(ch))
        still = frames[~warped]
        if still.size and (np.any(ch.change) or np.any(ch.slope)):
            zero = None if self.interp == "linear" else ch.slope[:, None]
            kind = "linear" if self.interp == "linear" else "hermite"
            kp = KeyPoses(ch.keys, ch.change[:, None], zero, m.n_frames, kind)
            out[~warped] = m.values[still, c] + interpolate_at(kp, still)[:, 0]
        if warped.any():
            t = frames[warped]
            base = self._base(c, ch.knots)
            x = self._unwrapped[:, c : c + 1]
            curve = interpolate_at(self._edited_curve(c, ch), t)[:, 0]
            r = residual_at(x, lambda i: interpolate_at(base, i), time_warp(t, ch.keys, ch.knots))[:, 0]
            out[warped] = curve + r + (m.values[t, c] - self._unwrapped[t, c])
        if ch.late:
            out += self._late(ch, frames)
        return out

    def _late(self, ch: _Channel, frames: I64) -> F64:
        """The change the keys added in a stretch give ``frames``: each key's change there spread
        by the curve's basis to its neighbouring keys (flat tangents: the curve it was added to
        keeps its slope there), so it fades to nothing at them."""
        knots = ch.all_keys
        values = np.array([ch.late.get(int(k), 0.0) for k in knots])[:, None]
        if self.interp == "linear":
            kp = KeyPoses(knots, values, None, self.original.n_frames, "linear")
        else:
            kp = KeyPoses(knots, values, np.zeros_like(values), self.original.n_frames, "hermite")
        return interpolate_at(kp, frames)[:, 0]

    def _span(self, c: int, f: int) -> tuple[int, int]:
        """``[start, stop)``: the frames a move of channel c's key at f changes."""
        k = self.keys(c)
        a = int(np.searchsorted(k, f))
        start = int(k[a - 1]) + 1 if a > 0 else 0
        stop = int(k[a + 1]) if a < k.size - 1 else self.original.n_frames
        return start, stop

    def pose(self, frame: int) -> F64:
        """``(C,)`` the edited capture's channels at one frame.

        Parameters
        ----------
        frame : int
            The frame.

        Returns
        -------
        ndarray
            ``(C,)`` float64.
        """
        v = self.original.values[frame].astype(np.float64)
        for c in self._touched():
            v[c] = self._values(c, self._channel(c), np.array([frame]))[0]
        return v

    # -- what a graph editor draws -----------------------------------------------------------
    def column(self, joint: str, channel: str) -> int:
        """The capture's column of a joint's channel (ParameterError naming the choices).

        Parameters
        ----------
        joint : str
            The joint's name.
        channel : str
            The channel's name (``Xrotation``...).

        Returns
        -------
        int
            The column.
        """
        m = self.original
        if joint not in m.joint_names:
            raise ParameterError("joint", joint, "a joint of the skeleton")
        j = m.joint_names.index(joint)
        if channel not in m.channels[j]:
            raise ParameterError("channel", channel, f"a channel of '{joint}': {', '.join(m.channels[j])}")
        return int(m._starts[j]) + m.channels[j].index(channel)

    def key_curve(self, c: int) -> F64:
        """``(F,)`` channel c's edited key curve alone (no residuals), within the capture's turns.

        Parameters
        ----------
        c : int
            The channel's column.

        Returns
        -------
        ndarray
            ``(F,)`` float64.
        """
        ch = self._channel(c)
        frames = np.arange(self.original.n_frames)
        curve = interpolate_at(self._edited_curve(c, ch), frames)[:, 0]
        if ch.late:
            curve = curve + self._late(ch, frames)
        return curve + (self.original.values[:, c] - self._unwrapped[:, c])

    def key_slopes(self, c: int) -> tuple[F64, F64] | None:
        """``(in, out)`` slopes (per frame) of channel c's key curve at its keys; None for linear.
        A key added in a stretch has the slope the curve had there (its handle is not turned).

        Parameters
        ----------
        c : int
            The channel's column.

        Returns
        -------
        tuple of (ndarray, ndarray) or None
            Slopes in and out, or None for linear keys.
        """
        ch = self._channel(c)
        kp = self._edited_curve(c, ch)
        if kp.tangents is None:
            return None
        arriving = kp.tangents if kp.tangents_in is None else kp.tangents_in
        s_in, s_out = arriving[:, 0].copy(), kp.tangents[:, 0].copy()
        late = [f for f in sorted(ch.late) if f not in ch.keys]
        if late:  # the slope the curve had there: the added key's change spreads with flat tangents
            slopes = [_hermite_slope(kp, float(f)) for f in late]
            at = np.searchsorted(ch.keys, late)
            s_in, s_out = np.insert(s_in, at, slopes), np.insert(s_out, at, slopes)
        return s_in, s_out

    # -- editing ---------------------------------------------------------------------------
    def _knot(self, c: int, frame: int, what: str) -> tuple[_Channel, int]:
        ch = self._channel(c)
        hit = np.flatnonzero(ch.keys == frame)
        if hit.size == 0 and frame in ch.late:
            why = f"a key of the {what} channel other than one a pose added where a moved key stretched"
            raise ParameterError("frame", frame, f"{why} (that key moves in value only)")
        if hit.size == 0:
            keys = " ".join(map(str, ch.keys.tolist()[:12]))
            raise ParameterError("frame", frame, f"a key of the {what} channel: {keys}")
        return ch, int(hit[0])

    def _report(self, edit: object, joint: str, method: str, c: int, frame: int) -> EditReport:
        first, stop = self._span(c, frame)
        return EditReport(edit, [joint], method, 0, 0.0, 0.0, first, stop - 1)

    def apply_channel(self, edit: ChannelEdit) -> EditReport:
        """Set one channel's key at ``edit.frame`` (a key of that channel) to ``edit.value``.

        Parameters
        ----------
        edit : ChannelEdit
            The joint, channel, key frame and value.

        Returns
        -------
        EditReport
            What the edit changed.
        """
        c = self.column(edit.joint, edit.channel)
        if not (math.isfinite(edit.value) and abs(edit.value) <= MAX_VALUE):
            raise ParameterError("value", edit.value, "a finite number")
        ch = self._channel(c)
        if edit.frame in ch.late and edit.frame not in ch.keys:  # a key a pose added in a stretch
            now = self._values(c, ch, np.array([edit.frame]))[0]
            step = _Step(None, {}, late={c: {edit.frame: ch.late[edit.frame] + float(edit.value - now)}})
            self._history.append(step)
            step.report = self._report(edit, edit.joint, "channel", c, edit.frame)
            return step.report
        ch, a = self._knot(c, edit.frame, edit.channel)
        now = self._values(c, ch, np.array([edit.frame]))[0]
        step = _Step(None, {c: {int(ch.knots[a]): float(edit.value - now)}})
        self._history.append(step)
        step.report = self._report(edit, edit.joint, "channel", c, edit.frame)
        return step.report

    def apply_tangent(self, edit: TangentEdit) -> EditReport:
        """Set the slope (per frame) one channel's key curve passes its key at ``edit.frame``
        with (the leaving handle; the arriving one turns by as much, so seed 003's handles stay
        aligned); linear keys have none (ParameterError).

        Parameters
        ----------
        edit : TangentEdit
            The joint, channel, key frame and slope.

        Returns
        -------
        EditReport
            What the edit changed.
        """
        if self.interp == "linear":
            raise ParameterError("interp", self.interp, "hermite or hermite-fit (linear keys: no handles)")
        if not (math.isfinite(edit.slope) and abs(edit.slope) <= MAX_VALUE):
            raise ParameterError("slope", edit.slope, "a finite slope per frame")
        c = self.column(edit.joint, edit.channel)
        ch, a = self._knot(c, edit.frame, edit.channel)
        _, s_out = self.key_slopes(c)
        change = {int(ch.knots[a]): float(edit.slope - s_out[a])}
        step = _Step(None, {}, slopes={c: change})
        self._history.append(step)
        step.report = self._report(edit, edit.joint, "handle", c, edit.frame)
        return step.report

    def apply_retime(self, edit: ChannelRetimeEdit) -> EditReport:
        """Move one channel's key in time, strictly between that channel's neighbouring keys (the
        first and last frame stay keys); ParameterError otherwise.

        Parameters
        ----------
        edit : ChannelRetimeEdit
            The joint, channel, key frame and where it goes.

        Returns
        -------
        EditReport
            What the edit changed.
        """
        c = self.column(edit.joint, edit.channel)
        ch, a = self._knot(c, edit.frame, edit.channel)
        check_retime(ch.all_keys, self.original.n_frames, edit.frame, edit.to)  # never past a key
        step = _Step(None, {}, moves={c: {int(ch.knots[a]): int(edit.to)}})
        self._history.append(step)
        step.report = self._report(edit, edit.joint, "retime", c, edit.to)
        return step.report

    def apply(self, edit: PoseEdit, method: str = "auto") -> EditReport:
        """Move ``edit.joint`` to its target at ``edit.frame`` (a key of some channel or a pose
        key, :attr:`pose_frames`) by IK on the pose shown there; each channel the solve turns
        has its key there moved, or one added (module docstring).

        Parameters
        ----------
        edit : PoseEdit
            The joint, frame, target and chain.
        method : str, default "auto"
            The IK solver.

        Returns
        -------
        EditReport
            What the edit changed.
        """
        m = self.original
        frames = self.pose_frames
        if edit.frame not in frames:
            listed = " ".join(map(str, frames.tolist()))
            what = "a key of some channel or a pose key" if self.pose_keys.size else "a key of some channel"
            raise ParameterError("frame", edit.frame, f"{what}: {listed}")
        if edit.joint not in m.joint_names:
            raise ParameterError("joint", edit.joint, "a joint of the skeleton")
        e = m.joint_names.index(edit.joint)
        current = self.pose(edit.frame)
        s = ik.solve(m, current, e, edit.chain, edit.target, ik.TOLERANCE * self.height, method)
        turned = ik.ancestors(m, e, edit.chain)
        # A channel's key at the frame moves by what the IK changed; where the frame was not one
        # of its keys it becomes one, holding the value the edits before gave it there too. In a
        # stretch a moved key retimed, the frame shows a fractional frame of the capture, so no
        # captured key can be put there: the key is added on top ("late"), its change spread to
        # its neighbouring keys by the curve's basis with flat tangents, so the curve there keeps
        # its slope and the stretch keeps its retimed detail.
        moves: dict[int, dict[int, float]] = {}
        late: dict[int, dict[int, float]] = {}
        f = edit.frame
        for c in np.flatnonzero(s.values != current).tolist():
            ch = self._channel(c)
            hit = np.flatnonzero(ch.keys == f)
            delta = float(s.values[c] - current[c])
            if hit.size:
                moves[c] = {int(ch.knots[hit[0]]): delta}
            elif f in self._warped(ch):
                there = float(self._late(ch, np.array([f]))[0]) if ch.late else 0.0
                late[c] = {f: there + delta}
            else:
                moves[c] = {f: float(s.values[c] - m.values[f, c])}
        names = [m.joint_names[j] for j in turned]
        report = EditReport(edit, names, s.method, s.iterations, s.miss, s.miss / self.height, f, f)
        step = _Step(report, moves, late=late)
        self._history.append(step)
        if moves or late:
            spans = [self._span(c, edit.frame) for c in (*moves, *late)]
            report.first = min(a for a, _ in spans)
            report.last = max(b for _, b in spans) - 1
        return step.report

    def apply_all(self, edits: list, method: str = "auto") -> list[EditReport]:
        """Edits in order, each on what the ones before left (:func:`.pose_edit.apply_edits`).

        Parameters
        ----------
        edits : list
            Pose and per-channel edits.
        method : str, default "auto"
            The IK solver.

        Returns
        -------
        list of EditReport
            One per edit.
        """
        return apply_edits(self, edits, method)

    def undo(self) -> object | None:
        return self._history.pop().report.edit if self._history else None

    def reset(self) -> None:
        self._history.clear()

    def motion(self) -> Motion:
        """The edited capture: each edited channel changed only between the neighbouring keys
        of its edited keys (elsewhere the capture itself)."""
        m = self.original
        values = m.values.copy()
        for c in sorted(self._touched()):
            ch = self._channel(c)
            edited = [f for s in self._history for part in (s.changes, s.slopes) for f in part.get(c, {})]
            spans = [np.arange(*self._span(c, int(ch.keys[np.searchsorted(ch.knots, f)]))) for f in edited]
            frames = np.unique(np.concatenate([self._warped(ch), *spans])).astype(np.int64)
            if frames.size:
                values[frames, c] = self._values(c, ch, frames)
        return m.with_values(values)
