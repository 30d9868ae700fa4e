"""The twins' arithmetic (:mod:`hairtool.frozen.brushes.twin_math`) equals a numba kernel's bit for
bit, where numpy's BLAS-backed ``dot``/``norm`` and pairwise ``sum`` need not; and the faint comb
sample that found the difference (strength 1e-5, a cursor coordinate of 1e-267: a length restore
cancels to ~1e-19 and shows the last bits) gives the kernel's bytes, on the contract test's comb
and on strands of more than 8 segments (where ``sum`` adds pairwise)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from numba import njit

from hairtool import samples
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.brushes.comb import comb, comb_reference
from hairtool.frozen.brushes.pinch import pinch, pinch_reference
from hairtool.frozen.brushes.smooth import smooth, smooth_reference
from hairtool.frozen.brushes.twin_math import dot3, norm3, running_sum

FINITE = st.floats(-1e150, 1e150, allow_nan=False, allow_infinity=False)


@njit(cache=True)
def _kernel_norms(v, out):
    for i in range(v.shape[0]):
        out[i] = np.sqrt(v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1] + v[i, 2] * v[i, 2])


@njit(cache=True)
def _kernel_total(x):
    t = 0.0
    for v in x:
        t += v
    return t


@settings(max_examples=60, deadline=None)
@given(v=arrays(np.float64, st.tuples(st.integers(1, 6), st.just(3)), elements=FINITE))
def test_norm3_and_dot3_are_the_kernels_sums_of_three_products(v):
    out = np.empty(len(v))
    _kernel_norms(v, out)
    assert norm3(v).tobytes() == out.tobytes()
    assert np.array([norm3(r) for r in v]).tobytes() == out.tobytes()  # one vector at a time too
    w = v[::-1]
    dots = np.array([w[i, 0] * v[i, 0] + w[i, 1] * v[i, 1] + w[i, 2] * v[i, 2] for i in range(len(v))])
    assert dot3(w, v).tobytes() == dots.tobytes()


@settings(max_examples=60, deadline=None)
@given(x=arrays(np.float64, st.integers(0, 40), elements=st.floats(-1e3, 1e3)))
def test_running_sum_ends_on_the_kernels_total(x):
    r = running_sum(x)
    assert r[0] == 0.0 and len(r) == len(x) + 1
    assert r[-1].tobytes() == np.float64(_kernel_total(x)).tobytes()


def faint_comb(vertices: int) -> tuple:
    groom = samples.comb(strands=25, vertices=vertices, spacing=0.1)
    sample = BrushSample(
        "comb", (0.1930212943374528, -2.0888861378345367e-267, -0.04665591384985747),
        (0.12663468725206878, 0.038018302699619755, -0.23537338401379593), 0.6406959513611937,
        1e-05, tuple(falloff_lut("smooth").tolist()), None, False, True,
    )  # fmt: skip
    return groom, sample, np.zeros(groom.strand_count, bool)


def test_the_faint_comb_sample_gives_the_kernels_bytes_in_its_twin():
    for vertices in (8, 20):
        groom, sample, locked = faint_comb(vertices)
        kernel, twin = comb(groom, sample, locked), comb_reference(groom, sample, locked)
        assert kernel.points.tobytes() == twin.points.tobytes()


def test_the_length_keeping_twins_agree_on_long_strands():
    """Smooth and pinch end with the same length restore as comb (20 vertices: 19 segments)."""
    groom, sample, locked = faint_comb(20)
    centre = np.zeros(3)
    for name, kernel, twin in (("smooth", smooth, smooth_reference), ("pinch", pinch, pinch_reference)):
        s = replace(sample, brush=name, strength=0.7)
        got, want = kernel(groom, s, locked, centre), twin(groom, s, locked, centre)
        assert got.points.tobytes() == want.points.tobytes()
