import functools

import numpy as np
from hypothesis import Phase, given, settings
from hypothesis import strategies as st

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


@functools.cache
def _axes_kernel():
    """The block in a kernel of its own, compiled once (not per example: 200 compiles took 2 min)."""
    from numba import njit

    from hairtool.rotation import perpendicular_axis

    @njit
    def axes(v):
        out = np.empty_like(v)
        for i in range(v.shape[0]):
            out[i, 0], out[i, 1], out[i, 2] = perpendicular_axis(v[i, 0], v[i, 1], v[i, 2])
        return out

    return axes


@settings(max_examples=200, deadline=None, phases=(Phase.explicit, Phase.generate))
@given(
    st.lists(
        st.tuples(
            *[st.floats(-1e3, 1e3).map(lambda x: 0.0 if abs(x) < 1e-6 else x) | st.sampled_from([1.0, -1.0])]
            * 3
        ),
        min_size=1,
        max_size=20,
    )
)
def test_the_kernels_perpendicular_axis_is_any_perpendicular(rows):
    """The one perpendicular-axis block align's and freeze's kernels share is its numpy twin's
    vector (ties between equally small components included; the norms may differ in the last
    bit); a zero vector gives +z."""
    v = np.array(rows, np.float64)
    nonzero = np.any(v != 0, axis=1)
    got = _axes_kernel()(v)
    np.testing.assert_allclose(got[nonzero], any_perpendicular(v[nonzero]), rtol=0, atol=4e-16)
    np.testing.assert_array_equal(got[~nonzero], np.tile([0.0, 0.0, 1.0], ((~nonzero).sum(), 1)))
