"""Inverse kinematics on real capture poses: reach, bone lengths, the two solvers, Euler angles."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.mocap import ik
from hairtool.mocap import quaternion as quat
from hairtool.mocap.bvh import read_bvh

CAPTURES = {
    "pymo_walk.bvh": ("LeftHand", "RightFoot"),
    "mocapbank_walk.bvh": ("LeftWrist", "RightAnkle"),
    "freebvh.bvh": ("mixamorig:LeftHand", "mixamorig:RightFoot"),
}


@pytest.fixture(scope="module", params=sorted(CAPTURES))
def capture(request, motion_dir):
    return request.param, read_bvh(motion_dir / request.param)


def _positions(m, values):
    return m.with_values(np.asarray(values)[None]).joint_positions()[0]


def _bones(m, values):
    """Every joint's distance to its parent: what rotations must not change."""
    p = _positions(m, values)
    return np.linalg.norm(p[1:] - p[m.parents[1:]], axis=1)


def _target(m, frame, joint, push):
    h = ik.figure_height(m)
    return _positions(m, m.values[frame])[joint] + np.asarray(push) * h


@pytest.mark.parametrize("method,chain", [("two-bone", 2), ("dls", 2), ("dls", 3), ("dls", 4)])
def test_the_effector_reaches_its_target_and_the_bones_keep_their_lengths(capture, method, chain):
    name, m = capture
    h = ik.figure_height(m)
    asked = chain
    for joint_name in CAPTURES[name]:
        chain = asked
        e = m.joint_names.index(joint_name)
        f = m.n_frames // 3
        chain = min(chain, int(m.depths()[e]))  # a foot three joints below the root
        target = _target(m, f, e, [0.04, 0.06, -0.03])
        s = ik.solve(m, m.values[f], e, chain, target, method=method)
        p = _positions(m, s.values)
        assert np.linalg.norm(p[e] - target) < 1e-4 * h
        assert s.miss < 1e-4 * h
        np.testing.assert_allclose(_bones(m, s.values), _bones(m, m.values[f]), rtol=0, atol=1e-9 * h)
        turned = ik.ancestors(m, e, chain)
        cols = [c for j in turned for c in ik.rotation_columns(m, j)[0]]
        untouched = np.setdiff1d(np.arange(m.n_channels), cols)
        assert np.array_equal(s.values[untouched], m.values[f][untouched])  # root translation too
        # The new angles stay near the old ones: no whole turns added.
        assert np.max(np.abs(s.values - m.values[f])) < 90.0


def test_two_bone_and_dls_agree_on_a_two_joint_chain(capture):
    """Both put the effector on the target; both middle joints lie on the one circle a two-bone
    limb allows (at bone length from the top joint and from the target); the analytic one is the
    point of that circle nearest where the middle joint was (the pole is the current bend)."""
    name, m = capture
    h = ik.figure_height(m)
    for joint_name in CAPTURES[name]:
        e = m.joint_names.index(joint_name)
        mid, top = ik.ancestors(m, e, 2)
        f = m.n_frames // 2
        before = _positions(m, m.values[f])
        target = _target(m, f, e, [-0.05, 0.05, 0.04])
        two = ik.solve(m, m.values[f], e, 2, target, method="two-bone")
        dls = ik.solve(m, m.values[f], e, 2, target, method="dls")
        assert two.iterations == 0 and two.method == "two-bone"
        a = np.linalg.norm(before[mid] - before[top])
        b = np.linalg.norm(before[e] - before[mid])
        elbows = []
        for s in (two, dls):
            p = _positions(m, s.values)
            assert np.linalg.norm(p[e] - target) < 1e-4 * h
            assert np.linalg.norm(p[top] - before[top]) < 1e-9 * h  # the top joint does not move
            assert np.linalg.norm(p[mid] - p[top]) == pytest.approx(a, abs=1e-9 * h)
            assert np.linalg.norm(p[mid] - target) == pytest.approx(b, abs=2e-4 * h)
            elbows.append(p[mid])
        moved = [np.linalg.norm(x - before[mid]) for x in elbows]
        assert moved[0] <= moved[1] + 1e-9 * h


def test_an_unreachable_target_straightens_the_limb_towards_it(capture):
    name, m = capture
    e = m.joint_names.index(CAPTURES[name][0])
    mid, top = ik.ancestors(m, e, 2)
    f = 0
    p = _positions(m, m.values[f])
    reach = np.linalg.norm(p[mid] - p[top]) + np.linalg.norm(p[e] - p[mid])
    direction = (p[e] - p[top]) / np.linalg.norm(p[e] - p[top])
    target = p[top] + 3.0 * reach * direction
    s = ik.solve(m, m.values[f], e, 2, target)
    q = _positions(m, s.values)
    assert np.linalg.norm(q[e] - q[top]) == pytest.approx(reach, rel=1e-6)
    assert s.miss == pytest.approx(2.0 * reach, rel=1e-5)


def test_euler_nearest_picks_the_representation_nearest_the_reference():
    rng = np.random.default_rng(4)
    for order in ("ZXY", "XYZ", "YZX", "ZYX"):
        for _ in range(50):
            ang = rng.uniform(-170, 170, 3)
            q = quat.from_euler(ang, order)
            # The other Euler family, shifted by whole turns, is the same rotation: the nearest
            # representation to a reference near it is that one, not the principal angles.
            other = np.array([ang[0] + 180.0, 180.0 - ang[1], ang[2] + 180.0])
            other += 360.0 * rng.integers(-2, 3, 3)
            for ref in (ang + rng.normal(0, 5, 3), other + rng.normal(0, 5, 3)):
                got = ik.euler_nearest(q, order, ref)
                assert quat.distance(quat.from_euler(got, order), q) < 1e-7
                want = ang if np.linalg.norm(ref - ang) < np.linalg.norm(ref - other) else other
                np.testing.assert_allclose(got, want, atol=1e-6)


def test_chains_longer_than_the_ancestors_and_bad_targets_are_refused(motion_dir):
    m = read_bvh(motion_dir / "mocapbank_walk.bvh")
    e = m.joint_names.index("LeftWrist")
    depth = int(m.depths()[e])
    with pytest.raises(ParameterError, match="chain"):
        ik.solve(m, m.values[0], e, depth + 1, [0, 0, 0])
    with pytest.raises(ParameterError, match="target"):
        ik.solve(m, m.values[0], e, 2, [0, np.nan, 0])
    with pytest.raises(ParameterError, match="method"):
        ik.solve(m, m.values[0], e, 2, [0, 0, 0], method="ccd")
    # The whole chain up to the root turns the body about the root, which keeps its place.
    s = ik.solve(m, m.values[0], e, depth, _target(m, 0, e, [0.05, 0.0, 0.05]))
    assert s.miss < 1e-4 * ik.figure_height(m)
    assert np.array_equal(s.values[:3], m.values[0][:3])


def test_euler_follow_stays_on_the_side_of_gimbal_lock_the_turn_takes():
    """A turn that brings the middle angle near −90° and back ends where it started, though the
    nearest triple to the start may be the other family after a long way round."""
    start = np.array([10.0, -40.0, 5.0])
    for end_angles in ([140.0, -80.0, 150.0], [15.0, -50.0, 0.0], [-30.0, 20.0, 60.0]):
        q = quat.from_euler(end_angles, "XYZ")
        got = ik.euler_follow(start, q, "XYZ")
        assert quat.distance(quat.from_euler(got, "XYZ"), q) < 1e-7
        np.testing.assert_allclose(got, end_angles, atol=1e-6)
    # Small turns: the nearest triple.
    q = quat.from_euler(start + 1.0, "XYZ")
    np.testing.assert_allclose(ik.euler_follow(start, q, "XYZ"), ik.euler_nearest(q, "XYZ", start))
