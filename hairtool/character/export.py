"""Writing a character back with its hair animated: one glTF channel per bone rotation.

The character's own JSON entries and binary bytes are kept as they were; the animation's key
times and rotations are appended after its buffer, and one animation is added. Anime drawings
are ``STEP`` keys exactly at the frames where a drawing starts (limited animation is a hold);
simulations are ``LINEAR`` keys. Optimal keys with Hermite curves (``--interp hermite-fit``) are
``CUBICSPLINE`` keys: the keys module's curve through the hemisphere-aligned quaternion components,
its in- and out-tangents per key rescaled from per frame to per second of the written key interval,
so a glTF player (which normalises after interpolating) draws the same rotations.

glTF key times are 32-bit floats. A key time that rounds *above* i/fps makes three.js, which
samples at i/fps in doubles, hold the previous drawing one frame longer, where Blender (which
snaps to frames) shows the new one; every time is therefore written as the largest float32 not
above i/fps, on which both agree.
"""

from __future__ import annotations

import base64
import copy
import json
import os
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hairtool.character.glb import BufferWriter, pack
from hairtool.character.read import load_document
from hairtool.errors import FormatError, ParameterError
from hairtool.io.atomic import atomic_open
from hairtool.keys.reconstruct import KeyPoses, key_poses
from hairtool.mocap import quaternion as quat

F64 = NDArray[np.float64]


def key_times(frames: NDArray[np.int64], fps: float) -> NDArray[np.float32]:
    """Float32 times of frame numbers, each the largest float32 ≤ frame/fps.

    Parameters
    ----------
    frames : ndarray
        int64 frame numbers.
    fps : float
        Frames per second.

    Returns
    -------
    ndarray
        float32 seconds.
    """
    exact = np.asarray(frames, dtype=np.float64) / fps
    t = exact.astype(np.float32)
    over = t.astype(np.float64) > exact
    t[over] = np.nextafter(t[over], np.float32(-np.inf))
    return t


def hold_keys(frames: F64) -> NDArray[np.int64]:
    """Frame numbers where a node's pose changes (frame 0 always): the STEP keys of held drawings.

    Parameters
    ----------
    frames : ndarray
        ``(F, J, 4)`` rotations of the animated nodes.

    Returns
    -------
    ndarray
        int64 frame numbers.
    """
    change = np.any(frames[1:] != frames[:-1], axis=tuple(range(1, frames.ndim)))
    return np.concatenate([[0], 1 + np.flatnonzero(change)]).astype(np.int64)


def animated_nodes(rotations: F64, rest: F64) -> list[int]:
    """Nodes whose rotation differs from the rest pose on some frame.

    Parameters
    ----------
    rotations : ndarray
        ``(F, J, 4)``.
    rest : ndarray
        ``(J, 4)``.

    Returns
    -------
    list of int
        Node indices.
    """
    return np.flatnonzero(np.any(np.abs(rotations - rest[None]) > 0, axis=(0, 2))).tolist()


def add_animation(
    document: dict,
    writer: BufferWriter,
    rotations: F64,
    fps: float,
    nodes: list[int],
    *,
    name: str,
    step: bool,
    loop_frames: int | None = None,
    key_frames: NDArray[np.int64] | dict[int, NDArray[np.int64]] | None = None,
    interp: str = "linear",
) -> None:
    """Append one animation: ``rotations`` ``(F, J, 4)`` wxyz of ``nodes`` at ``fps``.

    ``step``: keys only where the pose of the animated nodes changes, ``STEP`` interpolation
    (one shared time accessor). ``loop_frames``: add a closing key at that frame showing frame 0
    again, so the clip lasts the whole cycle. Otherwise a ``LINEAR`` key on every frame, or only
    on ``key_frames`` (optimal keys, increasing frame numbers; or per node, a dict node → frames,
    the nodes sharing a key set sharing its time accessor); with ``interp`` "hermite" or
    "hermite-fit" those keys are ``CUBICSPLINE`` with the keys module's tangents (the first and last
    frame must then be keys, as the DP's always are).

    Parameters
    ----------
    document : dict
        The glTF JSON, changed in place.
    writer : BufferWriter
        Where the keys' bytes go.
    rotations : ndarray
        ``(F, J, 4)`` wxyz.
    fps : float
        Frames per second.
    nodes : list of int
        The nodes animated.
    name : str
        The animation's name.
    step : bool
        Held drawings: ``STEP`` keys where the pose changes.
    loop_frames : int, optional
        A closing key at this frame showing frame 0.
    key_frames : ndarray or dict, optional
        Optimal keys, one set or per node.
    interp : str, default "linear"
        "linear", or "hermite"/"hermite-fit" for ``CUBICSPLINE``.
    """
    if interp != "linear" and (key_frames is None or step or loop_frames is not None):
        raise ParameterError(
            "interp", interp, "linear, unless optimal keys are written (no STEP, no loop key)"
        )
    if not isinstance(key_frames, dict):
        samplers = _samplers(writer, rotations, nodes, fps, step, loop_frames, key_frames, interp)
        channels = [
            {"sampler": k, "target": {"node": node, "path": "rotation"}} for k, node in enumerate(nodes)
        ]
    else:
        missing = [n for n in nodes if n not in key_frames]
        if missing:
            raise ParameterError("keys", f"none for node {missing[0]}", "key frames for every animated node")
        groups: dict[tuple[int, ...], list[int]] = {}
        for node in nodes:
            groups.setdefault(tuple(int(v) for v in np.asarray(key_frames[node]).reshape(-1)), []).append(
                node
            )
        samplers, channels = [], []
        for frames, group in groups.items():
            channels += [
                {"sampler": len(samplers) + k, "target": {"node": node, "path": "rotation"}}
                for k, node in enumerate(group)
            ]
            samplers += _samplers(writer, rotations, group, fps, step, loop_frames, np.array(frames), interp)
    # glTF has no frame rate: declared in extras, a reader need not guess it from the key times
    document.setdefault("animations", []).append(
        {"name": name, "channels": channels, "samplers": samplers, "extras": {"fps": float(fps)}}
    )


def _samplers(
    writer: BufferWriter,
    rotations: F64,
    nodes: list[int],
    fps: float,
    step: bool,
    loop_frames: int | None,
    key_frames: NDArray[np.int64] | None,
    interp: str,
) -> list[dict]:
    """One sampler per node of ``nodes``, on one time accessor (see :func:`add_animation`)."""
    f = len(rotations)
    sub = rotations[:, nodes]
    if key_frames is not None:
        frames = np.asarray(key_frames, dtype=np.int64)
        if (
            frames.ndim != 1
            or frames.size == 0
            or frames.min() < 0
            or frames.max() >= f
            or np.any(np.diff(frames) <= 0)
        ):
            raise ParameterError("keys", frames.tolist()[:6], f"increasing frame numbers in [0, {f})")
    else:
        frames = hold_keys(sub) if step else np.arange(f, dtype=np.int64)
    if interp != "linear":
        return _cubic_samplers(writer, hermite_keys(sub, frames, interp), fps, len(nodes))
    values = sub[frames]
    if loop_frames is not None:
        frames = np.concatenate([frames, [loop_frames]])
        values = np.concatenate([values, sub[:1]])
    values = _hemisphere(values)
    times = writer.add(key_times(frames, fps), "SCALAR", bounds=True)
    samplers = []
    for k in range(len(nodes)):
        xyzw = np.roll(values[:, k], -1, axis=1).astype(np.float32)
        samplers.append(
            {
                "input": times,
                "output": writer.add(xyzw, "VEC4"),
                "interpolation": "STEP" if step else "LINEAR",
            }
        )
    return samplers


def hermite_keys(rotations: F64, frames: NDArray[np.int64], interp: str) -> KeyPoses:
    """The keys module's Hermite keys of ``rotations`` ``(F, J, 4)``: values and per-frame tangents
    of the quaternion components, aligned to one hemisphere along time first (as
    :func:`hairtool.mocap.costs.reconstruct_motion` does); the curve is
    ``normalize(interpolate_keys(...))``.

    Parameters
    ----------
    rotations : ndarray
        ``(F, J, 4)`` wxyz.
    frames : ndarray
        int64 key frames.
    interp : str
        "hermite" or "hermite-fit".

    Returns
    -------
    KeyPoses
        Values and per-frame tangents.
    """
    return key_poses(quat.align_hemisphere(rotations, axis=0), frames, interp)


def _cubic_samplers(writer: BufferWriter, kp: KeyPoses, fps: float, count: int) -> list[dict]:
    """One ``CUBICSPLINE`` sampler per node: in-tangent, value, out-tangent per key, per second.

    glTF scales both tangents of a segment by its interval in seconds, here the difference of the
    float32 key times; the keys module scales them by the interval in frames. Each tangent is
    rescaled by its own segment's ratio, so the two curves agree up to float32 storage. The first
    in-tangent and the last out-tangent lie outside the clip and are written at ``fps``.
    """
    times32 = key_times(kp.keys, fps)
    ratio = np.diff(kp.keys).astype(np.float64) / np.diff(times32.astype(np.float64))
    arriving = kp.tangents if kp.tangents_in is None else kp.tangents_in
    out_t, in_t = kp.tangents * fps, arriving * fps
    out_t[:-1] = kp.tangents[:-1] * ratio[:, None, None]
    in_t[1:] = arriving[1:] * ratio[:, None, None]
    times = writer.add(times32, "SCALAR", bounds=True)
    samplers = []
    for k in range(count):
        triple = np.stack([in_t[:, k], kp.poses[:, k], out_t[:, k]], axis=1)  # (K, 3, 4) wxyz
        xyzw = np.roll(triple, -1, axis=2).reshape(-1, 4).astype(np.float32)
        samplers.append({"input": times, "output": writer.add(xyzw, "VEC4"), "interpolation": "CUBICSPLINE"})
    return samplers


def _hemisphere(q: F64) -> F64:
    """Consecutive keys on the same side of the double cover, so LINEAR interpolates the short way."""
    out = q.copy()
    for i in range(1, len(out)):
        flip = np.sum(out[i] * out[i - 1], axis=-1) < 0
        out[i][flip] *= -1.0
    return out


def write_animated(
    source: str | os.PathLike[str],
    out: str | os.PathLike[str],
    rotations: F64,
    rest: F64,
    fps: float,
    *,
    name: str,
    step: bool,
    loop_frames: int | None = None,
    key_frames: NDArray[np.int64] | dict[int, NDArray[np.int64]] | None = None,
    interp: str = "linear",
) -> dict:
    """Write ``source`` with its hair animated to ``out`` (.glb, .vrm or .gltf); a summary dict.
    ``key_frames``: optimal keys, one set or per node (a dict node → frames, every animated node
    in it); ``interp``: "linear", or "hermite"/"hermite-fit" for ``CUBICSPLINE`` keys on them.

    Parameters
    ----------
    source : str or os.PathLike
        The character read.
    out : str or os.PathLike
        ``.glb``, ``.vrm`` or ``.gltf``.
    rotations : ndarray
        ``(F, J, 4)`` wxyz local rotations.
    rest : ndarray
        ``(J, 4)`` the rest pose.
    fps : float
        Frames per second.
    name : str
        The animation's name.
    step : bool
        Held drawings.
    loop_frames : int, optional
        A closing key at this frame showing frame 0.
    key_frames : ndarray or dict, optional
        Optimal keys, one set or per node.
    interp : str, default "linear"
        The keys' interpolation.

    Returns
    -------
    dict
        The output, the animated nodes, the key count and the interpolation.
    """
    path = os.fspath(out)
    suffix = Path(path).suffix.lower()
    if suffix not in (".glb", ".vrm", ".gltf"):
        raise ParameterError("output", path, "a .glb, .vrm or .gltf file")
    if not np.isfinite(fps) or fps <= 0:
        raise ParameterError("fps", fps, "a positive frame rate")
    document, binary = load_document(source)
    document = copy.deepcopy(document)
    nodes = animated_nodes(rotations, rest)
    if not nodes:
        raise ParameterError("chains", 0, f"hair chains to animate in {os.fspath(source)}")
    buffers = document.get("buffers") or []
    if suffix == ".gltf":
        writer = BufferWriter(document)
        add_animation(
            document,
            writer,
            rotations,
            fps,
            nodes,
            name=name,
            step=step,
            loop_frames=loop_frames,
            key_frames=key_frames,
            interp=interp,
        )
        data = writer.bytes()
        if binary is not None and buffers and buffers[0].get("uri") is None:  # from a GLB: embed its bytes
            buffers[0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(binary).decode(
                "ascii"
            )
        uri = "data:application/octet-stream;base64," + base64.b64encode(data).decode("ascii")
        for view in document["bufferViews"][-writer.views :]:
            view["buffer"] = len(buffers)
        document["buffers"] = [*buffers, {"byteLength": len(data), "uri": uri}]
        payload = json.dumps(document, separators=(",", ":")).encode("utf-8")
    else:
        if binary is None and buffers:
            raise FormatError(source, "its buffers are outside the file: write the animation to a .gltf")
        own = binary or b""
        start = len(own) if not buffers else buffers[0].get("byteLength", len(own))
        writer = BufferWriter(document, offset=(start + 3) // 4 * 4)
        add_animation(
            document,
            writer,
            rotations,
            fps,
            nodes,
            name=name,
            step=step,
            loop_frames=loop_frames,
            key_frames=key_frames,
            interp=interp,
        )
        data = own[:start] + b"\0" * (-start % 4) + writer.bytes()
        if buffers:
            buffers[0]["byteLength"] = len(data)
        else:
            document["buffers"] = [{"byteLength": len(data)}]
        payload = pack(document, data)
    with atomic_open(path, "wb") as f:
        f.write(payload)
    return {
        "output": path,
        "animated_nodes": len(nodes),
        "keys": int(
            len(np.unique(np.concatenate([np.asarray(v).reshape(-1) for v in key_frames.values()])))
            if isinstance(key_frames, dict)
            else len(key_frames)
            if key_frames is not None
            else len(hold_keys(rotations[:, nodes]))
            if step
            else len(rotations)
        ),
        "interpolation": "STEP" if step else "LINEAR" if interp == "linear" else "CUBICSPLINE",
        "fps": fps,
        "frames": len(rotations),
    }
