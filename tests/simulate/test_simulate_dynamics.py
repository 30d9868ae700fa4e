"""Strand dynamics: inextensibility, roots on the head, rest, gusts, collisions, the numpy twin."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.groom import Groom
from hairtool.rotation import axis_angle_matrix
from hairtool.samples import scalp
from hairtool.simulate.dynamics import Gust, gust_schedule, simulate, simulate_reference
from hairtool.simulate.head_motion import head_motion


@pytest.fixture(scope="module")
def groom() -> Groom:
    return scalp(120, 10, seed=2)


def tip_speed(anim) -> np.ndarray:
    """(F−1,) mean tip speed in units/s."""
    tips = anim.frames[:, anim.topology.tip_indices].astype(np.float64)
    return np.linalg.norm(np.diff(tips, axis=0), axis=2).mean(axis=1) * anim.fps


def segment_lengths(anim) -> np.ndarray:
    end = anim.topology.segment_end
    f = anim.frames.astype(np.float64)
    return np.linalg.norm(f[:, end] - f[:, end - 1], axis=2)


@pytest.mark.parametrize("motion", ["turn", "nod", "shake", "hop"])
def test_kernel_matches_numpy_twin(groom, motion):
    kw = dict(motion=motion, frames=16, substeps=4, wind=((1.0, 0.0, 0.5), 40.0), gusts=2, seed=4)
    fast = simulate(groom, **kw)
    slow = simulate_reference(groom, **kw)
    np.testing.assert_allclose(fast.frames, slow.frames, atol=2e-5)


def test_kernel_matches_twin_on_uneven_strands():
    g = Groom.from_strands(
        [np.c_[np.zeros(n), 1.0 - 0.2 * np.arange(n), np.full(n, 0.3 * n)] for n in (2, 5, 9)]
    )
    kw = dict(motion="nod", frames=10, gusts=1, seed=1, collide=False)
    np.testing.assert_allclose(simulate(g, **kw).frames, simulate_reference(g, **kw).frames, atol=2e-5)


def test_same_bits_for_any_thread_count(groom):
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = simulate(groom, motion="shake", frames=12, gusts=1)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = simulate(groom, motion="shake", frames=12, gusts=1)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(one.frames, many.frames)


@pytest.mark.parametrize("motion", ["turn,nod", "shake,hop"])
def test_segments_keep_their_rest_lengths(groom, motion):
    anim = simulate(groom, motion=motion, frames=48, gusts=3, wind=((0, 0, 1), 60.0))
    rest = groom.segment_lengths
    assert np.abs(segment_lengths(anim) - rest).max() < 1e-5 * max(1.0, rest.max())
    assert anim.n_frames == 48 and anim.fps == 24.0


def test_roots_ride_exactly_on_the_moving_head(groom):
    anim = simulate(groom, motion="turn,hop", frames=30)
    head = head_motion("turn,hop", 29 / 24)
    roots = groom.roots.astype(np.float64)
    for f in range(30):
        m = head(f / 24)
        expect = roots @ m[:3, :3].T + m[:3, 3]
        np.testing.assert_allclose(anim.frames[f, groom.topology.root_indices], expect, atol=1e-6)


def test_still_head_without_wind_stays_at_rest(groom):
    anim = simulate(groom, motion="still", frames=48)
    assert np.abs(anim.frames - groom.points).max() < 1e-5
    assert tip_speed(anim).max() < 1e-3


def test_head_motion_moves_the_tips(groom):
    anim = simulate(groom, motion="shake", frames=48)
    assert tip_speed(anim).max() > 1.0


def test_seeded_gusts_are_reproducible_and_differ_by_seed(groom):
    a = simulate(groom, frames=40, gusts=2, seed=7)
    b = simulate(groom, frames=40, gusts=2, seed=7)
    c = simulate(groom, frames=40, gusts=2, seed=8)
    np.testing.assert_array_equal(a.frames, b.frames)
    assert np.abs(a.frames - c.frames).max() > 1e-2
    assert gust_schedule(3, 5.0, 100.0, 0.2, 1) == gust_schedule(3, 5.0, 100.0, 0.2, 1)


def test_a_gust_makes_a_burst_of_tip_speed(groom):
    gust = Gust(start=1.0, duration=0.25, direction=(1.0, 0.0, 0.0), strength=300.0)
    anim = simulate(groom, frames=72, gusts=[gust])
    speed = tip_speed(anim)  # speed[f] is between frames f and f + 1
    before = speed[:24].max()
    during = speed[24:40].max()
    assert before < 1e-3
    assert during > 2.0
    assert speed[-5:].max() < 0.5 * during  # and it settles again


def test_collisions_keep_hair_out_of_the_head():
    # Strands hang beside a unit head; wind blows them sideways into it.
    y = np.linspace(1.0, -1.0, 12)
    g = Groom.from_strands([np.c_[np.full(12, 1.2), y, np.full(12, z)] for z in np.linspace(-0.3, 0.3, 5)])
    still = lambda t: np.eye(4)  # noqa: E731
    kw = dict(motion=still, frames=40, wind=((-1, 0, 0), 300.0))
    free = np.ones(g.vertex_count, dtype=bool)
    free[g.topology.root_indices] = False
    d = np.linalg.norm(simulate(g, **kw).frames[-1], axis=1)
    assert d[free].min() > 0.97
    d_free = np.linalg.norm(simulate(g, collide=False, **kw).frames[-1], axis=1)
    assert d_free[free].min() < 0.8


def test_a_callable_motion_is_followed(groom):
    def spin(t):
        m = np.eye(4)
        m[:3, :3] = axis_angle_matrix((0.0, 1.0, 0.0), 2.0 * t)
        return m

    anim = simulate(groom, motion=spin, frames=12)
    m = spin(11 / 24)
    np.testing.assert_allclose(
        anim.frames[11, groom.topology.root_indices], groom.roots @ m[:3, :3].T.astype(np.float32), atol=1e-5
    )


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        (dict(frames=0), "frames"),
        (dict(substeps=0), "substeps"),
        (dict(fps=float("nan")), "fps"),
        (dict(stiffness=2.0), "stiffness"),
        (dict(damping=-1.0), "damping"),
        (dict(motion="jump"), "motion"),
        (dict(motion=lambda t: np.eye(4) * 2.0), "motion"),
        (dict(wind=((0, 0, 0), 5.0)), "wind direction"),
        (dict(wind=((0, 0, 1), float("inf"))), "wind strength"),
        (dict(wind=5.0), "wind"),
        (dict(gusts=-1), "gusts"),
        (dict(gusts=1, gust_duration=0.0), "gust_duration"),
        (dict(head_center=(0, 0)), "head_center"),
        (dict(gusts=[Gust(0.1, 0.0, (1.0, 0.0, 0.0), 5.0)]), "gust duration"),
        (dict(gusts=["strong"]), "gusts"),
        (dict(backend="gpu"), "backend"),
    ],
)
def test_bad_parameters_name_themselves(groom, kwargs, name):
    with pytest.raises(ParameterError, match=name):
        simulate(groom, **kwargs)
