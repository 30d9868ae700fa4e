"""Biovision BVH motion capture: reader, writer and forward kinematics.

A BVH file has a HIERARCHY (joints with an OFFSET from their parent, the CHANNELS they animate,
End Sites) and a MOTION block (one line of channel values per frame). Joints count ROOT and
JOINT entries only; End Sites are kept apart (``end_parents``, ``end_offsets``).

Conventions (the common ones, as Blender and most mocap tools read them):
- rotation channels are intrinsic and applied in the listed order: for "Zrotation Xrotation
  Yrotation" the local rotation is R = R_z · R_x · R_y, angles in degrees;
- position channels give the joint's position in its parent's frame and *replace* the OFFSET
  (components without a channel keep the offset's);
- world position of joint j: P_j = P_parent + R_parent_world · t_j, R_j_world = R_parent_world · R_j.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool import budget
from hairtool.errors import FormatError, ParameterError, quoted
from hairtool.io import user_text
from hairtool.io.atomic import atomic_open
from hairtool.mocap import quaternion as quat

F64 = NDArray[np.float64]

CHANNEL_NAMES = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")
#: Joints, and End Sites apart: forward kinematics walks the joints one by one in Python (0.1 to
#: 0.5 ms each a pass, by the frames), so 10,000 stay within seconds, where 100,000 took 22 s of
#: CPU; the largest production rigs, faces included, have a few thousand.
_MAX_JOINTS = 10_000
#: Bytes forward kinematics holds per pose (a joint or End Site in one frame): local and world
#: rotations and translations, the End Sites' gathered copies and the joined result, measured
#: at about 100 (joints) to 160 (End Sites) and rounded up; the budget bounds their total.
_POSE_BYTES = 200
_MAX_VALUES = 500_000_000  # frames × channels: refuse absurd headers before allocating
_MIN_POSES = 1_000_000  # frames × joints any file may have; beyond, at most one per byte of the file
_MIN_FRAME_TIME = 1e-6  # seconds; shorter would make the frame rate overflow (1 / 5e-324 is inf)
#: Offsets and channel values beyond float32's range are corruption: the key solver squares
#: differences of positions, which would overflow float64 from about 1.3e154 on.
MAX_VALUE = float(np.finfo(np.float32).max)


@dataclass
class Motion:
    """A skeleton and its channel values over frames.

    ``values`` is ``(F, C)`` float64 in file order: joint after joint, each joint's channels in
    ``channels[j]`` order; rotations in degrees.
    """

    joint_names: list[str]
    parents: NDArray[np.int64]
    offsets: F64
    channels: list[list[str]]
    values: F64
    frame_time: float
    end_parents: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    end_offsets: F64 = field(default_factory=lambda: np.zeros((0, 3)))

    def __post_init__(self) -> None:
        self.parents = np.asarray(self.parents, dtype=np.int64)
        self.offsets = np.asarray(self.offsets, dtype=np.float64).reshape(-1, 3)
        self.values = np.asarray(self.values, dtype=np.float64)
        self.end_parents = np.asarray(self.end_parents, dtype=np.int64)
        self.end_offsets = np.asarray(self.end_offsets, dtype=np.float64).reshape(-1, 3)
        j = len(self.joint_names)
        if j == 0 or self.parents.shape != (j,) or self.offsets.shape != (j, 3) or len(self.channels) != j:
            raise ParameterError("joints", j, "matching names, parents, offsets and channels")
        if self.parents[0] != -1 or np.any(self.parents[1:] < 0):
            raise ParameterError("parents", self.parents[:4], "−1 for the root (joint 0) only")
        if np.any(self.parents[1:] >= np.arange(1, j)):
            raise ParameterError("parents", self.parents, "each parent listed before its child")
        width = sum(len(c) for c in self.channels)
        if self.values.ndim != 2 or self.values.shape[1] != width:
            raise ParameterError("values", self.values.shape, f"(frames, {width})")
        if not (math.isfinite(self.frame_time) and self.frame_time > 0):
            raise ParameterError("frame_time", self.frame_time, "a positive number of seconds")
        starts = np.zeros(j + 1, dtype=np.int64)
        np.cumsum([len(c) for c in self.channels], out=starts[1:])
        self._starts = starts

    # -- sizes ---------------------------------------------------------------------------
    @property
    def n_frames(self) -> int:
        return int(self.values.shape[0])

    @property
    def n_joints(self) -> int:
        return len(self.joint_names)

    @property
    def n_channels(self) -> int:
        return int(self.values.shape[1])

    @property
    def fps(self) -> float:
        """1 / frame_time, snapped to a whole number within 0.02 % (files print 0.033333 for 30 fps)."""
        rate = 1.0 / self.frame_time
        whole = round(rate)
        return float(whole) if whole > 0 and abs(rate - whole) <= 2e-4 * rate else rate

    def __repr__(self) -> str:
        size = f"{self.n_joints} joints, {self.n_channels} channels"
        return f"Motion({size}, {self.n_frames} frames @ {self.fps:.4g})"

    def depths(self) -> NDArray[np.int64]:
        """``(J,)``: 0 for the root, 1 for its children, …"""
        d = np.zeros(self.n_joints, dtype=np.int64)
        for j in range(1, self.n_joints):
            d[j] = d[self.parents[j]] + 1
        return d

    def with_values(self, values: ArrayLike) -> Motion:
        """The same skeleton with new channel values (same frame time).

        Parameters
        ----------
        values : array_like
            ``(F, C)`` channel values, in the file's channel order.

        Returns
        -------
        Motion
            A motion sharing this one's joints, offsets and channels.
        """
        return Motion(
            list(self.joint_names),
            self.parents,
            self.offsets,
            [list(c) for c in self.channels],
            np.asarray(values, dtype=np.float64),
            self.frame_time,
            self.end_parents,
            self.end_offsets,
        )

    # -- channels → transforms -----------------------------------------------------------
    def _joint_values(self, j: int) -> F64:
        return self.values[:, self._starts[j] : self._starts[j + 1]]

    def local_rotations(self) -> F64:
        """``(F, J, 4)`` unit quaternions (w, x, y, z) of each joint relative to its parent."""
        q = quat.identity((self.n_frames, self.n_joints))
        for j, chans in enumerate(self.channels):
            cols = [k for k, c in enumerate(chans) if c.endswith("rotation")]
            if cols:
                order = "".join(chans[k][0] for k in cols)
                q[:, j] = quat.from_euler(self._joint_values(j)[:, cols], order)
        return q

    def local_translations(self) -> F64:
        """``(F, J, 3)``: each joint's position in its parent's frame (offset, or position channels)."""
        t = np.broadcast_to(self.offsets, (self.n_frames, self.n_joints, 3)).copy()
        for j, chans in enumerate(self.channels):
            for k, c in enumerate(chans):
                if c.endswith("position"):
                    t[:, j, "XYZ".index(c[0])] = self._joint_values(j)[:, k]
        return t

    def root_translation(self) -> F64:
        """``(F, 3)``: the root joint's position."""
        return self.local_translations()[:, 0].copy()

    def world_rotations(self, local: F64 | None = None) -> F64:
        """``(F, J, 4)`` rotations of each joint's frame in the world.

        Parameters
        ----------
        local : ndarray, optional
            ``(F, J, 4)`` local rotations to chain (None: the motion's own).

        Returns
        -------
        ndarray
            ``(F, J, 4)`` float64 unit quaternions.
        """
        q = self.local_rotations() if local is None else local
        w = np.empty_like(q)
        for j in range(self.n_joints):
            p = self.parents[j]
            w[:, j] = q[:, j] if p < 0 else quat.multiply(w[:, p], q[:, j])
        return w

    def joint_positions(self, end_sites: bool = False) -> F64:
        """``(F, J, 3)`` world positions by forward kinematics (``(F, J + E, 3)`` with End Sites last).

        Parameters
        ----------
        end_sites : bool, default False
            Also place the End Sites, after the joints.

        Returns
        -------
        ndarray
            ``(F, J, 3)`` or ``(F, J + E, 3)`` float64, in the capture's units.
        """
        return forward_kinematics(
            self.parents,
            self.local_translations(),
            self.local_rotations(),
            self.end_parents if end_sites else None,
            self.end_offsets,
        )


def forward_kinematics(
    parents: NDArray[np.int64],
    translations: F64,
    rotations: F64,
    end_parents: NDArray[np.int64] | None = None,
    end_offsets: F64 | None = None,
) -> F64:
    """World positions from local translations ``(F, J, 3)`` and rotations ``(F, J, 4)``.

    P_j = P_parent + R_parent_world · t_j; parents come before children.

    Parameters
    ----------
    parents : ndarray
        ``(J,)`` int64 parent of each joint (−1 for a root), parents first.
    translations : ndarray
        ``(F, J, 3)`` local translations.
    rotations : ndarray
        ``(F, J, 4)`` local rotations (unit quaternions).
    end_parents : ndarray, optional
        ``(E,)`` the joint each End Site hangs from (None: no End Sites).
    end_offsets : ndarray, optional
        ``(E, 3)`` the End Sites' offsets.

    Returns
    -------
    ndarray
        ``(F, J, 3)`` float64 world positions, ``(F, J + E, 3)`` with the End Sites last.
    """
    f, j = translations.shape[:2]
    world_q = np.empty((f, j, 4))
    pos = np.empty((f, j, 3))
    for k in range(j):
        p = parents[k]
        if p < 0:
            world_q[:, k] = rotations[:, k]
            pos[:, k] = translations[:, k]
        else:
            world_q[:, k] = quat.multiply(world_q[:, p], rotations[:, k])
            pos[:, k] = pos[:, p] + quat.rotate(world_q[:, p], translations[:, k])
    if end_parents is None or len(end_parents) == 0:
        return pos
    ends = pos[:, end_parents] + quat.rotate(world_q[:, end_parents], np.asarray(end_offsets)[None])
    return np.concatenate([pos, ends], axis=1)


# ---------------------------------------------------------------------------------------
# Reading
# ---------------------------------------------------------------------------------------
class _Tokens:
    def __init__(self, path: str, words: list[str]) -> None:
        self.path, self.words, self.i = path, words, 0

    def next(self, what: str) -> str:
        if self.i >= len(self.words):
            raise FormatError(self.path, f"file ends where {what} was expected")
        w = self.words[self.i]
        self.i += 1
        return w

    def expect(self, word: str) -> None:
        w = self.next(f"'{word}'")
        if w != word:
            raise FormatError(self.path, f"expected '{word}', found {quoted(w, 40)}")

    def number(self, what: str) -> float:
        w = self.next(what)
        try:
            v = float(w)
        except ValueError:
            raise FormatError(self.path, f"{what} is not a number: {quoted(w, 40)}") from None
        if not math.isfinite(v):
            raise FormatError(self.path, f"{what} is not finite: {quoted(w, 40)}")
        if abs(v) > MAX_VALUE:
            raise FormatError(self.path, f"{what} is beyond ±{MAX_VALUE:.2g}: {quoted(w, 40)}")
        return v


def _parse_hierarchy(tok: _Tokens, path: str):
    """The joints in file order (parents before children), read with an explicit stack of open
    joints rather than by recursion, so a chain of any depth reads (Python's recursion limit
    stopped a chain 1,000 joints deep)."""
    names: list[str] = []
    parents: list[int] = []
    offsets: list[list[float]] = []
    channels: list[list[str]] = []
    end_parents: list[int] = []
    end_offsets: list[list[float]] = []

    def offset(where: str) -> list[float]:
        tok.expect("OFFSET")
        return [tok.number(f"OFFSET of {where}") for _ in range(3)]

    def open_joint(parent: int) -> int:
        """Read a joint's name, '{', OFFSET and CHANNELS; its children and '}' come after."""
        name = tok.next("a joint name")
        if name == "{":
            raise FormatError(path, "a joint has no name")
        if len(names) >= _MAX_JOINTS:
            raise FormatError(path, f"more than {_MAX_JOINTS} joints")
        me = len(names)
        names.append(name)
        parents.append(parent)
        tok.expect("{")
        offsets.append(offset(f"joint '{name}'"))
        chans: list[str] = []
        if tok.i < len(tok.words) and tok.words[tok.i] == "CHANNELS":
            tok.next("CHANNELS")
            count = tok.number(f"channel count of '{name}'")
            if count != int(count) or not 0 <= count <= 6:
                raise FormatError(path, f"joint '{name}' has a channel count of {count:g}; expected 0 to 6")
            for _ in range(int(count)):
                c = tok.next(f"a channel of '{name}'")
                if c not in CHANNEL_NAMES:
                    raise FormatError(path, f"joint '{name}' has an unknown channel '{c[:40]}'")
                if c in chans:
                    raise FormatError(path, f"joint '{name}' lists channel '{c}' twice")
                chans.append(c)
        channels.append(chans)
        return me

    tok.expect("HIERARCHY")
    tok.expect("ROOT")
    open_joints = [open_joint(-1)]
    while open_joints:
        me = open_joints[-1]
        w = tok.next(f"'}}' closing joint {quoted(names[me])}")
        if w == "}":
            open_joints.pop()
        elif w == "JOINT":
            open_joints.append(open_joint(me))
        elif w == "End":
            tok.expect("Site")
            tok.expect("{")
            if len(end_parents) >= _MAX_JOINTS:
                raise FormatError(path, f"more than {_MAX_JOINTS} End Sites")
            end_parents.append(me)
            end_offsets.append(offset(f"the End Site of {quoted(names[me])}"))
            tok.expect("}")
        else:
            raise FormatError(path, f"unexpected {quoted(w, 40)} inside joint {quoted(names[me])}")
    return names, parents, offsets, channels, end_parents, end_offsets


def _frame_count(path: str, text: str) -> int:
    """``Frames:`` as a whole number ≥ 1; NaN, infinities and fractions are refused before any cast."""
    try:
        v = float(text)
    except ValueError:
        raise FormatError(path, f"Frames: {quoted(text, 40)} is not a number") from None
    if not (math.isfinite(v) and v >= 1 and v == math.floor(v)):
        raise FormatError(path, f"Frames: {quoted(text, 40)} is not a positive whole number")
    # Digits: exact even beyond 2^53, leading zeros dropped first (a finite v has at most 309
    # digits left; Python's int() refuses more than 4,300 however small the value).
    return int(text.lstrip("0")) if text.isdigit() else int(v)


def read_bvh(path: str | os.PathLike[str]) -> Motion:
    """Read a BVH file; any malformed input raises :class:`FormatError` naming the file.

    Parameters
    ----------
    path
        A BVH motion capture: its hierarchy (offsets, channels in their order) and motion.

    Returns
    -------
    Motion
        The skeleton and its channel values per frame, with the frame time.

    Raises
    ------
    FormatError
        The file is missing, malformed or truncated; the message names the file.
    """
    p = os.fspath(path)
    return bvh_from_bytes(user_text.read_bytes(p, "a BVH file", max_bytes=None), p)


def bvh_from_bytes(raw: bytes, where: str) -> Motion:
    """:func:`read_bvh` of a file's bytes held in memory (a project keeps its capture as BVH
    text); a :class:`FormatError` names ``where``.

    Parameters
    ----------
    raw
        The BVH file's bytes (UTF-8, or Latin-1 where they are not UTF-8).
    where
        The file or place the bytes come from, named in a refusal.

    Returns
    -------
    Motion
        The skeleton and its channel values per frame, with the frame time.

    Raises
    ------
    FormatError
        The bytes are not a well-formed BVH file; the message names ``where``.
    """
    p = where
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    mm = re.search(r"(?m)^\s*MOTION\s*$", text)
    head, sep, body = (text[: mm.start()], True, text[mm.end() :]) if mm else (text, False, "")
    if not sep:
        raise FormatError(p, "no MOTION block" if "HIERARCHY" in text else "not a BVH file (no HIERARCHY)")
    tok = _Tokens(p, head.split())
    if not tok.words or tok.words[0] != "HIERARCHY":
        raise FormatError(p, "not a BVH file (does not start with HIERARCHY)")
    names, parents, offsets, channels, end_parents, end_offsets = _parse_hierarchy(tok, p)
    if tok.i != len(tok.words):
        raise FormatError(p, f"unexpected '{tok.words[tok.i][:40]}' after the hierarchy")

    m = re.match(r"\s*Frames\s*:\s*(\S+)\s+Frame\s+Time\s*:\s*(\S+)", body)
    if not m:
        raise FormatError(p, "MOTION block lacks 'Frames:' and 'Frame Time:'")
    n_frames = _frame_count(p, m.group(1))
    try:
        frame_time = float(m.group(2))
    except ValueError:
        raise FormatError(p, f"Frame Time: '{m.group(2)[:40]}' is not a number") from None
    if not (math.isfinite(frame_time) and frame_time >= _MIN_FRAME_TIME):
        raise FormatError(
            p, f"Frame Time: {m.group(2)[:40]} is not a number of seconds ≥ {_MIN_FRAME_TIME:g}"
        )
    width = sum(len(c) for c in channels)
    if n_frames * max(width, 1) > _MAX_VALUES:
        raise FormatError(p, f"{n_frames} frames × {width} channels is too large")
    # Every value takes at least one character and a separator: bound the count by the file.
    if n_frames * max(2 * width, 1) > len(body) - m.end():
        raise FormatError(
            p,
            f"MOTION block is truncated: 'Frames:' says {n_frames} frames of {width} values, "
            f"more than its {len(body) - m.end()} characters can hold",
        )
    # Forward kinematics holds every joint in every frame (112 bytes a pose): joints without
    # channels cost no bytes in the file, so bound frames × joints by the file too.
    poses = n_frames * (len(names) + len(end_parents))
    if poses > max(len(raw), _MIN_POSES):
        raise FormatError(
            p,
            f"{n_frames} frames of {len(names) + len(end_parents)} joints and End Sites is more "
            f"than a file of {len(raw)} bytes can describe (joints without channels?)",
        )
    what = f"{p}: {n_frames} frames of {len(names) + len(end_parents)} joints and End Sites (posed)"
    budget.check_bytes(poses * _POSE_BYTES, what)

    lines = [ln for ln in body[m.end() :].splitlines() if ln.strip()]
    if len(lines) < n_frames:
        raise FormatError(p, f"MOTION block is truncated: {len(lines)} of {n_frames} frames")
    if len(lines) > n_frames:
        raise FormatError(p, f"MOTION block has {len(lines)} frame lines but 'Frames:' says {n_frames}")
    values = np.empty((n_frames, width), dtype=np.float64)
    for i, ln in enumerate(lines):
        words = ln.split()
        if len(words) != width:
            raise FormatError(p, f"frame {i} has {len(words)} values; the hierarchy has {width} channels")
        try:
            values[i] = [float(w) for w in words]
        except ValueError:
            raise FormatError(p, f"frame {i} has a value that is not a number") from None
    if not np.all(np.isfinite(values)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(values), axis=1))[0])
        raise FormatError(p, f"frame {bad} has a non-finite value")
    if np.any(np.abs(values) > MAX_VALUE):
        bad = int(np.flatnonzero(np.any(np.abs(values) > MAX_VALUE, axis=1))[0])
        raise FormatError(p, f"frame {bad} has a value beyond ±{MAX_VALUE:.2g}")
    return Motion(
        names,
        np.array(parents),
        np.array(offsets),
        channels,
        values,
        frame_time,
        np.array(end_parents, dtype=np.int64),
        np.array(end_offsets).reshape(-1, 3),
    )


# ---------------------------------------------------------------------------------------
# Writing
# ---------------------------------------------------------------------------------------
def _fmt(v: float) -> str:
    s = f"{v:.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def write_bvh(path: str | os.PathLike[str], motion: Motion) -> None:
    """Write ``motion`` as BVH (atomically); values keep 6 decimals.

    Parameters
    ----------
    path
        The file to write (a temporary file beside it is renamed into place).
    motion
        The skeleton and its channel values; the hierarchy, offsets, channel order and frame
        time are written as the motion holds them.

    Raises
    ------
    OSError
        The file cannot be written; an earlier file at ``path`` is left as it was.
    """
    text = bvh_text(motion)
    with atomic_open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)


def bvh_text(motion: Motion) -> str:
    """The text :func:`write_bvh` writes (a project keeps its capture as this text).

    Parameters
    ----------
    motion
        The skeleton and its channel values.

    Returns
    -------
    str
        The BVH file's text, lines ended by ``\\n``.
    """
    children: list[list[int]] = [[] for _ in range(motion.n_joints)]
    for j in range(1, motion.n_joints):
        children[motion.parents[j]].append(j)
    ends: list[list[int]] = [[] for _ in range(motion.n_joints)]
    for e, j in enumerate(motion.end_parents):
        ends[j].append(e)
    out: list[str] = ["HIERARCHY"]
    # Depth-first with an explicit stack (a chain may be deeper than Python's recursion limit):
    # ("open", j) writes a joint's head and pushes its closing, its End Sites and its children.
    stack: list[tuple[str, int]] = [("open", 0)]
    depth = np.zeros(motion.n_joints, dtype=np.int64)
    while stack:
        step, j = stack.pop()
        pad = "\t" * int(depth[j])
        if step == "open":
            out.append(f"{pad}{'ROOT' if j == 0 else 'JOINT'} {motion.joint_names[j]}")
            out.append(f"{pad}{{")
            out.append(f"{pad}\tOFFSET {' '.join(_fmt(v) for v in motion.offsets[j])}")
            if motion.channels[j]:
                out.append(f"{pad}\tCHANNELS {len(motion.channels[j])} {' '.join(motion.channels[j])}")
            stack.append(("close", j))
            for c in reversed(children[j]):
                depth[c] = depth[j] + 1
                stack.append(("open", c))
        else:
            for e in ends[j]:
                out.append(f"{pad}\tEnd Site")
                out.append(f"{pad}\t{{")
                out.append(f"{pad}\t\tOFFSET {' '.join(_fmt(v) for v in motion.end_offsets[e])}")
                out.append(f"{pad}\t}}")
            out.append(f"{pad}}}")

    out += ["MOTION", f"Frames: {motion.n_frames}", f"Frame Time: {motion.frame_time:.7g}"]
    out += [" ".join(_fmt(v) for v in row) for row in motion.values]
    return "\n".join(out) + "\n"
