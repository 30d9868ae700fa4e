"""Quaternion utilities against rotation matrices built independently (Rodrigues)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.mocap import quaternion as quat
from hairtool.rotation import axis_angle_matrix

AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
ORDERS = ["".join(p) for p in itertools.permutations("XYZ")]


def euler_matrix(angles_deg, order):
    m = np.eye(3)
    for a, c in zip(angles_deg, order, strict=True):
        m = m @ axis_angle_matrix(AXES[c], np.radians(a))
    return m


@pytest.mark.parametrize("order", ORDERS)
def test_from_euler_is_the_intrinsic_product_in_channel_order(order):
    rng = np.random.default_rng(1)
    angles = rng.uniform(-170, 170, (20, 3))
    q = quat.from_euler(angles, order)
    for a, qq in zip(angles, q, strict=True):
        np.testing.assert_allclose(quat.to_matrix(qq), euler_matrix(a, order), atol=1e-12)


def test_single_axis_rotation_by_hand():
    # 90° about z takes x to y.
    q = quat.from_euler([[90.0]], "Z")[0]
    np.testing.assert_allclose(quat.rotate(q, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0], atol=1e-12)
    # ZX: first the x-rotation is applied to the vector, then z (R = Rz · Rx).
    q = quat.from_euler([[90.0, 90.0]], "ZX")[0]
    np.testing.assert_allclose(quat.rotate(q, [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0], atol=1e-12)


@pytest.mark.parametrize("order", ORDERS)
def test_to_euler_round_trip_including_gimbal_lock(order):
    rng = np.random.default_rng(2)
    angles = rng.uniform(-179, 179, (50, 3))
    angles[:, 1] = rng.uniform(-89, 89, 50)
    back = quat.to_euler(quat.from_euler(angles, order), order)
    np.testing.assert_allclose(back, angles, atol=1e-8)
    lock = np.array([[30.0, 90.0, 0.0], [-40.0, -90.0, 0.0]])
    q = quat.from_euler(lock, order)
    np.testing.assert_allclose(
        quat.to_matrix(quat.from_euler(quat.to_euler(q, order), order)), quat.to_matrix(q), atol=1e-7
    )


def test_multiply_inverse_and_rotate():
    rng = np.random.default_rng(3)
    a = quat.normalize(rng.normal(size=(10, 4)))
    b = quat.normalize(rng.normal(size=(10, 4)))
    np.testing.assert_allclose(
        quat.to_matrix(quat.multiply(a, b)), quat.to_matrix(a) @ quat.to_matrix(b), atol=1e-12
    )
    np.testing.assert_allclose(quat.multiply(a, quat.inverse(a)), quat.identity((10,)), atol=1e-12)
    v = rng.normal(size=(10, 3))
    np.testing.assert_allclose(quat.rotate(a, v), np.einsum("nij,nj->ni", quat.to_matrix(a), v), atol=1e-12)


def test_distance_is_half_the_rotation_angle_and_ignores_sign():
    q1 = quat.from_axis_angle([0.0, 0.0, 1.0], 0.3)
    q2 = quat.from_axis_angle([0.0, 0.0, 1.0], 1.1)
    assert quat.distance(q1, q2) == pytest.approx(0.4)
    assert quat.distance(q1, -q2) == pytest.approx(0.4)
    assert quat.distance(q1, q1) == pytest.approx(0.0, abs=1e-7)


def test_slerp_ends_midpoint_and_short_arc():
    q1 = quat.from_axis_angle([1.0, 0.0, 0.0], 0.2)
    q2 = quat.from_axis_angle([1.0, 0.0, 0.0], 1.0)
    np.testing.assert_allclose(quat.slerp(q1, q2, 0.0), q1, atol=1e-12)
    np.testing.assert_allclose(quat.slerp(q1, q2, 1.0), q2, atol=1e-12)
    np.testing.assert_allclose(
        quat.slerp(q1, q2, 0.25), quat.from_axis_angle([1.0, 0.0, 0.0], 0.4), atol=1e-12
    )
    # −q2 is the same rotation: slerp still takes the short way.
    mid = quat.slerp(q1, -q2, 0.5)
    assert quat.distance(mid, quat.from_axis_angle([1.0, 0.0, 0.0], 0.6)) < 1e-7
    np.testing.assert_allclose(quat.slerp(q1, q1, 0.5), q1, atol=1e-12)


def test_align_hemisphere_makes_neighbours_agree():
    rng = np.random.default_rng(4)
    walk = np.cumsum(rng.normal(scale=0.05, size=(40, 3, 4)), axis=0)
    q = quat.normalize(walk + np.array([1.0, 0.0, 0.0, 0.0]))
    flipped = q * rng.choice([-1.0, 1.0], size=(40, 3, 1))
    a = quat.align_hemisphere(flipped, axis=0)
    assert np.all(np.sum(a[1:] * a[:-1], axis=-1) >= 0)
    np.testing.assert_allclose(np.abs(np.sum(a * q, axis=-1)), 1.0, atol=1e-12)


def test_bad_orders_are_parameter_errors():
    with pytest.raises(ParameterError, match="order"):
        quat.from_euler([[1.0, 2.0]], "XQ")
    with pytest.raises(ParameterError, match="angles"):
        quat.from_euler([[1.0, 2.0]], "XYZ")
    with pytest.raises(ParameterError, match="order"):
        quat.to_euler(quat.identity((1,)), "XYX")
