"""The bundled character, made here so it is ours to ship: a head and body with 14 hair bunches.

Every bunch is a tapered tube skinned to its own chain of five nodes (``J_Sec_Hair1_NN`` →
``J_Sec_Hair5_NN``, VRoid's naming), parented to the head; the body carries the bones VRM 1.0
requires of a humanoid. :func:`build` returns the glTF document and its buffer;
``python -m hairtool.character.bundled OUT_DIR`` writes ``bunches.vrm`` (VRM 1.0 with
``VRMC_springBone`` springs and colliders) and ``bunches.glb`` (the same glTF without the VRM
extensions: its chains are found by name). Geometry is rounded to 10 µm so a rebuild on another
machine gives the same bytes.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from hairtool.character.glb import BufferWriter, pack
from hairtool.io.atomic import atomic_open

HEAD_CENTRE = np.array([0.0, 1.58, 0.0])
HEAD_RADIUS = 0.11
NODES_PER_CHAIN = 5
CLEARANCE = HEAD_RADIUS + 0.03  # hair nodes stay this far from the head's centre at rest
SKIN, HAIR = (0.93, 0.78, 0.68, 1.0), (0.35, 0.22, 0.45, 1.0)

# name, parent, local translation; VRM 1.0 faces +Z, the character's left is +X
BODY = [
    ("Hips", None, (0.0, 0.95, 0.0)),
    ("Spine", "Hips", (0.0, 0.15, 0.0)),
    ("Neck", "Spine", (0.0, 0.3, 0.0)),
    ("Head", "Neck", (0.0, 0.1, 0.0)),
    ("LeftUpperArm", "Spine", (0.18, 0.24, 0.0)),
    ("LeftLowerArm", "LeftUpperArm", (0.26, 0.0, 0.0)),
    ("LeftHand", "LeftLowerArm", (0.24, 0.0, 0.0)),
    ("RightUpperArm", "Spine", (-0.18, 0.24, 0.0)),
    ("RightLowerArm", "RightUpperArm", (-0.26, 0.0, 0.0)),
    ("RightHand", "RightLowerArm", (-0.24, 0.0, 0.0)),
    ("LeftUpperLeg", "Hips", (0.09, -0.05, 0.0)),
    ("LeftLowerLeg", "LeftUpperLeg", (0.0, -0.42, 0.0)),
    ("LeftFoot", "LeftLowerLeg", (0.0, -0.42, 0.0)),
    ("RightUpperLeg", "Hips", (-0.09, -0.05, 0.0)),
    ("RightLowerLeg", "RightUpperLeg", (0.0, -0.42, 0.0)),
    ("RightFoot", "RightLowerLeg", (0.0, -0.42, 0.0)),
]
HUMAN_BONE = {n: n[0].lower() + n[1:] for n, _, _ in BODY}

# azimuth (degrees from the face, +Z, towards the left, +X), root elevation (degrees), length (m)
BUNCHES = [
    (-30, 55, 0.14),
    (-10, 58, 0.15),
    (10, 58, 0.15),
    (30, 55, 0.14),  # bangs
    (-60, 42, 0.26),
    (60, 42, 0.26),
    (-90, 40, 0.28),
    (90, 40, 0.28),  # sides
    (-125, 35, 0.34),
    (125, 35, 0.34),
    (-155, 35, 0.36),
    (155, 35, 0.36),
    (180, 38, 0.38),  # back
    (180, 70, 0.32),  # crown
]
SPRING = {
    "stiffness": 1.0,
    "gravityPower": 0.3,
    "gravityDir": [0.0, -1.0, 0.0],
    "dragForce": 0.4,
    "hitRadius": 0.01,
}


def _r(a: np.ndarray) -> np.ndarray:
    return np.round(np.asarray(a, dtype=np.float64), 5)


def hair_chain(azimuth: float, elevation: float, length: float) -> np.ndarray:
    """``(5, 3)`` rest nodes of one bunch: out from the scalp, then hanging; clear of the head.

    Parameters
    ----------
    azimuth, elevation : float
        Where the bunch leaves the scalp, degrees.
    length : float
        Its length.

    Returns
    -------
    ndarray
        ``(5, 3)`` float64.
    """
    az, el = math.radians(azimuth), math.radians(elevation)
    out = np.array([math.sin(az), 0.0, math.cos(az)])
    root = HEAD_CENTRE + HEAD_RADIUS * (math.cos(el) * out + np.array([0.0, math.sin(el), 0.0]))
    k = np.arange(NODES_PER_CHAIN)[:, None]
    lift = np.where(k > 0, 0.05 + 0.01 * k, 0.0)
    nodes = root + lift * out - (length * k / (NODES_PER_CHAIN - 1)) * np.array([0.0, 1.0, 0.0])
    off = nodes[1:] - HEAD_CENTRE
    dist = np.linalg.norm(off, axis=1, keepdims=True)
    nodes[1:] = HEAD_CENTRE + off * np.maximum(dist, CLEARANCE) / dist  # keep clear of the head
    return _r(nodes)


def _ring_frame(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    d = d / np.linalg.norm(d)
    a = np.array([1.0, 0.0, 0.0]) if abs(d[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    u = np.cross(d, a)
    u /= np.linalg.norm(u)
    return u, np.cross(d, u)


def tube(centres: np.ndarray, radii: np.ndarray, sides: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rings of ``sides`` vertices around a polyline, closed at the tip: positions, normals, triangles.

    Parameters
    ----------
    centres : ndarray
        ``(N, 3)`` the polyline.
    radii : ndarray
        ``(N,)`` the radius at each point.
    sides : int
        Vertices per ring.

    Returns
    -------
    tuple of (ndarray, ndarray, ndarray)
        Positions, normals and triangles.
    """
    pos, nor = [], []
    for i, c in enumerate(centres):
        d = centres[min(i + 1, len(centres) - 1)] - centres[max(i - 1, 0)]
        u, v = _ring_frame(d)
        for s in range(sides):
            a = 2 * math.pi * s / sides
            n = math.cos(a) * u + math.sin(a) * v
            pos.append(c + radii[i] * n)
            nor.append(n)
    tris = []
    for i in range(len(centres) - 1):
        for s in range(sides):
            a, b = i * sides + s, i * sides + (s + 1) % sides
            tris += [(a, b, b + sides), (a, b + sides, a + sides)]
    return np.array(pos), np.array(nor), np.array(tris)


def sphere(centre: np.ndarray, radius: float, rings: int = 8, sides: int = 12):
    """A UV sphere's positions, normals and triangles (the bundled character's head).

    Parameters
    ----------
    centre : ndarray
        ``(3,)``.
    radius : float
        Its radius.
    rings : int, default 8
        Rings from pole to pole.
    sides : int, default 12
        Vertices per ring.

    Returns
    -------
    tuple of (ndarray, ndarray, ndarray)
        Positions, normals and triangles.
    """
    pos, nor = [], []
    for i in range(rings + 1):
        el = math.pi / 2 - math.pi * i / rings
        for s in range(sides):
            a = 2 * math.pi * s / sides
            n = np.array([math.cos(el) * math.sin(a), math.sin(el), math.cos(el) * math.cos(a)])
            pos.append(centre + radius * n)
            nor.append(n)
    tris = []
    for i in range(rings):
        for s in range(sides):
            a, b = i * sides + s, i * sides + (s + 1) % sides
            tris += [(a, b + sides, b), (a, a + sides, b + sides)]
    return np.array(pos), np.array(nor), np.array(tris)


class _Mesh:
    def __init__(self) -> None:
        self.pos, self.nor, self.tri, self.joints, self.weights = [], [], [], [], []
        self.n = 0

    def add(self, pos, nor, tri, joints, weights) -> None:
        self.pos.append(pos)
        self.nor.append(nor)
        self.tri.append(tri + self.n)
        self.joints.append(joints)
        self.weights.append(weights)
        self.n += len(pos)

    def arrays(self):
        return (
            np.concatenate(self.pos),
            np.concatenate(self.nor),
            np.concatenate(self.tri),
            np.concatenate(self.joints),
            np.concatenate(self.weights),
        )


def _one_joint(n: int, j: int) -> tuple[np.ndarray, np.ndarray]:
    joints = np.zeros((n, 4), dtype=np.int64)
    joints[:, 0] = j
    weights = np.zeros((n, 4))
    weights[:, 0] = 1.0
    return joints, weights


def build(vrm: bool = True) -> tuple[dict, bytes]:
    """The character's glTF document and binary buffer (with the VRM 1.0 extensions if ``vrm``).

    Parameters
    ----------
    vrm : bool, default True
        Add the VRM 1.0 extensions.

    Returns
    -------
    tuple of (dict, bytes)
        The glTF JSON and the binary buffer.
    """
    names, parents, local = [], [], []
    for name, parent, t in BODY:
        names.append(name)
        parents.append(-1 if parent is None else names.index(parent))
        local.append(np.array(t))
    world = []
    for j, t in enumerate(local):
        world.append(t if parents[j] < 0 else world[parents[j]] + t)
    head = names.index("Head")
    chains = []
    for b, (az, el, length) in enumerate(BUNCHES, start=1):
        nodes = hair_chain(az, el, length)
        ids = []
        for k, p in enumerate(nodes):
            parent = head if k == 0 else ids[-1]
            ids.append(len(names))
            names.append(f"J_Sec_Hair{k + 1}_{b:02d}")
            parents.append(parent)
            local.append(_r(p - world[parent]))
            world.append(world[parent] + local[-1])
        chains.append(ids)
    world = np.array(world)

    body, hair = _Mesh(), _Mesh()
    p, n, t = sphere(HEAD_CENTRE, HEAD_RADIUS)
    body.add(p, n, t, *_one_joint(len(p), head))
    limbs = [("Hips", "Neck", 0.13, 0.1), ("Neck", "Head", 0.05, 0.05)]
    limbs += [(f"{s}UpperArm", f"{s}Hand", 0.045, 0.035) for s in ("Left", "Right")]
    limbs += [(f"{s}UpperLeg", f"{s}Foot", 0.07, 0.05) for s in ("Left", "Right")]
    for a, b, r0, r1 in limbs:
        ja, jb = names.index(a), names.index(b)
        centres = np.linspace(world[ja], world[jb], 4)
        p, n, t = tube(centres, np.linspace(r0, r1, 4), 8)
        seg = [ja] * 8 * 2 + [parents[jb]] * 8 * 2 if a.endswith(("Arm", "Leg")) else [ja] * 32
        joints = np.zeros((len(p), 4), dtype=np.int64)
        joints[:, 0] = seg
        weights = np.zeros((len(p), 4))
        weights[:, 0] = 1.0
        body.add(p, n, t, joints, weights)
    sides = 5
    for ids in chains:
        nodes = world[ids]
        stations, radii, js, ws = [], [], [], []
        for i in range(len(ids) - 1):
            for f in (0.0, 0.5):
                stations.append(nodes[i] + f * (nodes[i + 1] - nodes[i]))
                radii.append(0.024 * (1.0 - (i + f) / (len(ids) - 1)) + 0.003)
                if f == 0.0 and i > 0:
                    js.append((ids[i - 1], ids[i])), ws.append((0.5, 0.5))
                else:
                    js.append((ids[i], ids[i])), ws.append((1.0, 0.0))
        stations.append(nodes[-1])
        radii.append(0.003)
        js.append((ids[-2], ids[-2])), ws.append((1.0, 0.0))
        p, n, t = tube(np.array(stations), np.array(radii), sides)
        joints = np.zeros((len(p), 4), dtype=np.int64)
        weights = np.zeros((len(p), 4))
        joints[:, :2] = np.repeat(np.array(js), sides, axis=0)
        weights[:, :2] = np.repeat(np.array(ws), sides, axis=0)
        hair.add(p, n, t, joints, weights)

    doc: dict = {"asset": {"version": "2.0", "generator": "hairtool bundled character"}}
    if vrm:
        doc["extensionsUsed"] = ["VRMC_vrm", "VRMC_springBone"]
    doc["scene"] = 0
    skin_joints = list(range(len(names)))
    mesh_nodes = [len(names), len(names) + 1]
    doc["scenes"] = [{"nodes": [0, *mesh_nodes]}]
    nodes_json = []
    for j, name in enumerate(names):
        node: dict = {"name": name, "translation": [float(v) for v in local[j]]}
        kids = [c for c in range(len(names)) if parents[c] == j]
        if kids:
            node["children"] = kids
        nodes_json.append(node)
    nodes_json.append({"name": "Body", "mesh": 0, "skin": 0})
    nodes_json.append({"name": "Hair", "mesh": 1, "skin": 0})
    doc["nodes"] = nodes_json
    doc["materials"] = [
        {"name": "Skin", "pbrMetallicRoughness": {"baseColorFactor": list(SKIN), "metallicFactor": 0.0}},
        {
            "name": "Hair",
            "pbrMetallicRoughness": {"baseColorFactor": list(HAIR), "metallicFactor": 0.0},
            "doubleSided": True,
        },
    ]
    w = BufferWriter(doc)
    meshes = []
    for mesh_name, mesh, material in (("Body", body, 0), ("Hair", hair, 1)):
        pos, nor, tri, joints, weights = mesh.arrays()
        joints = np.where(weights > 0, joints, 0)  # the validator warns of joints given no weight
        attributes = {
            "POSITION": w.add(_r(pos).astype(np.float32), "VEC3", target=34962, bounds=True),
            "NORMAL": w.add(_r(nor).astype(np.float32), "VEC3", target=34962),
            "JOINTS_0": w.add(joints.astype(np.uint8), "VEC4", target=34962),
            "WEIGHTS_0": w.add(weights.astype(np.float32), "VEC4", target=34962),
        }
        indices = w.add(tri.reshape(-1).astype(np.uint16), "SCALAR", target=34963)
        meshes.append(
            {
                "name": mesh_name,
                "primitives": [
                    {"attributes": attributes, "indices": indices, "material": material, "mode": 4}
                ],
            }
        )
    doc["meshes"] = meshes
    inverse_bind = np.tile(np.eye(4), (len(names), 1, 1))
    inverse_bind[:, :3, 3] = -world
    ibm = w.add(inverse_bind.transpose(0, 2, 1).reshape(-1, 16).astype(np.float32), "MAT4")
    doc["skins"] = [{"name": "Character", "inverseBindMatrices": ibm, "joints": skin_joints, "skeleton": 0}]
    binary = w.bytes()
    doc["buffers"] = [{"byteLength": len(binary)}]
    if vrm:
        doc["extensions"] = {"VRMC_vrm": _vrm_meta(names), "VRMC_springBone": _springs(names, chains)}
    return doc, binary


def _vrm_meta(names: list[str]) -> dict:
    return {
        "specVersion": "1.0",
        "meta": {
            "name": "Bunches",
            "version": "1",
            "authors": ["hairtool"],
            "copyrightInformation": "made by hairtool's own code; MIT, as hairtool",
            "licenseUrl": "https://vrm.dev/licenses/1.0/",  # the one VRM 1.0 readers accept
            "otherLicenseUrl": "https://opensource.org/licenses/MIT",
            "avatarPermission": "everyone",
            "allowExcessivelyViolentUsage": True,
            "allowExcessivelySexualUsage": False,
            "commercialUsage": "corporation",
            "allowPoliticalOrReligiousUsage": True,
            "allowAntisocialOrHateUsage": False,
            "creditNotation": "unnecessary",
            "allowRedistribution": True,
            "modification": "allowModificationRedistribution",
        },
        "humanoid": {"humanBones": {HUMAN_BONE[n]: {"node": names.index(n)} for n, _, _ in BODY}},
    }


def _springs(names: list[str], chains: list[list[int]]) -> dict:
    head, spine = names.index("Head"), names.index("Spine")
    return {
        "specVersion": "1.0",
        "colliders": [
            {
                "node": head,
                "shape": {
                    "sphere": {"offset": [0.0, round(HEAD_CENTRE[1] - 1.5, 5), 0.0], "radius": HEAD_RADIUS}
                },
            },
            {
                "node": spine,
                "shape": {"capsule": {"offset": [0.0, 0.05, 0.0], "radius": 0.09, "tail": [0.0, 0.3, 0.0]}},
            },
        ],
        "colliderGroups": [{"name": "Head and body", "colliders": [0, 1]}],
        "springs": [
            {"name": f"Hair{b:02d}", "joints": [{"node": j, **SPRING} for j in ids], "colliderGroups": [0]}
            for b, ids in enumerate(chains, start=1)
        ],
    }


def build_vrm0() -> tuple[dict, bytes]:
    """The same character declared as VRM 0.x: bone groups of root bones (0.x's misspelled
    ``stiffiness``), Unity-frame collider offsets (z flipped), a list of human bones. It has a
    sphere per collider group only, so the body capsule is left out."""
    doc, binary = build(vrm=True)
    springs = doc["extensions"].pop("VRMC_springBone")
    doc["extensions"].pop("VRMC_vrm")
    doc["extensionsUsed"] = ["VRM"]
    names = [n["name"] for n in doc["nodes"]]
    sphere = springs["colliders"][0]
    x, y, z = sphere["shape"]["sphere"]["offset"]
    joint = springs["springs"][0]["joints"][0]
    group = {
        "comment": "hair",
        "stiffiness": joint["stiffness"],
        "gravityPower": joint["gravityPower"],
        "gravityDir": {"x": 0.0, "y": -1.0, "z": 0.0},
        "dragForce": joint["dragForce"],
        "center": -1,
        "hitRadius": joint["hitRadius"],
        "bones": [s["joints"][0]["node"] for s in springs["springs"]],
        "colliderGroups": [0],
    }
    collider = {"offset": {"x": x, "y": y, "z": -z}, "radius": sphere["shape"]["sphere"]["radius"]}
    doc["extensions"]["VRM"] = {
        "specVersion": "0.0",
        "exporterVersion": "hairtool",
        "meta": {
            "title": "Bunches",
            "author": "hairtool",
            "licenseName": "Other",
            "otherLicenseUrl": "https://opensource.org/licenses/MIT",
        },
        "humanoid": {"humanBones": [{"bone": HUMAN_BONE[n], "node": names.index(n)} for n, _, _ in BODY]},
        "secondaryAnimation": {
            "boneGroups": [group],
            "colliderGroups": [{"node": sphere["node"], "colliders": [collider]}],
        },
    }
    return doc, binary


def write(folder: str | Path) -> list[Path]:
    """Write ``bunches.vrm`` and ``bunches.glb`` into ``folder`` (atomically); their paths.

    Parameters
    ----------
    folder : str or Path
        Where the two files go.

    Returns
    -------
    list of Path
        Their paths.
    """
    out = []
    for name, vrm in (("bunches.vrm", True), ("bunches.glb", False)):
        path = Path(folder) / name
        with atomic_open(path, "wb") as f:
            f.write(pack(*build(vrm)))
        out.append(path)
    return out


if __name__ == "__main__":  # pragma: no cover - the generator command
    for p in write(sys.argv[1] if len(sys.argv) > 1 else "resources"):
        print(p)
