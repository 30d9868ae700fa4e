import numpy as np

from hairtool.rotation import any_perpendicular, axis_angle_matrix, normalize, rotate


def test_rotate_matches_matrix_and_keeps_length():
    rng = np.random.default_rng(0)
    v = rng.normal(size=(50, 3))
    a = normalize(rng.normal(size=(50, 3)))
    th = rng.uniform(-np.pi, np.pi, 50)
    r = rotate(v, a, th)
    for i in range(50):
        np.testing.assert_allclose(r[i], axis_angle_matrix(a[i], th[i]) @ v[i], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(r, axis=1), np.linalg.norm(v, axis=1))


def test_quarter_turn_about_z():
    np.testing.assert_allclose(rotate([1.0, 0, 0], [0, 0, 1.0], np.pi / 2), [0, 1, 0], atol=1e-15)


def test_perpendicular_is_unit_and_orthogonal():
    v = np.array([[1.0, 0, 0], [0, 0, 2], [1, 1, 1], [1e-9, 1, 0]])
    p = any_perpendicular(v)
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), 1)
    np.testing.assert_allclose(np.sum(p * v, axis=1), 0, atol=1e-12)
    np.testing.assert_array_equal(normalize(np.zeros((1, 3))), 0)
