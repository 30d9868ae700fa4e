"""Kernel bodies run as plain Python (what NUMBA_DISABLE_JIT would run) and across thread counts."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from hairtool.kernel_arrays import readonly
from hairtool.keys.costs import cost_table
from hairtool.keys.dp import _layer_block, _penalty_kernel
from hairtool.keys.features import _resample_kernel
from hairtool.keys.gram import centered_gram, frame_curvature
from hairtool.keys.segment_hermite import _hermite_kernel, hermite_quad_weights
from hairtool.keys.segment_linear import _linear_kernel
from hairtool.keys.segment_worst import _worst_kernel


def walk(n: int, d: int, seed: int = 0) -> np.ndarray:
    return np.cumsum(np.random.default_rng(seed).normal(size=(n, d)), axis=0)


def test_python_bodies_match_the_compiled_kernels():
    x = walk(14, 3, seed=1)
    g, c = centered_gram(x), frame_curvature(x)
    np.testing.assert_allclose(
        _linear_kernel.py_func(g, c, 0.5), _linear_kernel(g, c, 0.5), rtol=1e-13, atol=1e-12
    )
    q = hermite_quad_weights(14)
    np.testing.assert_allclose(
        _hermite_kernel.py_func(g, c, 0.5, q), _hermite_kernel(g, c, 0.5, q), rtol=1e-13, atol=1e-12
    )
    for herm in (False, True):  # rows dealt into 3 hands in Python, 2 compiled: the same table
        slow, fast = _worst_kernel.py_func(g, c, 0.5, herm, 3), _worst_kernel(g, c, 0.5, herm, 2)
        np.testing.assert_allclose(slow, fast, rtol=1e-13, atol=1e-12)
    ct = np.ascontiguousarray(cost_table(x).T)
    for use_max in (False, True):
        a, b = [(np.full((15, 14), np.inf), np.full((15, 14), -1)) for _ in range(2)]
        for e, _ in (a, b):
            e[1, 0] = 0.0
        for k0, k1 in ((2, 9), (9, 15)):  # the Python function and the compiled one, block by block
            _layer_block.py_func(ct, *a, k0, k1, use_max)
            _layer_block(ct, *b, k0, k1, use_max)
        np.testing.assert_array_equal(a[0], b[0])
        np.testing.assert_array_equal(a[1], b[1])
    np.testing.assert_array_equal(_penalty_kernel.py_func(ct, 1.0)[1], _penalty_kernel(ct, 1.0)[1])
    frames = readonly(np.random.default_rng(2).normal(size=(3, 12, 3)).astype(np.float32))  # as features'
    off = np.array([0, 5, 12])
    out_py, out_jit = np.empty((3, 2, 4, 3)), np.empty((3, 2, 4, 3))
    _resample_kernel.py_func(frames, off, np.linspace(0, 1, 4), out_py)
    _resample_kernel(frames, off, np.linspace(0, 1, 4), out_jit)
    np.testing.assert_allclose(out_py, out_jit, rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize("interp", ["linear", "hermite"])
def test_tables_are_bit_identical_whatever_the_thread_count(interp):
    x = walk(90, 7, seed=3)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = cost_table(x, interp, 0.2)
        worst_one = cost_table(x, interp, 0.2, "worst")
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = cost_table(x, interp, 0.2)
        worst_many = cost_table(x, interp, 0.2, "worst")
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(one, many)
    np.testing.assert_array_equal(worst_one, worst_many)
