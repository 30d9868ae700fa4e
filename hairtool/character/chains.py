"""Hair chains and their springs, from VRM 1.0 (``VRMC_springBone``), VRM 0.x
(``VRM.secondaryAnimation``) or a pattern on node names.

VRM 1.0 lists every joint of a spring, the last one being only the tail. VRM 0.x lists the
root bones of a group; each chain follows the node's children to a leaf (a branch starts a new
chain at the branching child) and every node is a joint, the last swinging a virtual tail.
0.x files store collider offsets with z flipped (Unity's left-handed frame); they are turned
into glTF's frame here. A pattern (a regular expression) picks nodes by name; each run of
picked nodes from parent to child is a chain with default settings.
"""

from __future__ import annotations

import math
import re

import numpy as np

from hairtool.character.model import Chain, Collider, Joint, Nodes
from hairtool.errors import FormatError

DEFAULT_PATTERN = r"(?i)hair"


def _num(path: str, value, what: str, default: float) -> float:
    if value is None:
        return default
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise FormatError(path, f"{what} must be a finite number, not {value!r}")
    return float(value)


def _node(path: str, value, nodes: Nodes, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < nodes.count:
        raise FormatError(path, f"{what}: {value!r} is not a node index below {nodes.count}")
    return value


def _vec(path: str, value, what: str, default: tuple[float, float, float]) -> np.ndarray:
    if value is None:
        return np.array(default)
    if isinstance(value, dict):
        value = [value.get("x", 0.0), value.get("y", 0.0), value.get("z", 0.0)]
    if not isinstance(value, list) or len(value) != 3:
        raise FormatError(path, f"{what} must be three numbers")
    return np.array([_num(path, v, what, 0.0) for v in value])


def _list(path: str, value, what: str) -> list:
    if value is None:
        return []
    if not isinstance(value, list):
        raise FormatError(path, f"{what} must be a list")
    return value


def _dict(path: str, value, what: str) -> dict:
    if not isinstance(value, dict):
        raise FormatError(path, f"{what} must be an object")
    return value


def _vrm1(path: str, ext: dict, nodes: Nodes) -> tuple[tuple[Chain, ...], tuple[Collider, ...]]:
    colliders = []
    for i, c in enumerate(_list(path, ext.get("colliders"), "colliders")):
        c = _dict(path, c, f"collider {i}")
        node = _node(path, c.get("node"), nodes, f"collider {i}")
        shape = _dict(path, c.get("shape"), f"collider {i} shape")
        if "sphere" in shape:
            s = _dict(path, shape["sphere"], f"collider {i} sphere")
            colliders.append(
                Collider(
                    node,
                    _vec(path, s.get("offset"), "offset", (0, 0, 0)),
                    _num(path, s.get("radius"), "radius", 0.0),
                )
            )
        elif "capsule" in shape:
            s = _dict(path, shape["capsule"], f"collider {i} capsule")
            colliders.append(
                Collider(
                    node,
                    _vec(path, s.get("offset"), "offset", (0, 0, 0)),
                    _num(path, s.get("radius"), "radius", 0.0),
                    _vec(path, s.get("tail"), "tail", (0, 0, 0)),
                )
            )
        else:
            raise FormatError(path, f"collider {i} is neither a sphere nor a capsule")
    groups = []
    for i, g in enumerate(_list(path, ext.get("colliderGroups"), "colliderGroups")):
        ids = _list(path, _dict(path, g, f"collider group {i}").get("colliders"), "colliders")
        for c in ids:
            if isinstance(c, bool) or not isinstance(c, int) or not 0 <= c < len(colliders):
                raise FormatError(path, f"collider group {i} names collider {c!r}, which does not exist")
        groups.append(tuple(ids))
    chains = []
    for i, s in enumerate(_list(path, ext.get("springs"), "springs")):
        s = _dict(path, s, f"spring {i}")
        joints = _list(path, s.get("joints"), f"spring {i} joints")
        ids, settings = [], []
        for k, j in enumerate(joints):
            j = _dict(path, j, f"spring {i} joint {k}")
            node = _node(path, j.get("node"), nodes, f"spring {i} joint {k}")
            if ids and nodes.parents[node] != ids[-1]:
                raise FormatError(
                    path, f"spring {i}: joint {k} (node {node}) is not a child of the joint before it"
                )
            ids.append(node)
            g = _vec(path, j.get("gravityDir"), "gravityDir", (0.0, -1.0, 0.0))
            settings.append(
                Joint(
                    stiffness=_num(path, j.get("stiffness"), "stiffness", 1.0),
                    gravity_power=_num(path, j.get("gravityPower"), "gravityPower", 0.0),
                    gravity_dir=tuple(float(v) for v in g),
                    drag=_num(path, j.get("dragForce"), "dragForce", 0.5),
                    hit_radius=_num(path, j.get("hitRadius"), "hitRadius", 0.0),
                )
            )
        if len(ids) < 2:
            raise FormatError(path, f"spring {i} has fewer than two joints (a joint and its tail)")
        used = sorted(
            {
                c
                for g in _list(path, s.get("colliderGroups"), "colliderGroups")
                for c in groups[_group(path, g, len(groups))]
            }
        )
        center = -1 if s.get("center") is None else _node(path, s.get("center"), nodes, f"spring {i} center")
        name = s.get("name") if isinstance(s.get("name"), str) else f"spring{i}"
        chains.append(Chain(name, tuple(ids), tuple(settings), tuple(used), center))
    return tuple(chains), tuple(colliders)


def _group(path: str, g, n: int) -> int:
    if isinstance(g, bool) or not isinstance(g, int) or not 0 <= g < n:
        raise FormatError(path, f"collider group {g!r} does not exist")
    return g


def _follow(nodes: Nodes, root: int) -> list[list[int]]:
    """Root → leaf along the first child; every other child starts a chain of its own."""
    out, starts = [], [root]
    while starts:
        ids, j = [], starts.pop(0)
        while True:
            ids.append(j)
            kids = nodes.children(j)
            if not kids:
                break
            starts.extend(kids[1:])
            j = kids[0]
        out.append(ids)
    return out


def _vrm0(path: str, ext: dict, nodes: Nodes) -> tuple[tuple[Chain, ...], tuple[Collider, ...]]:
    second = ext.get("secondaryAnimation") or {}
    second = _dict(path, second, "secondaryAnimation")
    colliders, groups = [], []
    for i, g in enumerate(_list(path, second.get("colliderGroups"), "colliderGroups")):
        g = _dict(path, g, f"collider group {i}")
        node = _node(path, g.get("node"), nodes, f"collider group {i}")
        ids = []
        for k, c in enumerate(_list(path, g.get("colliders"), "colliders")):
            c = _dict(path, c, f"collider group {i} collider {k}")
            offset = _vec(path, c.get("offset"), "offset", (0, 0, 0)) * np.array([1.0, 1.0, -1.0])
            ids.append(len(colliders))
            colliders.append(Collider(node, offset, _num(path, c.get("radius"), "radius", 0.0)))
        groups.append(tuple(ids))
    chains = []
    for i, b in enumerate(_list(path, second.get("boneGroups"), "boneGroups")):
        b = _dict(path, b, f"bone group {i}")
        g = _vec(path, b.get("gravityDir"), "gravityDir", (0.0, -1.0, 0.0))
        joint = Joint(
            stiffness=_num(path, b.get("stiffiness", b.get("stiffness")), "stiffiness", 1.0),
            gravity_power=_num(path, b.get("gravityPower"), "gravityPower", 0.0),
            gravity_dir=tuple(float(v) for v in g),
            drag=_num(path, b.get("dragForce"), "dragForce", 0.4),
            hit_radius=_num(path, b.get("hitRadius"), "hitRadius", 0.02),
        )
        used = sorted(
            {
                c
                for gi in _list(path, b.get("colliderGroups"), "colliderGroups")
                for c in groups[_group(path, gi, len(groups))]
            }
        )
        center = b.get("center")
        center = (
            -1 if center is None or center == -1 else _node(path, center, nodes, f"bone group {i} center")
        )
        name = b.get("comment") if isinstance(b.get("comment"), str) and b.get("comment") else f"boneGroup{i}"
        for r, root in enumerate(_list(path, b.get("bones"), "bones")):
            for k, ids in enumerate(_follow(nodes, _node(path, root, nodes, f"bone group {i} bone {r}"))):
                label = f"{name}:{nodes.names[ids[0]]}" + (f":{k}" if k else "")
                chains.append(
                    Chain(label, tuple(ids), (joint,) * len(ids), tuple(used), center, virtual_tail=True)
                )
    return tuple(chains), tuple(colliders)


def by_pattern(path: str, nodes: Nodes, pattern: str) -> tuple[Chain, ...]:
    """Runs of nodes whose names match ``pattern``, parent to child, each a chain of ≥ 2 nodes.

    Parameters
    ----------
    path : str
        The file, named in a refusal.
    nodes : Nodes
        The character's nodes.
    pattern : str
        A regular expression on node names.

    Returns
    -------
    tuple of Chain
        The chains.
    """
    try:
        rx = re.compile(pattern)
    except re.error as e:
        raise FormatError(path, f"the chain pattern {pattern!r} is not a regular expression ({e})") from None
    picked = np.array([bool(rx.search(n)) for n in nodes.names], dtype=bool)
    chains = []
    for j in nodes.order.tolist():
        p = int(nodes.parents[j])
        if not picked[j] or (p >= 0 and picked[p]):
            continue
        for ids in _follow_picked(nodes, j, picked):
            if len(ids) >= 2:
                chains.append(Chain(nodes.names[ids[0]], tuple(ids), (Joint(),) * len(ids)))
    return tuple(chains)


def _follow_picked(nodes: Nodes, root: int, picked: np.ndarray) -> list[list[int]]:
    out, starts = [], [root]
    while starts:
        ids, j = [], starts.pop(0)
        while True:
            ids.append(j)
            kids = [k for k in nodes.children(j) if picked[k]]
            if not kids:
                break
            starts.extend(kids[1:])
            j = kids[0]
        out.append(ids)
    return out


def find_chains(
    path: str, doc: dict, nodes: Nodes, pattern: str | None = None
) -> tuple[str, tuple[Chain, ...], tuple[Collider, ...]]:
    """VRM version ("1.0", "0.x" or ""), chains and colliders. ``pattern`` overrides the springs.

    Parameters
    ----------
    path : str
        The file, named in a refusal.
    doc : dict
        The glTF JSON.
    nodes : Nodes
        The character's nodes.
    pattern : str, optional
        A regular expression on node names (None: the VRM springs).

    Returns
    -------
    tuple of (str, tuple of Chain, tuple of Collider)
        The VRM version, the chains and the colliders.
    """
    ext = doc.get("extensions") or {}
    if not isinstance(ext, dict):
        raise FormatError(path, "its extensions must be an object")
    version = "1.0" if "VRMC_vrm" in ext else "0.x" if "VRM" in ext else ""
    if pattern is not None:
        return version, by_pattern(path, nodes, pattern), ()
    if "VRMC_springBone" in ext:
        return (version or "1.0", *_vrm1(path, _dict(path, ext["VRMC_springBone"], "VRMC_springBone"), nodes))
    if "VRM" in ext:
        return ("0.x", *_vrm0(path, _dict(path, ext["VRM"], "the VRM extension"), nodes))
    return version, by_pattern(path, nodes, DEFAULT_PATTERN), ()
