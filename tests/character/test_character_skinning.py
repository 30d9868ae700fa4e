"""Linear blend skinning: the kernel against its numpy twin, the rest pose, and rigid turns."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.character import load_character
from hairtool.character.skinning import skin
from hairtool.mocap import quaternion as quat

CHARACTER = load_character(Path(__file__).resolve().parents[1] / "data" / "characters" / "bunches.vrm")


def test_the_rest_pose_gives_back_the_bind_positions():
    world = CHARACTER.nodes.world()
    for mesh in CHARACTER.meshes:
        np.testing.assert_allclose(skin(mesh, world), mesh.positions, atol=1e-6)


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), angle=st.floats(-3.0, 3.0))
def test_the_kernel_equals_the_numpy_twin_on_random_poses(seed, angle):
    rng = np.random.default_rng(seed)
    axes = rng.normal(size=(CHARACTER.nodes.count, 3))
    rot = quat.from_axis_angle(
        axes / np.linalg.norm(axes, axis=1, keepdims=True), angle * rng.random(CHARACTER.nodes.count)
    )
    world = CHARACTER.nodes.world(rot)
    for mesh in CHARACTER.meshes:
        np.testing.assert_allclose(skin(mesh, world), skin(mesh, world, use_numba=False), atol=1e-12)


def test_turning_the_whole_character_turns_every_vertex_rigidly():
    q = quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), 0.7)
    root = np.eye(4)
    root[:3, :3] = quat.to_matrix(q)
    root[:3, 3] = (0.1, 0.2, -0.3)
    world = CHARACTER.nodes.world(root=root)
    for mesh in CHARACTER.meshes:
        expect = mesh.positions @ root[:3, :3].T + root[:3, 3]
        np.testing.assert_allclose(skin(mesh, world), expect, atol=1e-6)  # float32 bind data


def test_a_hair_joint_moves_only_its_own_bunch():
    hair = next(m for m in CHARACTER.meshes if m.name == "Hair")
    chain = CHARACTER.chains[3]
    rot = CHARACTER.nodes.rotation.copy()
    rot[chain.nodes[1]] = quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), 0.5)
    rest = skin(hair, CHARACTER.nodes.world())
    moved = np.linalg.norm(skin(hair, CHARACTER.nodes.world(rot)) - rest, axis=1) > 0
    own = np.isin(hair.joints, chain.nodes).any(axis=1)
    assert moved.any() and not (moved & ~own).any()
