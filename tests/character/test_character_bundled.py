"""The bundled character: rebuilt by our own code to the same bytes, and what the issue asks of it."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hairtool.character import bundled, load_character
from hairtool.character.glb import pack

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data" / "characters"


def test_the_committed_files_equal_a_regeneration():
    for name, vrm in (("bunches.vrm", True), ("bunches.glb", False)):
        fresh = pack(*bundled.build(vrm))
        assert (ROOT / "resources" / name).read_bytes() == fresh, name
        assert (DATA / name).read_bytes() == fresh, name


def test_a_head_a_body_and_at_least_twelve_bunches_each_on_its_own_chain():
    c = load_character(DATA / "bunches.vrm")
    assert c.vrm_version == "1.0"
    assert len(c.chains) >= 12
    nodes = [n for ch in c.chains for n in ch.nodes]
    assert len(nodes) == len(set(nodes))  # no node in two chains
    head = c.nodes.names.index("Head")
    assert all(c.nodes.parents[ch.nodes[0]] == head for ch in c.chains)
    hair = next(m for m in c.meshes if m.name == "Hair")
    for ch in c.chains:  # every bunch's strip is skinned to its own chain and nothing else
        used = set(hair.joints[(hair.weights > 0) & np.isin(hair.joints, ch.nodes)].tolist())
        assert used and used <= set(ch.nodes)
    assert {"Head", "Hips", "Spine"} <= set(c.nodes.names)
    assert len(c.colliders) == 2 and c.colliders[1].tail is not None  # a sphere and a capsule


def test_the_rest_hair_clears_every_collider_by_its_hit_radius():
    c = load_character(DATA / "bunches.vrm")
    world = c.nodes.world()
    for col in c.colliders:
        p = world[col.node, :3, :3] @ col.offset + world[col.node, :3, 3]
        q = p if col.tail is None else world[col.node, :3, :3] @ col.tail + world[col.node, :3, 3]
        for ch in c.chains:
            tails = world[list(ch.nodes[1:]), :3, 3]
            u = np.clip((tails - p) @ (q - p) / max(float((q - p) @ (q - p)), 1e-30), 0.0, 1.0)
            nearest = p + u[:, None] * (q - p)
            gap = np.linalg.norm(tails - nearest, axis=1) - col.radius - ch.settings[0].hit_radius
            assert gap.min() > 0, ch.name


def test_the_plain_glb_finds_the_same_chains_by_name():
    vrm = load_character(DATA / "bunches.vrm")
    glb = load_character(DATA / "bunches.glb")
    assert glb.vrm_version == ""
    assert [ch.nodes for ch in glb.chains] == [ch.nodes for ch in vrm.chains]
