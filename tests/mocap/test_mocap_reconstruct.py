"""Rebuilding a capture from its key frames."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.mocap import quaternion as quat
from hairtool.mocap.bvh import read_bvh
from hairtool.mocap.costs import joint_position_errors, reconstruct_motion


@pytest.fixture(scope="module")
def walk(motion_dir):
    return read_bvh(motion_dir / "mocapbank_walk.bvh")


@pytest.mark.parametrize("interp", ["linear", "hermite"])
def test_every_frame_a_key_gives_the_capture_back(walk, interp):
    r = reconstruct_motion(walk, np.arange(walk.n_frames), interp)
    assert r.channels == walk.channels and r.n_frames == walk.n_frames
    assert joint_position_errors(walk, r).max() < 1e-9
    # Euler angles come back in each joint's channel order, within whole turns of the originals.
    np.testing.assert_allclose(r.values, walk.values, atol=1e-7)


@pytest.mark.parametrize("interp", ["linear", "hermite"])
def test_keys_are_exact_and_between_is_close(walk, interp):
    keys = np.r_[np.arange(0, walk.n_frames, 10), walk.n_frames - 1]
    r = reconstruct_motion(walk, keys, interp)
    e = joint_position_errors(walk, r)
    assert e.shape == (walk.n_frames, walk.n_joints)
    assert e[keys].max() < 1e-9
    assert 0 < e.mean() < 2.0  # scene units: cm on a ~170-unit skeleton


def test_linear_is_slerp_between_keys(walk):
    r = reconstruct_motion(walk, [0, 20], "linear")
    q0, q20 = walk.local_rotations()[0], walk.local_rotations()[20]
    expect = quat.slerp(q0, q20, 0.35)
    assert np.all(quat.distance(r.local_rotations()[7], expect) < 1e-7)
    np.testing.assert_allclose(
        r.root_translation()[7], 0.65 * walk.root_translation()[0] + 0.35 * walk.root_translation()[20]
    )
    # Frames after the last key hold it.
    np.testing.assert_allclose(r.joint_positions()[30], r.joint_positions()[20], atol=1e-9)


def test_hermite_follows_a_walk_better_than_linear(walk):
    keys = np.r_[np.arange(0, walk.n_frames, 8), walk.n_frames - 1]
    lin = joint_position_errors(walk, reconstruct_motion(walk, keys, "linear")).mean()
    her = joint_position_errors(walk, reconstruct_motion(walk, keys, "hermite")).mean()
    assert her < 0.5 * lin


def test_rebuilt_motion_round_trips_through_bvh(tmp_path, walk):
    from hairtool.mocap.bvh import write_bvh

    r = reconstruct_motion(walk, [0, 100, 200, 454], "hermite")
    write_bvh(tmp_path / "r.bvh", r)
    back = read_bvh(tmp_path / "r.bvh")
    assert joint_position_errors(r, back).max() < 1e-3


def test_bad_keys_and_interp(walk):
    with pytest.raises(ParameterError, match="keys"):
        reconstruct_motion(walk, [0, walk.n_frames])
    with pytest.raises(ParameterError, match="keys"):
        reconstruct_motion(walk, [])
    with pytest.raises(ParameterError, match="keys"):
        reconstruct_motion(walk, [0.5, 3])
    with pytest.raises(ParameterError, match="interp"):
        reconstruct_motion(walk, [0, 3], "cubic")
    short = walk.with_values(walk.values[:5])
    with pytest.raises(ParameterError, match="reconstructed"):
        joint_position_errors(walk, short)
