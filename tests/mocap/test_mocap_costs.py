"""Seed-003 segment costs: the numba kernel against its numpy twin, and the metric's properties."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.mocap import quaternion as quat
from hairtool.mocap.bvh import Motion, read_bvh
from hairtool.mocap.costs import (
    bvh_features,
    joint_weights,
    motion_features,
    rotation_cost_table,
    rotation_cost_table_reference,
    skeleton_size,
)


def random_motion(frames=30, seed=0):
    """Three joints in a chain with wandering Euler angles (XYZ, ZXY, YZX) and a root translation."""
    rng = np.random.default_rng(seed)
    rot = np.cumsum(rng.normal(scale=12.0, size=(frames, 9)), axis=0)
    pos = np.cumsum(rng.normal(scale=0.3, size=(frames, 3)), axis=0)
    chans = [
        ["Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"],
        ["Zrotation", "Xrotation", "Yrotation"],
        ["Yrotation", "Zrotation", "Xrotation"],
    ]
    values = np.concatenate([pos, rot], axis=1)
    return Motion(["a", "b", "c"], [-1, 0, 1], [[0, 0, 0], [0, 1, 0], [0, 1, 0]], chans, values, 1 / 30)


@pytest.fixture(scope="module")
def walk(motion_dir):
    m = read_bvh(motion_dir / "mocapbank_walk.bvh")
    return m.with_values(m.values[:50])


# Float64 rounding: each term Dist² moves by ~2 ulp of q_k·slerp (about 4e-16) whatever the
# order of operations, and the rotation steps add a few ulp per frame; the old arccos polynomial
# (good to 2e-8 rad) was off by 3e-8 relative.
EXACT = {"rtol": 1e-10, "atol": 1e-12}


def test_kernel_matches_numpy_twin_on_random_motion():
    m = random_motion()
    fast = rotation_cost_table(m)
    slow = rotation_cost_table_reference(m)
    np.testing.assert_allclose(fast, slow, **EXACT)
    assert fast.max() > 0.1


def test_kernel_matches_numpy_twin_on_a_real_capture(walk):
    w = np.random.default_rng(5).uniform(0.1, 1.0, walk.n_joints)
    fast = rotation_cost_table(walk, weights=w, translation_weight=0.3)
    slow = rotation_cost_table_reference(walk, weights=w, translation_weight=0.3)
    np.testing.assert_allclose(fast, slow, **EXACT)


@pytest.mark.parametrize("name", ["mocapbank_walk", "pymo_walk", "freebvh"])
def test_kernel_matches_numpy_twin_on_every_capture(motion_dir, name):
    m = read_bvh(motion_dir / f"{name}.bvh")
    m = m.with_values(m.values[:70])
    fast, slow = rotation_cost_table(m), rotation_cost_table_reference(m)
    np.testing.assert_allclose(fast, slow, **EXACT)
    iu = np.triu_indices(m.n_frames, 2)
    assert np.max(np.abs(fast[iu] - slow[iu]) / slow[iu]) < 1e-7  # even the smallest entries


def test_kernel_matches_numpy_twin_across_blocks_of_ends(motion_dir):
    """Rows longer than a block of segment ends (512) run several blocks, each from an aligned lane."""
    from hairtool.mocap.costs import _BLOCK, _cost_inputs, _pair_cost_reference

    m = read_bvh(motion_dir / "pymo_walk.bvh")
    n = 2 * _BLOCK + 30  # the walk has 1,064 frames
    m = m.with_values(m.values[:n])
    fast = rotation_cost_table(m)
    q, p, w, wt = _cost_inputs(m, None, None)
    pairs = [(0, _BLOCK - 1), (0, _BLOCK), (0, _BLOCK + 1), (0, n - 1), (1, n - 1), (5, 2 * _BLOCK + 3)]
    for i, j in [*pairs, (400, n - 2)]:
        assert fast[i, j] == pytest.approx(_pair_cost_reference(q, p, w, wt, i, j), rel=1e-12)


def test_coordinates_across_a_quaternion_are_an_orthonormal_basis():
    from hairtool.mocap.costs import _across

    rng = np.random.default_rng(11)
    q = rng.normal(size=(1, 6, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    qi = q[0, 0]
    basis = np.array([_across(np.eye(4)[None], 0, k, *qi) for k in range(4)]).T  # rows: q_i, then across
    np.testing.assert_allclose(basis @ basis.T, np.eye(4), atol=1e-15)
    np.testing.assert_allclose(basis[0], qi, atol=1e-15)
    for k in range(1, 6):  # the coordinates of q_k are its products with the basis
        np.testing.assert_allclose(_across(q, 0, k, *qi), basis @ q[0, k], atol=1e-15)


def test_arccos_squared_polynomials_are_exact_to_rounding():
    from hairtool.mocap.costs import _acos2_far, _acos2_mid, _acos2_near, acos2_reference

    for poly, top in ((_acos2_near, 1 / 16), (_acos2_mid, 1 / 4), (_acos2_far, 1.0)):
        u = np.concatenate([np.linspace(0.0, top, 4001), np.geomspace(1e-17, top, 400)])
        got = np.array([poly(v) for v in u])
        exact = acos2_reference(u)
        assert got[0] == 0.0
        assert np.max(np.abs(got[1:] - exact[1:]) / exact[1:]) < 4e-15


def test_max_span_marks_far_pairs_infinite(walk):
    fast = rotation_cost_table(walk, max_span=7)
    slow = rotation_cost_table_reference(walk, max_span=7)
    far = np.abs(np.subtract.outer(np.arange(50), np.arange(50))) > 7
    assert np.all(np.isinf(fast[far])) and np.all(np.isfinite(fast[~far]))
    np.testing.assert_allclose(fast[~far], slow[~far], **EXACT)
    np.testing.assert_allclose(fast[~far], rotation_cost_table(walk)[~far], rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("max_span", [None, 9])
def test_a_table_made_in_row_ranges_for_a_progress_bar_is_the_same(motion_dir, max_span):
    m = read_bvh(motion_dir / "pymo_walk.bvh")
    m = m.with_values(m.values[:300])
    shares = []
    made = rotation_cost_table(m, max_span=max_span, progress=shares.append)
    assert made.tobytes() == rotation_cost_table(m, max_span=max_span).tobytes()
    assert len(shares) >= 15 and shares == sorted(shares) and shares[-1] == 1.0


def test_table_is_symmetric_with_free_neighbours(walk):
    c = rotation_cost_table(walk)
    np.testing.assert_array_equal(c, c.T)
    assert np.all(np.diag(c) == 0) and np.all(np.diag(c, 1) == 0)
    assert np.all(c[np.triu_indices(50, 2)] > 0)
    # A longer segment never costs less than a shorter one it contains, on this smooth capture's start.
    assert c[0, 10] > c[0, 3]


def test_geodesic_motion_costs_nothing():
    # Constant angular velocity about one axis and constant root velocity: slerp and lerp are exact.
    f = 20
    angles = np.linspace(0.0, 150.0, f)
    values = np.column_stack(
        [np.linspace(0, 3, f), np.zeros(f), np.zeros(f), angles, np.zeros(f), np.zeros(f)]
    )
    chans = [["Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation"]]
    m = Motion(["a"], [-1], [[0, 0, 0]], chans, values, 0.1)
    assert np.abs(rotation_cost_table(m)).max() < 1e-10
    assert np.abs(rotation_cost_table_reference(m)).max() < 1e-10


def test_cost_is_the_seed_formula_for_one_segment():
    m = random_motion(frames=6, seed=3)
    w = joint_weights(m)
    q = quat.align_hemisphere(m.local_rotations(), axis=0)
    p = m.root_translation() / skeleton_size(m)
    i, j = 0, 5
    total = 0.0
    for k in range(1, 5):
        s = quat.slerp(q[i], q[j], (k - i) / (j - i))
        total += np.sum(w * quat.distance(q[k], s) ** 2)
        total += w[0] * np.sum((p[k] - (p[i] + (k - i) / (j - i) * (p[j] - p[i]))) ** 2)
    assert rotation_cost_table(m)[0, 5] == pytest.approx(total, rel=1e-12)


def test_same_bits_for_any_thread_count(walk):
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = rotation_cost_table(walk)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = rotation_cost_table(walk)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(one, many)


def test_joint_weights_favour_the_trunk(walk):
    w = joint_weights(walk)
    assert w.sum() == pytest.approx(1.0)
    d = walk.depths()
    assert np.all(w[d == 0] > w[d == 1].max())
    np.testing.assert_allclose(joint_weights(walk, falloff=1.0), 1.0 / walk.n_joints)
    with pytest.raises(ParameterError, match="falloff"):
        joint_weights(walk, falloff=0.0)


def test_position_features_carry_the_weights(walk):
    w = joint_weights(walk)
    x = motion_features(walk, "positions")
    assert x.shape == (50, 3 * walk.n_joints) and x.dtype == np.float64
    p = walk.joint_positions()
    rel = p - p[:, :1]
    d2 = np.sum(w * np.sum((rel[3] - rel[9]) ** 2, axis=-1)[None], axis=1)[0]
    d2 += w[0] * np.sum((p[3, 0] - p[9, 0]) ** 2)
    assert np.sum((x[3] - x[9]) ** 2) == pytest.approx(d2)


def test_rotation_features_are_sign_continuous(walk):
    x = motion_features(walk, "rotations")
    assert x.shape == (50, 4 * walk.n_joints + 3)
    q = x[:, : 4 * walk.n_joints].reshape(50, walk.n_joints, 4)
    assert np.all(np.sum(q[1:] * q[:-1], axis=-1) >= 0)


def test_bvh_features_reads_the_file(motion_dir):
    x = bvh_features(motion_dir / "freebvh.bvh")
    assert x.shape == (69, 55 * 3) and np.all(np.isfinite(x))


def test_bad_arguments(walk):
    with pytest.raises(ParameterError, match="kind"):
        motion_features(walk, "angles")
    with pytest.raises(ParameterError, match="weights"):
        motion_features(walk, weights=np.ones(3))
    with pytest.raises(ParameterError, match="weights"):
        rotation_cost_table(walk, weights=np.full(walk.n_joints, np.nan))
    with pytest.raises(ParameterError, match="interp"):
        rotation_cost_table(walk, interp="squad")
    with pytest.raises(ParameterError, match="max_span"):
        rotation_cost_table(walk, max_span=0)


def test_long_segments_across_the_kernel_blocks_match_the_seed_formula():
    # Ends 512 frames and more from the start fall in the kernel's second block of segment ends,
    # and the cos/sin recurrence runs over hundreds of steps: both must stay exact to the twin.
    m = random_motion(frames=560, seed=4)
    w = joint_weights(m)
    q = quat.align_hemisphere(m.local_rotations(), axis=0)
    p = m.root_translation() / skeleton_size(m)
    table = rotation_cost_table(m)
    for i, j in [(0, 559), (0, 513), (1, 514), (3, 300), (40, 555)]:
        t = (np.arange(i + 1, j) - i) / (j - i)
        s = quat.slerp(q[i][None], q[j][None], t[:, None])
        d = quat.distance(q[i + 1 : j], s)
        lin = p[i] + t[:, None] * (p[j] - p[i])
        total = np.sum(w * d * d) + w[0] * np.sum((p[i + 1 : j] - lin) ** 2)
        assert table[i, j] == pytest.approx(total, rel=1e-7)
