"""Key poses of a capture edited by inverse kinematics, the change carried to every frame while
the captured detail stays (seed 003 §5, Fig. 9).

Each joint's rotation is a key curve through its key poses (slerp for "linear", the cubic
Hermite of seed 003 on hemisphere-aligned quaternion components for "hermite", fitted handles
for "hermite-fit": the curves of :func:`hairtool.mocap.costs.reconstruct_motion`) plus the
residual of every frame against it. An edit drags one joint at a key frame to a target; the IK
(:mod:`hairtool.mocap.ik`) turns its nearest ancestors; the key curve is rebuilt with the new
key pose and the residual added back:

    q_f' = normalize(q_f + ĉ_new(f) − ĉ_old(f))     (= ĉ_new(f) + residual_f)

which is exact where nothing moved: a key's curve changes only strictly between its
neighbouring keys, so every other frame keeps the capture's values bit for bit, and so does
every joint no edit turned. The Hermite tangents stay those of the captured samples (seed 003),
so the change fades from the key to zero at its neighbours. Joints with one or two rotation
channels are edited on their angles directly. New angles are written in the joint's channel
order, each frame nearest the previous one moved as the capture moves there, so they stay
continuous with the unchanged frames on both sides (no 360° turns, no jumps to the other Euler
family); only where the edited turn winds through gimbal lock do the first and third angles
jump together, once, at the frame nearest the lock (:meth:`PoseEditor._track`).
"""

from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import FormatError, ParameterError
from hairtool.io import user_text
from hairtool.keys.edit import check_retime, residual_at, time_warp
from hairtool.keys.reconstruct import KeyPoses, check_keys, interpolate_at, key_poses
from hairtool.mocap import ik
from hairtool.mocap import quaternion as quat
from hairtool.mocap.bvh import MAX_VALUE, Motion

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

INTERPS = ("linear", "hermite", "hermite-fit")
FIELDS = ("frame", "joint", "target", "chain")
CHANNEL_FIELDS = ("frame", "joint", "channel", "value")
RETIME_FIELDS = ("frame", "to")
TANGENT_FIELDS = ("frame", "joint", "channel", "slope")


@dataclass(frozen=True)
class PoseEdit:
    """Move ``joint`` to the world point ``target`` at key ``frame`` by turning its ``chain``
    nearest ancestors (2: upper and lower limb, solved analytically)."""

    frame: int
    joint: str
    target: tuple[float, float, float]
    chain: int

    def to_dict(self) -> dict:
        return {"frame": self.frame, "joint": self.joint, "target": list(self.target), "chain": self.chain}


@dataclass(frozen=True)
class ChannelEdit:
    """Set one rotation channel of the key pose at key ``frame`` to ``value`` (degrees): a key
    dragged in value in a graph editor, carried to the frames around it like an IK edit."""

    frame: int
    joint: str
    channel: str
    value: float

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class TangentEdit:
    """Set the slope (degrees per frame) that one rotation channel's key curve enters and leaves
    the key at ``frame`` with: a Hermite handle dragged in a graph editor (both handles of the
    key aligned on it), carried to the frames between the neighbouring keys like any edit."""

    frame: int
    joint: str
    channel: str
    slope: float

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class RetimeEdit:
    """Move the key at ``frame`` to the frame ``to`` (strictly between its neighbouring keys):
    a key dragged in time in a graph editor. The key pose keeps its values and handles, the key
    curve takes the new knot and the frames between the neighbours show the capture's residuals
    retimed with it (:func:`hairtool.keys.edit.retime_key`); later edits of that key name ``to``."""

    frame: int
    to: int

    def to_dict(self) -> dict:
        return asdict(self)


Edit = PoseEdit | ChannelEdit | TangentEdit | RetimeEdit


@dataclass
class EditReport:
    """What one edit did: the joints it turned, the solver, how far the effector is from the
    target (scene units and share of the figure's height; more than ``tolerance_share``: out of
    reach) and the frames it changed (``first``..``last``, strictly between the neighbouring keys)."""

    edit: Edit
    turned: list[str]
    method: str
    iterations: int
    miss: float
    miss_share: float
    first: int
    last: int
    tolerance_share: float = ik.TOLERANCE

    def to_dict(self) -> dict:
        d = asdict(self)
        d["edit"] = self.edit.to_dict()
        return d


def _is_int(v: object) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_number(v: object) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _finite(v: float) -> bool:
    try:
        return math.isfinite(v)
    except OverflowError:  # a JSON integer of hundreds of digits
        return False


def parse_edits(data: object, motion: Motion, source: str = "edits") -> list[PoseEdit]:
    """Edits from JSON data (a list of objects, or ``{"edits": [...]}``), checked against the
    skeleton: known joint, three finite numbers, a chain of 1 up to the joint's ancestors with
    rotation channels to turn. Key frames are checked by :meth:`PoseEditor.apply`. Any fault
    raises :class:`FormatError` naming ``source`` and the edit (counted from 1).

    Parameters
    ----------
    data : object
        The parsed JSON.
    motion : Motion
        The capture.
    source : str, default "edits"
        The file, named in a refusal.

    Returns
    -------
    list of PoseEdit
        The edits.
    """
    if isinstance(data, dict) and set(data) == {"edits"}:
        data = data["edits"]
    if not isinstance(data, list):
        raise FormatError(source, 'expected a list of edits {"frame", "joint", "target", "chain"}')
    names = {n: j for j, n in enumerate(motion.joint_names)}
    depths = motion.depths()
    out = []
    for i, e in enumerate(data, 1):
        where = f"edit {i}"
        if not isinstance(e, dict):
            raise FormatError(source, f"{where} is not an object with the fields {', '.join(FIELDS)}")
        missing = [k for k in FIELDS if k not in e]
        extra = sorted(str(k)[:40] for k in e if k not in FIELDS)
        if missing or extra:
            what = f"lacks {', '.join(missing)}" if missing else f"has unknown fields {', '.join(extra)}"
            raise FormatError(source, f"{where} {what} (fields: {', '.join(FIELDS)})")
        frame, joint, target, chain = (e[k] for k in FIELDS)
        if not _is_int(frame) or not 0 <= frame < motion.n_frames:
            last = motion.n_frames - 1
            raise FormatError(source, f"{where}: frame {frame!r} is not a frame number 0..{last}")
        if not isinstance(joint, str) or joint not in names:
            shown = ", ".join(motion.joint_names[:8]) + (", …" if motion.n_joints > 8 else "")
            raise FormatError(source, f"{where}: joint {str(joint)[:60]!r} is not in the skeleton ({shown})")
        if not (isinstance(target, list) and len(target) == 3 and all(_is_number(v) for v in target)):
            raise FormatError(source, f"{where}: target {str(target)[:60]} is not [x, y, z] (3 numbers)")
        if not all(_finite(v) for v in target):
            raise FormatError(source, f"{where}: target {target} is not finite")
        if any(abs(v) > MAX_VALUE for v in target):
            raise FormatError(source, f"{where}: target {target} is beyond ±{MAX_VALUE:.2g} (no capture is)")
        j = names[joint]
        if not _is_int(chain) or not 1 <= chain <= depths[j]:
            why = f"is not a whole number 1..{depths[j]} (the ancestors of '{joint}')"
            raise FormatError(source, f"{where}: chain {chain!r} {why}")
        turned = ik.ancestors(motion, j, chain)
        if not any(ik.rotation_columns(motion, a)[0] for a in turned):
            raise FormatError(source, f"{where}: the chain above '{joint}' has no rotation channels to turn")
        out.append(PoseEdit(int(frame), joint, tuple(float(v) for v in target), int(chain)))
    return out


def parse_edit_list(data: object, motion: Motion, source: str = "edits") -> list[Edit]:
    """Pose edits (:func:`parse_edits`), channel edits ``{"frame", "joint", "channel", "value"}``,
    handle edits ``{"frame", "joint", "channel", "slope"}`` and key moves ``{"frame", "to"}`` in
    one list, in order (what a
    studio project keeps); faults raise :class:`FormatError` naming ``source`` and the edit
    (counted from 1).

    Parameters
    ----------
    data : object
        The parsed JSON.
    motion : Motion
        The capture.
    source : str, default "edits"
        The file, named in a refusal.

    Returns
    -------
    list of Edit
        The edits, in order.
    """
    if isinstance(data, dict) and set(data) == {"edits"}:
        data = data["edits"]
    if not isinstance(data, list):
        raise FormatError(source, "expected a list of edits")
    out: list[Edit] = []
    for i, e in enumerate(data, 1):
        if isinstance(e, dict) and "to" in e and "joint" not in e:
            out.append(_parse_retime(e, motion, source, i))
            continue
        if not (isinstance(e, dict) and "channel" in e):
            try:
                out += parse_edits([e], motion, source)
            except FormatError as err:
                raise FormatError(source, err.reason.replace("edit 1", f"edit {i}", 1)) from None
            continue
        fields = TANGENT_FIELDS if "slope" in e else CHANNEL_FIELDS
        missing = [k for k in fields if k not in e]
        extra = sorted(str(k)[:40] for k in e if k not in fields)
        if missing or extra:
            what = f"lacks {', '.join(missing)}" if missing else f"has unknown fields {', '.join(extra)}"
            raise FormatError(source, f"edit {i} {what} (fields: {', '.join(fields)})")
        frame, joint, channel, value = (e[k] for k in fields)
        if not _is_int(frame) or not 0 <= frame < motion.n_frames:
            raise FormatError(
                source, f"edit {i}: frame {frame!r} is not a frame number 0..{motion.n_frames - 1}"
            )
        if not isinstance(joint, str) or joint not in motion.joint_names:
            raise FormatError(source, f"edit {i}: joint {str(joint)[:60]!r} is not in the skeleton")
        j = motion.joint_names.index(joint)
        rotations = [c for c in motion.channels[j] if c.endswith("rotation")]
        if channel not in rotations:
            raise FormatError(
                source, f"edit {i}: '{str(channel)[:40]}' is not a rotation channel of '{joint}'"
            )
        if not _is_number(value) or not _finite(value) or abs(value) > MAX_VALUE:
            raise FormatError(source, f"edit {i}: {fields[3]} {str(value)[:40]} is not a finite number")
        kind = TangentEdit if fields is TANGENT_FIELDS else ChannelEdit
        out.append(kind(int(frame), joint, channel, float(value)))
    return out


def _parse_retime(e: dict, motion: Motion, source: str, i: int) -> RetimeEdit:
    extra = sorted(str(k)[:40] for k in e if k not in RETIME_FIELDS)
    if "frame" not in e or extra:
        what = "lacks frame" if "frame" not in e else f"has unknown fields {', '.join(extra)}"
        raise FormatError(source, f"edit {i} {what} (fields: {', '.join(RETIME_FIELDS)})")
    for name in RETIME_FIELDS:
        v = e[name]
        if not _is_int(v) or not 0 <= v < motion.n_frames:
            last = motion.n_frames - 1
            raise FormatError(source, f"edit {i}: {name} {str(v)[:40]} is not a frame number 0..{last}")
    return RetimeEdit(int(e["frame"]), int(e["to"]))


def read_edits(path: str | os.PathLike[str], motion: Motion) -> list[PoseEdit]:
    """:func:`parse_edits` of a JSON file; unreadable or invalid JSON raises :class:`FormatError`.

    Parameters
    ----------
    path : str or os.PathLike
        The edit file (JSON).
    motion : Motion
        The capture whose joints the edits name.

    Returns
    -------
    list of PoseEdit
        The edits, in the file's order.
    """
    return parse_edits(read_json(path), motion, os.fspath(path))


def read_json(path: str | os.PathLike[str]) -> object:
    """A JSON file's data; unreadable or invalid JSON raises :class:`FormatError` naming it.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    object
        Its data.
    """
    # every user text limit, as jobs files get; a project's capture section (an edit file
    # too) carries the capture's BVH text whole
    return user_text.read(path, "an edit file", "json", texts=frozenset({"bvh"}))


def apply_edits(editor, edits: list, method: str = "auto") -> list[EditReport]:
    """Edits in order on ``editor`` (a :class:`PoseEditor` or a
    :class:`~hairtool.mocap.channel_edit.ChannelEditor`), each on what the ones before left: a
    key's value (``apply_channel``), its handle (``apply_tangent``), a key moved in time of the
    kind that editor keys (``editor.RETIME``: the pose key, or one channel's key;
    ``apply_retime``), an IK pose edit (``apply``). Another kind raises
    :class:`ParameterError` naming it, so no edit is read as another.

    Parameters
    ----------
    editor : PoseEditor or ChannelEditor
        The editor.
    edits : list
        The edits.
    method : str, default "auto"
        The IK solver.

    Returns
    -------
    list of EditReport
        One per edit.
    """
    out = []
    for e in edits:
        if isinstance(e, ChannelEdit):
            out.append(editor.apply_channel(e))
        elif isinstance(e, TangentEdit):
            out.append(editor.apply_tangent(e))
        elif isinstance(e, editor.RETIME):
            out.append(editor.apply_retime(e))
        elif isinstance(e, PoseEdit):
            out.append(editor.apply(e, method))
        else:
            shown = e.to_dict() if hasattr(e, "to_dict") else repr(e)[:80]
            raise ParameterError("edit", shown, editor.KINDS)
    return out


class PoseEditor:
    """A capture, its keys, and its key poses as edited so far; the original is kept, so
    edits undo (:meth:`undo`, :meth:`reset`) and compose (each solve starts from the edited pose)."""

    RETIME = RetimeEdit  # the key moves it makes: the pose key, every channel
    KINDS = "an edit of the pose keys: an IK pose, a key's value, its handle or its move in time"

    def __init__(self, motion: Motion, keys: ArrayLike, interp: str = "linear") -> None:
        """Take the key curve and the residuals out of ``motion``.

        Parameters
        ----------
        motion : Motion
            The capture.
        keys : array_like
            Its key frames, ascending, first and last frame included.
        interp : {"linear", "hermite", "hermite-fit"}, default "linear"
            The key curve.
        """
        if interp not in INTERPS:
            raise ParameterError("interp", interp, " or ".join(INTERPS))
        self.original = motion
        self.interp = interp
        # the keys the residuals are measured against (the solved ones) and the keys as edited
        # (a key moved in time, RetimeEdit): the same until a key moves
        self._keys0: I64 = check_keys(keys, motion.n_frames)
        self.keys: I64 = self._keys0.copy()
        self.height = ik.figure_height(motion)
        self._q = quat.align_hemisphere(motion.local_rotations(), axis=0)
        self._base_values = motion.values[self._keys0].copy()
        self._key_values = self._base_values.copy()
        self._key_q = self._q[self._keys0].copy()
        # report, key index, its values and quaternions before, for a handle edit the joint and
        # its tangents before (None: the captured ones), for a key move the keys before
        self._history: list[tuple[EditReport, int, F64, F64, tuple | None, I64 | None]] = []
        self._curves: dict[int, KeyPoses] = {}
        self._angle_curves: dict[int, KeyPoses] = {}
        self._other_curve: KeyPoses | None = None  # the channels no joint turns (positions)
        self._tangents: dict[int, tuple[F64, F64]] = {}  # joint → edited (out, in) tangents (K, D)

    # -- keys ------------------------------------------------------------------------------
    def key_index(self, frame: int) -> int:
        """The index of a key frame among the keys.

        Parameters
        ----------
        frame : int
            A frame that is a key (ParameterError naming the keys otherwise).

        Returns
        -------
        int
            Its index in :attr:`keys`.
        """
        hit = np.flatnonzero(self.keys == frame)
        if hit.size == 0:
            raise ParameterError("frame", frame, f"a key frame: {' '.join(map(str, self.keys.tolist()))}")
        return int(hit[0])

    def key_pose(self, frame: int) -> F64:
        """``(C,)`` channel values of the edited pose at a key frame.

        Parameters
        ----------
        frame : int
            A key frame.

        Returns
        -------
        ndarray
            ``(C,)`` float64, a copy.
        """
        return self._key_values[self.key_index(frame)].copy()

    def span(self, frame: int) -> tuple[int, int]:
        """``(first, last)``: the frames an edit at this key changes (strictly between its neighbours).

        Parameters
        ----------
        frame : int
            A key frame.

        Returns
        -------
        tuple of (int, int)
            The first and last frame changed.
        """
        a = self.key_index(frame)
        first = int(self.keys[a - 1]) + 1 if a > 0 else 0
        last = int(self.keys[a + 1]) - 1 if a < self.keys.size - 1 else self.original.n_frames - 1
        return first, last

    @property
    def reports(self) -> list[EditReport]:
        return [r for r, *_ in self._history]

    # -- editing ---------------------------------------------------------------------------
    def apply(self, edit: PoseEdit, method: str = "auto") -> EditReport:
        """Solve one edit on the current pose at its key and keep the new key pose.

        Parameters
        ----------
        edit : PoseEdit
            The joint, key frame, target and chain.
        method : {"auto", "two-bone", "dls"}, default "auto"
            The solver (:func:`hairtool.mocap.ik.solve`): "auto" is two-bone where the chain
            is 2, else damped least squares.

        Returns
        -------
        EditReport
            The joints turned, the solver, the miss and the frames changed.
        """
        m = self.original
        if edit.joint not in m.joint_names:
            raise ParameterError("joint", edit.joint, "a joint of the skeleton")
        a = self.key_index(edit.frame)
        e = m.joint_names.index(edit.joint)
        values = self._key_values[a]
        s = ik.solve(m, values, e, edit.chain, edit.target, ik.TOLERANCE * self.height, method)
        turned = ik.ancestors(m, e, edit.chain)
        saved = (a, self._key_values[a].copy(), self._key_q[a].copy())
        self._key_values[a] = s.values
        for j in turned:
            cols, order = ik.rotation_columns(m, j)
            if ik.is_ball_joint(m, j):
                q = quat.from_euler(s.values[cols], order)
                ref = self._q[self._keys0[a], j]
                self._key_q[a, j] = -q if np.dot(q, ref) < 0 else q
        first, last = self.span(edit.frame)
        names = [m.joint_names[j] for j in turned]
        report = EditReport(edit, names, s.method, s.iterations, s.miss, s.miss / self.height, first, last)
        self._history.append((report, *saved, None, None))
        return report

    def apply_channel(self, edit: ChannelEdit) -> EditReport:
        """Set one rotation channel of a key pose (a key dragged in value): the key curve through
        the new pose plus the residuals, as for an IK edit. A ball joint's key quaternion is made
        from its three angles at the key, so the other two keep their values there.

        Parameters
        ----------
        edit : ChannelEdit
            The joint, key frame, channel and new value (degrees).

        Returns
        -------
        EditReport
            What the edit changed.
        """
        m = self.original
        j, cols, order, i = self._channel(edit)
        if not (math.isfinite(edit.value) and abs(edit.value) <= MAX_VALUE):
            raise ParameterError("value", edit.value, "a finite angle in degrees")
        a = self.key_index(edit.frame)
        saved = (a, self._key_values[a].copy(), self._key_q[a].copy())
        self._key_values[a, cols[i]] = float(edit.value)
        if ik.is_ball_joint(m, j):
            q = quat.from_euler(self._key_values[a, cols], order)
            ref = self._q[self._keys0[a], j]
            self._key_q[a, j] = -q if np.dot(q, ref) < 0 else q
        first, last = self.span(edit.frame)
        report = EditReport(edit, [edit.joint], "channel", 0, 0.0, 0.0, first, last)
        self._history.append((report, *saved, None, None))
        return report

    def apply_retime(self, edit: RetimeEdit) -> EditReport:
        """Move a key in time (a key dragged sideways): the key keeps its pose and handles, the
        frames between its neighbouring keys follow with the residuals retimed
        (:func:`hairtool.keys.edit.retime_key`, every channel of the pose, positions too, as
        pose keys are shared); ParameterError for an end key or a frame not strictly between
        the neighbours.

        Parameters
        ----------
        edit : RetimeEdit
            The key frame and where it goes.

        Returns
        -------
        EditReport
            What the edit changed.
        """
        a, after = check_retime(self.keys, self.original.n_frames, edit.frame, edit.to)
        saved = (a, self._key_values[a].copy(), self._key_q[a].copy())
        before, self.keys = self.keys, after
        first, last = self.span(edit.to)
        report = EditReport(edit, [], "retime", 0, 0.0, 0.0, first, last)
        self._history.append((report, *saved, None, before))
        return report

    def _channel(self, edit: ChannelEdit | TangentEdit) -> tuple[int, list[int], str, int]:
        """The joint, its rotation columns and order, and the edited channel's place among them."""
        m = self.original
        if edit.joint not in m.joint_names:
            raise ParameterError("joint", edit.joint, "a joint of the skeleton")
        j = m.joint_names.index(edit.joint)
        cols, order = ik.rotation_columns(m, j)
        names = [m.channels[j][c - int(m._starts[j])] for c in cols]
        if edit.channel not in names:
            raise ParameterError(
                "channel", edit.channel, f"a rotation channel of '{edit.joint}': {', '.join(names)}"
            )
        return j, cols, order, names.index(edit.channel)

    def apply_tangent(self, edit: TangentEdit) -> EditReport:
        """Set one rotation channel's slope at a key (a Hermite handle dragged; both handles of
        the key take it). A ball joint's curve is on quaternions: its tangent there moves along
        the quaternion's derivative with respect to that angle, J_c = ∂q/∂θ_c, by what the slope
        lacks (J⁺ t is the three angles' slope, so the other two keep theirs). Linear keys have
        no handles (ParameterError).

        Parameters
        ----------
        edit : TangentEdit
            The joint, key frame, channel and slope (degrees per frame).

        Returns
        -------
        EditReport
            What the edit changed.
        """
        if self.interp == "linear":
            raise ParameterError(
                "interp", self.interp, "hermite or hermite-fit (linear keys have no handles)"
            )
        m = self.original
        j, cols, order, i = self._channel(edit)
        if not (math.isfinite(edit.slope) and abs(edit.slope) <= MAX_VALUE):
            raise ParameterError("slope", edit.slope, "a finite slope in degrees per frame")
        a = self.key_index(edit.frame)
        before = self._tangents.get(j)
        out, inn = (t.copy() for t in self._current_tangents(j))
        if ik.is_ball_joint(m, j):
            jac = self._euler_jacobian(a, j, cols, order)
            for t in (out, inn):
                now = np.linalg.lstsq(jac, t[a], rcond=None)[0]
                t[a] = t[a] + jac[:, i] * (float(edit.slope) - now[i])
        else:
            out[a, i] = inn[a, i] = float(edit.slope)
        self._tangents[j] = (out, inn)
        first, last = self.span(edit.frame)
        report = EditReport(edit, [edit.joint], "handle", 0, 0.0, 0.0, first, last)
        self._history.append(
            (report, a, self._key_values[a].copy(), self._key_q[a].copy(), (j, before), None)
        )
        return report

    def key_slopes(self, joint: int) -> tuple[F64, F64] | None:
        """``(in, out)``, each ``(K, n)``: the slopes (degrees per frame) a joint's key curve
        enters and leaves each key with, its rotation channels in channel order; None for
        linear keys (no handles).

        Parameters
        ----------
        joint : int
            The joint's index.

        Returns
        -------
        tuple of (ndarray, ndarray) or None
            The slopes in and out, or None where the joint has no rotation channels.
        """
        if self.interp == "linear":
            return None
        m = self.original
        cols, order = ik.rotation_columns(m, joint)
        out, inn = self._current_tangents(joint)
        if not ik.is_ball_joint(m, joint):
            return inn.copy(), out.copy()
        s_in, s_out = np.empty((self.keys.size, 3)), np.empty((self.keys.size, 3))
        for a in range(self.keys.size):
            jac = self._euler_jacobian(a, joint, cols, order)
            s_in[a] = np.linalg.lstsq(jac, inn[a], rcond=None)[0]
            s_out[a] = np.linalg.lstsq(jac, out[a], rcond=None)[0]
        return s_in, s_out

    def _euler_jacobian(self, a: int, j: int, cols: list[int], order: str) -> F64:
        """``(4, 3)`` ∂q/∂θ (per degree) of a ball joint's key quaternion at key index a."""
        e = self._key_values[a, cols]
        sign = 1.0 if np.dot(quat.from_euler(e, order), self._key_q[a, j]) >= 0 else -1.0
        h = 1e-3
        steps = np.eye(3) * h
        plus = quat.from_euler(e + steps, order)
        minus = quat.from_euler(e - steps, order)
        return sign * (plus - minus).T / (2 * h)

    def _base_tangents(self, j: int) -> tuple[F64, F64]:
        """A joint's captured key tangents ``(out, in)``: of its quaternions (ball joints) or its
        angles (hinges)."""
        if ik.is_ball_joint(self.original, j):
            kp = self._kp(j)
        else:
            kp = self._angle_kp(j)
        return kp.tangents, kp.tangents if kp.tangents_in is None else kp.tangents_in

    def _angle_kp(self, j: int) -> KeyPoses:
        """A hinge joint's key curve on its captured angles at the solved keys."""
        if j not in self._angle_curves:
            cols, _ = ik.rotation_columns(self.original, j)
            self._angle_curves[j] = key_poses(self.original.values[:, cols], self._keys0, self.interp)
        return self._angle_curves[j]

    def _current_tangents(self, j: int) -> tuple[F64, F64]:
        return self._tangents[j] if j in self._tangents else self._base_tangents(j)

    def _tangent_rows(self, j: int) -> I64:
        """Key indices whose tangents a handle edit changed for joint j."""
        if j not in self._tangents:
            return np.zeros(0, dtype=np.int64)
        (out, inn), (b_out, b_in) = self._tangents[j], self._base_tangents(j)
        return np.flatnonzero(np.any(out != b_out, axis=1) | np.any(inn != b_in, axis=1))

    def apply_all(self, edits: list[Edit], method: str = "auto") -> list[EditReport]:
        """Edits in order, each on the pose the ones before it left (:func:`apply_edits`).

        Parameters
        ----------
        edits : list of Edit
            Pose, channel, tangent and retime edits.
        method : str, default "auto"
            The IK solver for pose edits (see :meth:`apply`).

        Returns
        -------
        list of EditReport
            One per edit.
        """
        return apply_edits(self, edits, method)

    def undo(self) -> Edit | None:
        """Take back the last edit (None when there is none)."""
        if not self._history:
            return None
        report, a, values, q, tangents, keys = self._history.pop()
        self._key_values[a], self._key_q[a] = values, q
        if keys is not None:
            self.keys = keys
        if tangents is not None:
            j, before = tangents
            if before is None:
                self._tangents.pop(j, None)
            else:
                self._tangents[j] = before
        return report.edit

    def reset(self) -> None:
        while self._history:
            self.undo()

    # -- the edited capture ----------------------------------------------------------------
    def _kp(self, j: int) -> KeyPoses:
        """A ball joint's key curve on its captured quaternions (tangents kept through edits)."""
        if j not in self._curves:
            kind = "linear" if self.interp == "linear" else self.interp
            self._curves[j] = key_poses(self._q[:, j], self._keys0, kind)
        return self._curves[j]

    def _curve(
        self,
        j: int,
        poses: F64,
        frames: I64,
        tangents: tuple[F64, F64] | None = None,
        knots: I64 | None = None,
    ) -> F64:
        """``(len(frames), 4)`` joint j's key curve through the key quaternions ``poses`` at the
        key frames ``knots`` (default the keys as edited), with the ``(out, in)`` tangents
        given, else the captured ones."""
        knots = self.keys if knots is None else knots
        if self.interp == "linear":  # slerp, as reconstruct_motion rebuilds it
            k = knots
            a = np.clip(np.searchsorted(k, frames, side="right") - 1, 0, k.size - 2)
            s = (frames - k[a]) / (k[a + 1] - k[a]).astype(np.float64)
            return quat.slerp(poses[a], poses[a + 1], s)
        kp = self._kp(j)
        if tangents is not None:
            edited = KeyPoses(knots, poses, tangents[0], kp.n_frames, kp.interp, tangents[1])
        else:
            edited = KeyPoses(knots, poses, kp.tangents, kp.n_frames, kp.interp, kp.tangents_in)
        return interpolate_at(edited, frames)

    def motion(self) -> Motion:
        """The edited capture at every frame: the edited key curves plus the stored residuals
        (retimed between the neighbours of a key moved in time)."""
        m = self.original
        values = m.values.copy()
        changed = np.any(self._key_values != self._base_values, axis=0)  # (C,) columns any edit moved
        warped = self._warped_frames()
        for j in range(m.n_joints):
            cols, order = ik.rotation_columns(m, j)
            handles = self._tangent_rows(j) if cols else np.zeros(0, dtype=np.int64)
            if not cols or not (np.any(changed[cols]) or handles.size or warped.size):
                continue
            rows = np.flatnonzero(np.any(self._key_values[:, cols] != self._base_values[:, cols], axis=1))
            rows = np.union1d(rows, handles)
            tangents = self._tangents.get(j) if handles.size else None
            spans = [np.arange(*self._span_of(a)) for a in rows]
            frames = np.unique(np.concatenate([warped, *spans]))
            moved = np.isin(frames, warped)
            still = frames[~moved]
            ball = ik.is_ball_joint(m, j)
            # Frames whose segment kept its keys: the edit's spread is the key's change of angles
            # weighted by the curve's basis (the tangents are the same before and after, so they
            # cancel). Frames in a segment a moved key stretched: the curve plus the residual of
            # the frame they now show.
            if ball:
                base = self._q[self._keys0, j]
                q = np.empty((frames.size, 4))
                if still.size:
                    delta = self._curve(j, self._key_q[:, j], still, tangents) - self._curve(j, base, still)
                    q[~moved] = self._q[still, j] + delta
                if moved.any():
                    q[moved] = self._curve(j, self._key_q[:, j], frames[moved], self._tangents.get(j))
                    q[moved] += residual_at(
                        self._q[:, j],
                        lambda i, j=j, base=base: self._curve(j, base, i, knots=self._keys0),
                        time_warp(frames[moved], self.keys, self._keys0),
                    )
                q = quat.normalize(q)
                for run in np.split(np.arange(frames.size), np.flatnonzero(np.diff(frames) > 1) + 1):
                    values[np.ix_(frames[run], cols)] = self._track(frames[run], cols, order, q[run])
            else:
                if still.size:
                    change = self._key_values[:, cols] - self._base_values[:, cols]
                    if tangents is not None:
                        (out, inn), (b_out, b_in) = tangents, self._base_tangents(j)
                        spread = self._spread(change, still, (out - b_out, inn - b_in))
                    else:
                        spread = self._spread(change, still)
                    values[np.ix_(still, cols)] = m.values[np.ix_(still, cols)] + spread
                if moved.any():
                    out, inn = self._current_tangents(j)
                    kp = self._angle_kp(j)
                    edited = KeyPoses(self.keys, self._key_values[:, cols], out, kp.n_frames, kp.interp, inn)
                    retimed = self._retimed(m.values[:, cols], kp, edited, frames[moved])
                    values[np.ix_(frames[moved], cols)] = retimed
        if warped.size:  # the channels no joint turns (the root's position) move in time too
            others = self._other_columns()
            if others:
                kp = self._others()
                edited = KeyPoses(self.keys, kp.poses, kp.tangents, kp.n_frames, kp.interp, kp.tangents_in)
                values[np.ix_(warped, others)] = self._retimed(m.values[:, others], kp, edited, warped)
        return m.with_values(values)

    def _retimed(self, x: F64, base: KeyPoses, edited: KeyPoses, frames: I64) -> F64:
        """Channels ``x`` at ``frames`` in a stretched segment: the edited key curve there plus
        the residual against the captured key curve ``base`` at the frame each now shows."""
        u = time_warp(frames, self.keys, self._keys0)
        return interpolate_at(edited, frames) + residual_at(x, lambda i: interpolate_at(base, i), u)

    def _warped_frames(self) -> I64:
        """Frames in a segment next to a key moved in time (the moved key's own frame included)."""
        moved = np.flatnonzero(self.keys != self._keys0)
        if moved.size == 0:
            return np.zeros(0, dtype=np.int64)
        k = self.keys
        return np.unique(np.concatenate([np.arange(k[a - 1] + 1, k[a + 1]) for a in moved]))

    def _other_columns(self) -> list[int]:
        m = self.original
        turned = {c for j in range(m.n_joints) for c in ik.rotation_columns(m, j)[0]}
        return [c for c in range(m.n_channels) if c not in turned]

    def _others(self) -> KeyPoses:
        if self._other_curve is None:
            x = self.original.values[:, self._other_columns()]
            self._other_curve = key_poses(x, self._keys0, self.interp)
        return self._other_curve

    def key_curve(self, joint: int, reference: F64 | None = None) -> F64:
        """``(F, n)`` a joint's rotation channels on its edited key curve alone (no residuals):
        the curve a graph editor draws through the keys. Angles are written nearest
        ``reference`` (``(F, n)``, default the edited capture's), so the two overlay.

        Parameters
        ----------
        joint : int
            The joint's index.
        reference : ndarray, optional
            ``(F, n)`` angles to write nearest (None: the edited capture's).

        Returns
        -------
        ndarray
            ``(F, n)`` float64 angles in degrees.
        """
        m = self.original
        cols, order = ik.rotation_columns(m, joint)
        frames = np.arange(m.n_frames)
        if reference is None:
            reference = self.motion().values[:, cols]
        if ik.is_ball_joint(m, joint):
            q = self._curve(joint, self._key_q[:, joint], frames, self._tangents.get(joint))
            return np.array([ik.euler_nearest(q[f], order, reference[f]) for f in frames]).reshape(
                -1, len(cols)
            )
        out, inn = self._current_tangents(joint)
        kp = self._angle_kp(joint)
        edited = KeyPoses(self.keys, self._key_values[:, cols], out, kp.n_frames, kp.interp, inn)
        return interpolate_at(edited, frames)

    def _span_of(self, a: int) -> tuple[int, int]:
        """``[start, stop)`` frames of key index ``a``'s span."""
        first, last = self.span(int(self.keys[a]))
        return first, last + 1

    def _spread(self, change: F64, frames: I64, tangents: tuple[F64, F64] | None = None) -> F64:
        """``(len(frames), D)`` key changes ``(K, D)`` carried to the frames by the curve's basis
        (the tangents are the same before and after an edit, so they cancel, unless a handle
        edit changed them by ``tangents`` = (Δout, Δin))."""
        if tangents is not None:
            kp = KeyPoses(self.keys, change, tangents[0], self.original.n_frames, "hermite", tangents[1])
            return interpolate_at(kp, frames)
        zero = None if self.interp == "linear" else np.zeros_like(change)
        kind = "linear" if self.interp == "linear" else "hermite"
        return interpolate_at(KeyPoses(self.keys, change, zero, self.original.n_frames, kind), frames)

    def _track(self, run: I64, cols: list[int], order: str, q: F64) -> F64:
        """Euler angles for the rotations ``q`` of a run of consecutive frames, continuous with the
        unchanged frames on both sides.

        Forward from the frame before the run, each frame is written nearest the previous one
        moved as the capture moves there (so the capture's own wraps stay where they are);
        backward the same from the frame after. The two agree unless the edited turn winds
        around gimbal lock (the middle angle through ±90°), which no continuous set of angles
        can undo by the run's end: then the run switches from the one to the other at the frame
        nearest the lock, where the two triples describe nearly the same turn."""
        orig = self.original.values[:, cols]
        n = self.original.n_frames
        first, last = int(run[0]), int(run[-1])

        def follow(frames: list[int], step: int) -> F64:
            out = np.empty((len(frames), len(cols)))
            prev = None
            anchor = frames[0] - step
            if 0 <= anchor < n:
                prev = orig[anchor]
            for i, f in enumerate(frames):
                ref = orig[f] if prev is None else prev + (orig[f] - orig[f - step])
                out[i] = prev = ik.euler_nearest(q[f - first], order, ref)
            return out

        forward = follow(list(range(first, last + 1)), 1)
        if last == n - 1:
            return forward
        backward = follow(list(range(last, first - 1, -1)), -1)[::-1]
        if first == 0 or np.allclose(forward, backward, rtol=0, atol=1e-6):
            return backward if first == 0 else forward
        i, _, k = ("XYZ".index(c) for c in order)
        lock = np.abs(quat.to_matrix(q)[:, i, k])  # |sin| of the middle angle
        split = int(np.argmax(lock))
        return np.concatenate([forward[:split], backward[split:]])
