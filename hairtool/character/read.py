"""Reading a character (``.glb``, ``.gltf``, ``.vrm``: glTF 2.0, VRM 0.x and 1.0) with pygltflib.

The node tree, skinned triangle meshes (positions, normals, four joints and weights per vertex,
inverse bind matrices), base colours, rotation animations, and the hair chains with their
spring settings and colliders (:mod:`hairtool.character.chains`). Anything malformed is one
:class:`~hairtool.errors.FormatError` naming the file and what is wrong.
"""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path

import numpy as np
from pygltflib import GLTF2

from hairtool.character import accessors
from hairtool.character.chains import find_chains
from hairtool.character.glb import MAX_BYTES, unpack
from hairtool.character.model import Character, Clip, Nodes, SkinnedMesh
from hairtool.errors import FormatError
from hairtool.mocap import quaternion as quat

SUFFIXES = (".glb", ".gltf", ".vrm")


def is_character_path(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` names a glTF, GLB or VRM file (by its suffix).

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    bool
        True for a character's suffix.
    """
    return Path(path).suffix.lower() in SUFFIXES


def load_document(path: str | os.PathLike[str]) -> tuple[dict, bytes | None]:
    """The glTF JSON (as a dict) and the GLB binary chunk (None for ``.gltf`` text).

    Parameters
    ----------
    path : str or os.PathLike
        A ``.glb``, ``.gltf`` or ``.vrm`` file.

    Returns
    -------
    tuple of (dict, bytes or None)
        The JSON and the binary chunk.
    """
    p = os.fspath(path)
    try:
        size = os.path.getsize(p)
        if size > MAX_BYTES:
            raise FormatError(p, f"{size} bytes is more than a character file may have ({MAX_BYTES})")
        data = Path(p).read_bytes()
    except OSError as e:
        raise FormatError(p, e.strerror or "cannot be read") from None
    if data[:4] == b"glTF":
        return unpack(p, data)
    try:
        doc = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError):
        raise FormatError(p, "neither a GLB file nor glTF JSON") from None
    if not isinstance(doc, dict):
        raise FormatError(p, "its glTF JSON is not an object")
    return doc, None


def _gltf(path: str, doc: dict) -> GLTF2:
    asset = doc.get("asset")
    if not isinstance(asset, dict) or not str(asset.get("version", "")).startswith("2."):
        raise FormatError(path, "not glTF 2.0 (asset.version must be 2.x)")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return GLTF2.from_dict(doc)
    except Exception as e:  # pygltflib's schema errors come in many classes
        raise FormatError(path, f"its glTF JSON does not fit the schema ({e.__class__.__name__})") from None


def _vector(path: str, value, n: int, default: tuple[float, ...], what: str) -> np.ndarray:
    if value is None:
        return np.array(default, dtype=np.float64)
    try:
        v = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        v = np.empty(0)
    if v.shape != (n,) or not np.all(np.isfinite(v)):
        raise FormatError(path, f"{what} must be {n} finite numbers")
    return v


def _decompose(path: str, matrix, what: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    m = _vector(path, matrix, 16, (), what).reshape(4, 4).T  # glTF matrices are column-major
    t = m[:3, 3]
    s = np.linalg.norm(m[:3, :3], axis=0)
    if np.any(s < 1e-12):
        raise FormatError(path, f"{what} is singular")
    r = m[:3, :3] / s
    if np.linalg.det(r) < 0:
        s[0], r[:, 0] = -s[0], -r[:, 0]
    w = np.sqrt(max(0.0, 1.0 + np.trace(r))) / 2
    if w > 1e-6:
        q = np.array(
            [w, (r[2, 1] - r[1, 2]) / (4 * w), (r[0, 2] - r[2, 0]) / (4 * w), (r[1, 0] - r[0, 1]) / (4 * w)]
        )
    else:
        i = int(np.argmax(np.diag(r)))
        j, k = (i + 1) % 3, (i + 2) % 3
        v = np.zeros(4)
        v[i + 1] = np.sqrt(max(0.0, 1.0 + r[i, i] - r[j, j] - r[k, k])) / 2
        v[j + 1] = (r[j, i] + r[i, j]) / (4 * v[i + 1])
        v[k + 1] = (r[k, i] + r[i, k]) / (4 * v[i + 1])
        v[0] = (r[k, j] - r[j, k]) / (4 * v[i + 1])
        q = v
    return t, quat.normalize(q), s


def read_nodes(path: str, gltf: GLTF2) -> Nodes:
    """The node tree of ``gltf``: names, parents (parents first) and rest transforms.

    Parameters
    ----------
    path : str
        The file, named in a refusal.
    gltf : GLTF2
        The document.

    Returns
    -------
    Nodes
        The nodes.
    """
    nodes = gltf.nodes or []
    n = len(nodes)
    parents = np.full(n, -1, dtype=np.int64)
    t, r, s = np.zeros((n, 3)), np.zeros((n, 4)), np.ones((n, 3))
    names = []
    for j, node in enumerate(nodes):
        names.append(node.name if isinstance(node.name, str) else f"node{j}")
        for c in node.children or []:
            c = accessors._index(path, f"node {j}: child", c, n)
            if parents[c] >= 0 or c == j:
                raise FormatError(path, f"node {c} has more than one parent (the nodes must form trees)")
            parents[c] = j
        if node.matrix is not None and node.matrix != [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]:
            t[j], r[j], s[j] = _decompose(path, node.matrix, f"node {j}'s matrix")
        else:
            t[j] = _vector(path, node.translation, 3, (0.0, 0.0, 0.0), f"node {j}'s translation")
            xyzw = _vector(path, node.rotation, 4, (0.0, 0.0, 0.0, 1.0), f"node {j}'s rotation")
            if abs(np.linalg.norm(xyzw) - 1.0) > 1e-3:
                raise FormatError(path, f"node {j}'s rotation is not a unit quaternion")
            r[j] = quat.normalize(np.roll(xyzw, 1))
            s[j] = _vector(path, node.scale, 3, (1.0, 1.0, 1.0), f"node {j}'s scale")
    order, seen = [], np.zeros(n, dtype=bool)
    stack = [j for j in range(n) if parents[j] < 0][::-1]
    while stack:
        j = stack.pop()
        seen[j] = True
        order.append(j)
        stack.extend(reversed(np.flatnonzero(parents == j).tolist()))
    if not seen.all():
        raise FormatError(path, "its nodes form a cycle")
    return Nodes(tuple(names), parents, t, r, s, np.array(order, dtype=np.int64))


def _base_color(path: str, gltf: GLTF2, material) -> tuple[float, float, float, float]:
    if material is None:
        return (1.0, 1.0, 1.0, 1.0)
    mats = gltf.materials or []
    m = mats[accessors._index(path, "material", material, len(mats))]
    pbr = m.pbrMetallicRoughness
    factor = None if pbr is None else pbr.baseColorFactor
    return tuple(float(v) for v in _vector(path, factor, 4, (1.0, 1.0, 1.0, 1.0), "baseColorFactor"))


class _Attributes:
    """A primitive's attributes, whether pygltflib gave an object or left a plain dict."""

    def __init__(self, att) -> None:
        d = att if isinstance(att, dict) else (vars(att) if att is not None else {})
        self.POSITION, self.NORMAL = d.get("POSITION"), d.get("NORMAL")
        self.JOINTS_0, self.WEIGHTS_0 = d.get("JOINTS_0"), d.get("WEIGHTS_0")


_attributes = _Attributes


def read_meshes(path: str, gltf: GLTF2, data: list[bytes], nodes: Nodes) -> tuple[SkinnedMesh, ...]:
    """Every triangle primitive of a node with a mesh and a skin.

    Parameters
    ----------
    path : str
        The file, named in a refusal.
    gltf : GLTF2
        The document.
    data : list of bytes
        Its buffers.
    nodes : Nodes
        Its nodes.

    Returns
    -------
    tuple of SkinnedMesh
        The skinned meshes.
    """
    out = []
    skins, meshes = gltf.skins or [], gltf.meshes or []
    for j, node in enumerate(gltf.nodes or []):
        if node.mesh is None or node.skin is None:
            continue
        mesh = meshes[accessors._index(path, f"node {j}: mesh", node.mesh, len(meshes))]
        skin = skins[accessors._index(path, f"node {j}: skin", node.skin, len(skins))]
        joints = np.array([accessors._index(path, "skin joint", k, nodes.count) for k in skin.joints or []])
        if joints.size == 0:
            raise FormatError(path, f"skin {node.skin} has no joints")
        if skin.inverseBindMatrices is None:
            ibm = np.tile(np.eye(4), (joints.size, 1, 1))
        else:
            ibm = accessors.read(path, gltf, data, skin.inverseBindMatrices, "inverseBindMatrices")
            if ibm.shape != (joints.size, 16):
                raise FormatError(path, f"skin {node.skin}: one inverse bind matrix per joint expected")
            ibm = ibm.astype(np.float64).reshape(-1, 4, 4).transpose(0, 2, 1)
        for k, prim in enumerate(mesh.primitives or []):
            what = f"mesh {node.mesh} primitive {k}"
            if prim.mode not in (None, 4):
                continue  # lines and points carry no skin surface to draw
            att = _attributes(prim.attributes)
            if att.POSITION is None or att.JOINTS_0 is None or att.WEIGHTS_0 is None:
                raise FormatError(path, f"{what}: a skinned primitive needs POSITION, JOINTS_0 and WEIGHTS_0")
            pos = accessors.read(path, gltf, data, att.POSITION, f"{what} POSITION").astype(np.float64)
            v = len(pos)
            slots = accessors.read(path, gltf, data, att.JOINTS_0, f"{what} JOINTS_0").astype(np.int64)
            weights = accessors.read(path, gltf, data, att.WEIGHTS_0, f"{what} WEIGHTS_0").astype(np.float64)
            normals = None
            if att.NORMAL is not None:
                normals = accessors.read(path, gltf, data, att.NORMAL, f"{what} NORMAL").astype(np.float64)
            if (
                pos.shape != (v, 3)
                or slots.shape != (v, 4)
                or weights.shape != (v, 4)
                or (normals is not None and normals.shape != (v, 3))
            ):
                raise FormatError(path, f"{what}: attributes of different lengths or widths")
            if not np.all(np.isfinite(pos)) or not np.all(np.isfinite(weights)):
                raise FormatError(path, f"{what}: non-finite positions or weights")
            if slots.size and (slots.min() < 0 or slots.max() >= joints.size):
                raise FormatError(path, f"{what}: JOINTS_0 names a joint the skin does not have")
            total = weights.sum(axis=1, keepdims=True)
            if np.any(total <= 0):
                raise FormatError(path, f"{what}: a vertex has no skin weight")
            if prim.indices is None:
                tris = np.arange(v - v % 3, dtype=np.int64).reshape(-1, 3)
            else:
                tris = accessors.read(path, gltf, data, prim.indices, f"{what} indices").astype(np.int64)
                if tris.ndim != 1 or tris.size % 3 or (tris.size and (tris.min() < 0 or tris.max() >= v)):
                    raise FormatError(path, f"{what}: indices are not triangles of its vertices")
                tris = tris.reshape(-1, 3)
            out.append(
                SkinnedMesh(
                    name=(mesh.name if isinstance(mesh.name, str) else f"mesh{node.mesh}"),
                    positions=pos,
                    normals=normals,
                    triangles=tris,
                    joints=joints[slots],
                    weights=weights / total,
                    inverse_bind=ibm,
                    skin_joints=joints,
                    joint_slots=slots,
                    base_color=_base_color(path, gltf, prim.material),
                )
            )
    return tuple(out)


def _declared_fps(extras: object) -> float | None:
    """An animation's ``extras.fps`` when it is a positive finite number (hairtool writes it)."""
    fps = extras.get("fps") if isinstance(extras, dict) else None
    if isinstance(fps, (int, float)) and not isinstance(fps, bool) and np.isfinite(fps) and fps > 0:
        return float(fps)
    return None


def read_clips(path: str, gltf: GLTF2, data: list[bytes], nodes: Nodes) -> tuple[Clip, ...]:
    """Rotation channels of every animation (translations and scales are not posed here).

    Parameters
    ----------
    path : str
        The file, named in a refusal.
    gltf : GLTF2
        The document.
    data : list of bytes
        Its buffers.
    nodes : Nodes
        Its nodes.

    Returns
    -------
    tuple of Clip
        The clips.
    """
    clips = []
    for a, anim in enumerate(gltf.animations or []):
        rot, step, cubic = {}, set(), {}
        samplers = anim.samplers or []
        for c, ch in enumerate(anim.channels or []):
            tgt = ch.target
            if tgt is None or tgt.path != "rotation" or tgt.node is None:
                continue
            j = accessors._index(path, f"animation {a} channel {c}: node", tgt.node, nodes.count)
            s = samplers[
                accessors._index(path, f"animation {a} channel {c}: sampler", ch.sampler, len(samplers))
            ]
            times = accessors.read(path, gltf, data, s.input, f"animation {a} times").astype(np.float64)
            q = accessors.read(path, gltf, data, s.output, f"animation {a} rotations").astype(np.float64)
            spline = None
            if s.interpolation == "CUBICSPLINE":
                if q.ndim != 2 or q.shape[1] != 4 or len(q) != 3 * times.size:
                    raise FormatError(
                        path, f"animation {a} channel {c}: in-tangent, value and out-tangent per key expected"
                    )
                spline = np.roll(q.reshape(-1, 3, 4), 1, axis=2)
                q = q.reshape(-1, 3, 4)[:, 1]
            if times.ndim != 1 or times.size == 0 or q.shape != (times.size, 4):
                raise FormatError(path, f"animation {a} channel {c}: one quaternion per key time expected")
            if not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0) or not np.all(np.isfinite(q)):
                raise FormatError(path, f"animation {a} channel {c}: key times must increase")
            if spline is not None:
                if not np.all(np.isfinite(spline)):
                    raise FormatError(path, f"animation {a} channel {c}: tangents must be finite")
                rot[j] = (times, spline[:, 1])  # the spline's own values: normalised after interpolation
                cubic[j] = (spline[:, 0], spline[:, 2])
                continue
            rot[j] = (times, quat.normalize(np.roll(q, 1, axis=1)))
            if s.interpolation == "STEP":
                step.add(j)
        name = anim.name if isinstance(anim.name, str) else f"animation{a}"
        clips.append(Clip(name, rot, frozenset(step), cubic, _declared_fps(anim.extras)))
    return tuple(clips)


def load_character(path: str | os.PathLike[str], pattern: str | None = None) -> Character:
    """Read a character; its hair chains from VRM springs, or ``pattern`` (a regex on node names).

    Parameters
    ----------
    path : str or os.PathLike
        A ``.glb``, ``.gltf`` or ``.vrm`` file.
    pattern : str, optional
        A regular expression on node names picking the hair chains (None: the VRM springs).

    Returns
    -------
    Character
        Its nodes, meshes, clips, chains and colliders.
    """
    p = os.fspath(path)
    doc, binary = load_document(p)
    gltf = _gltf(p, doc)
    try:
        data = accessors.buffers(p, gltf, binary)
        nodes = read_nodes(p, gltf)
        meshes = read_meshes(p, gltf, data, nodes)
        clips = read_clips(p, gltf, data, nodes)
        version, chains, colliders = find_chains(p, doc, nodes, pattern)
    except (AttributeError, TypeError, KeyError, IndexError, ValueError, OverflowError) as e:
        # pygltflib does not check types: a value of the wrong kind where the schema wants an
        # object, index or list surfaces here; the checks above name the common cases precisely
        detail = str(e).splitlines()[0][:120] if str(e) else ""
        raise FormatError(
            p, f"malformed glTF: a value of the wrong kind ({e.__class__.__name__}: {detail})"
        ) from None
    return Character(p, nodes, meshes, chains, colliders, clips, version)
