"""The BVH of the hair chains: read back, its forward kinematics puts every node where the character does."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hairtool.character import load_character
from hairtool.character.bvh import write_chains_bvh
from hairtool.character.cycle import chain_points, character_cycle
from hairtool.character.springs import head_shake, simulate
from hairtool.mocap.bvh import read_bvh

CHARACTER = load_character(Path(__file__).resolve().parents[1] / "data" / "characters" / "bunches.vrm")


def _check(tmp_path, rotations):
    path = tmp_path / "hair.bvh"
    write_chains_bvh(path, CHARACTER, rotations, 24.0)
    motion = read_bvh(path)
    assert motion.n_frames == len(rotations) and motion.fps == 24.0
    got = motion.joint_positions(end_sites=True)
    world = CHARACTER.nodes.world(rotations)
    for ch in CHARACTER.chains:
        expect = chain_points(CHARACTER, ch, world)
        rows = [motion.joint_names.index(CHARACTER.nodes.names[j]) for j in ch.nodes[:-1]]
        end = motion.n_joints + CHARACTER.chains.index(ch)
        np.testing.assert_allclose(got[:, [*rows, end]], expect, atol=2e-5)  # 6 decimals in the file


def test_the_cycles_chains_read_back_where_they_are(tmp_path):
    cyc = character_cycle(CHARACTER)
    _check(tmp_path, cyc.frames())


def test_a_shaken_heads_springs_read_back_where_they_are(tmp_path):
    _check(tmp_path, simulate(CHARACTER, head_shake(CHARACTER, 6, 24.0, turn_deg=40.0), 24.0))
