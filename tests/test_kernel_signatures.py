"""A kernel compiles once per dtype, whatever the write flag or memory order of the caller's
arrays: numba types both, and each variant is a compile of its own (seconds for a parallel
kernel, on a studio's first run and on every fresh clone's test run, where the variants the
tests' own writable arrays asked for took about a hundred compiles). Each public entry here is
called with a writable, a read-only and (where it takes any) a Fortran-ordered copy of the same
input; every signature its kernel holds afterwards takes that input read-only and C-ordered, and
the answers agree bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.anime import pose
from hairtool.anime.schedule import schedule
from hairtool.anime.wave import WaveParams, make_bunches, pose_pictures
from hairtool.bounds import _box, box
from hairtool.guides import child_clumps, children
from hairtool.guides.binding import bind_roots
from hairtool.keys import features


def variants(a: np.ndarray, fortran: bool = True) -> list[np.ndarray]:
    """``a`` writable, read-only and (``fortran``) in Fortran order: the same values."""
    ro = a.copy()
    ro.flags.writeable = False
    return [a.copy(), ro, *([np.asfortranarray(a)] if fortran else [])]


def argument_types(kernel, index: int) -> list:
    return [sig[index] for sig in kernel.signatures]


def assert_one_signature(kernel, index: int) -> None:
    kinds = argument_types(kernel, index)
    assert kinds, "the kernel ran"
    assert all(t.layout == "C" and not t.mutable for t in kinds), kinds


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_box(dtype):
    p = np.random.default_rng(1).standard_normal((40, 3)).astype(dtype)
    got = [box(a) for a in variants(p)]
    assert all(np.array_equal(g[0], got[0][0]) and np.array_equal(g[1], got[0][1]) for g in got)
    assert_one_signature(_box, 0)


def test_resampled_frames():
    frames = np.random.default_rng(2).standard_normal((3, 9, 3)).astype(np.float32)
    counts = np.array([4, 5])
    got = [features.resample_frames(f, counts, 6) for f in variants(frames, fortran=False)]
    assert all(np.array_equal(g, got[0]) for g in got)
    assert_one_signature(features._resample_kernel, 0)


def test_pose_times():
    g = samples.scalp(12, 6, seed=3)
    params = WaveParams(1.5, 0.4, -0.9, 2.5, 0.8)
    bunches = make_bunches(g, seed=11, amplitude_spread=0.5, phase_spread=1.0)
    times = schedule(params.period, 6, 2).picture_times
    got = [pose_pictures(g, params, t, bunches) for t in variants(np.asarray(times), fortran=False)]
    assert all(np.array_equal(x, got[0]) for x in got)
    assert_one_signature(pose._pose_kernel, 6)


def test_children_and_their_clumps():
    guides = samples.scalp(8, 5, seed=3)
    b = bind_roots(guides, count=40, seed=4)
    kids = b.build()
    got = []
    for p in variants(kids.points, fortran=False):  # the studio's live points are writable
        run = child_clumps.ChildClumps(b.guide_ids, 8, 0.08, 2, None, "printed", 1, False)
        got.append(run.run(p, kids.topology).copy())
    assert all(np.array_equal(x, got[0]) for x in got)
    assert_one_signature(child_clumps._clumps_kernel, 0)
    assert_one_signature(child_clumps._clumps_kernel, 1)
    assert_one_signature(children._children_kernel, 10)
