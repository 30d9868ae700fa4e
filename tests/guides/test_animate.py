"""Render-hair animations: the children of a binding over an animation of its guides, and their
USD export with the guides as a second prim, written one frame at a time."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from hairtool import io, samples
from hairtool.errors import Cancelled, ParameterError
from hairtool.groom import Animation
from hairtool.guides.animate import RenderHairAnimation, render_frames_reference
from hairtool.guides.binding import bind_dense, bind_roots
from hairtool.guides.files import GUIDES_PRIM, HAIR_PRIM, AnimationWithGuides, split_guides
from hairtool.guides.render import ChildClump, RenderHair
from hairtool.guides.root_motion import following
from hairtool.io import usd
from hairtool.simulate.sway import sway_animation


@pytest.fixture(scope="module")
def shot():
    guides = samples.scalp(40, 8, seed=1)
    binding = bind_roots(guides, count=600, seed=2)
    return binding, sway_animation(guides, 7, flick_frame=4)


def test_every_frame_is_the_interpolation_of_that_frames_guides(shot):
    binding, anim = shot
    hair = RenderHairAnimation(binding, anim)
    whole = hair.animation()
    assert (whole.n_frames, whole.vertex_count, whole.fps) == (anim.n_frames, binding.vertex_count, anim.fps)
    for f in range(anim.n_frames):
        pose = anim.frame(f)  # the children's roots carried by the guides' (the head turns)
        assert whole.frames[f].tobytes() == following(binding, pose).build(pose).points.tobytes()
    assert np.abs(whole.frames[4] - whole.frames[0]).max() > 0.05  # the flick moves the children
    ref = render_frames_reference(binding, anim)
    size = float(np.ptp(whole.frames[0], axis=0).max())
    np.testing.assert_allclose(whole.frames, ref, atol=1e-5 * size)


def test_same_bytes_at_one_and_two_threads(shot):
    binding, anim = shot
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = RenderHairAnimation(binding, anim).animation().frames.tobytes()
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = RenderHairAnimation(binding, anim).animation().frames.tobytes()
    finally:
        numba.set_num_threads(before)
    assert one == two


def test_children_clumped_on_every_frame_and_a_dense_groom_returns_at_rest():
    dense = samples.scalp(300, 10, seed=5)
    guides, binding = bind_dense(dense, 30, seed=1)
    still = Animation(np.stack([guides.points, guides.points]), guides.topology, 12.0)
    back = RenderHairAnimation(binding, still).animation()
    assert back.frames[1].tobytes() == dense.points.tobytes()  # the guides at rest give back the groom
    moving = sway_animation(guides, 3, flick_frame=1)
    clump = ChildClump(radius=0.2, iterations=2)
    hair = RenderHairAnimation(binding, moving, clump)
    single = RenderHair(binding, clump, follow_roots=True)
    for f in range(moving.n_frames):
        assert hair.frame_points(f).tobytes() == single.update(moving.frame(f)).points.tobytes()


def test_an_animation_of_other_strands_is_refused(shot):
    binding, _ = shot
    other = sway_animation(samples.scalp(41, 8, seed=1), 3)
    with pytest.raises(ParameterError, match="guides"):
        RenderHairAnimation(binding, other)
    with pytest.raises(ParameterError, match="guides"):
        render_frames_reference(binding, other)


@pytest.mark.parametrize("name", ["shot.usdc", "shot.usda"])
def test_usd_round_trip_of_animated_render_hair_and_guides(shot, tmp_path, name, monkeypatch):
    binding, anim = shot
    anim = anim.with_frames(anim.frames, time_codes=np.arange(anim.n_frames) + 101.0)
    monkeypatch.setattr(usd, "FLUSH_BYTES", 1)  # a crate is saved after every frame
    hair = RenderHairAnimation(binding, anim)
    done = []
    usd.write(tmp_path / name, AnimationWithGuides(hair), progress=lambda i, n: done.append((i, n)))
    assert done[-1] == (anim.n_frames, anim.n_frames) and len(done) == anim.n_frames
    back = io.read(tmp_path / name)
    assert isinstance(back, Animation) and back.fps == anim.fps
    assert back.time_codes.tolist() == anim.time_codes.tolist()
    prims = back.metadata.curves
    assert [(c.path, c.strands, c.purpose) for c in prims] == [
        (HAIR_PRIM, binding.child_count, "default"),
        (GUIDES_PRIM, anim.strand_count, "guide"),
    ]
    children, guides = split_guides(back)
    assert children.frames.tobytes() == hair.animation().frames.tobytes()
    assert guides.frames.tobytes() == anim.frames.tobytes()
    w = children.thickness.reshape(-1, 8)
    assert np.all(w[:, 0] > w[:, -1])  # render strands taper from root to tip


def test_a_write_stopped_between_frames_leaves_no_file(shot, tmp_path):
    binding, anim = shot
    target = tmp_path / "stopped.usdc"

    def stop(done, total):
        if done == 3:
            raise Cancelled

    with pytest.raises(Cancelled):
        usd.write(target, AnimationWithGuides(RenderHairAnimation(binding, anim)), progress=stop)
    assert list(tmp_path.iterdir()) == []


def test_a_stream_frame_that_is_not_finite_is_refused_and_out_must_fit(shot, tmp_path):
    binding, anim = shot
    hair = RenderHairAnimation(binding, anim)

    class Broken(AnimationWithGuides):
        def frame_points(self, f):
            p = super().frame_points(f)
            p[5, 1] = np.nan if f == 2 else p[5, 1]
            return p

    with pytest.raises(ParameterError, match="finite"):
        usd.write(tmp_path / "nan.usdc", Broken(hair))
    assert list(tmp_path.iterdir()) == []
    rows = np.empty((binding.vertex_count + 10, 3), np.float32)
    assert hair.frame_points(3, rows[:-10]) is not None
    assert rows[:-10].tobytes() == hair.frame_points(3).tobytes()
    with pytest.raises(ParameterError, match="out"):
        hair.frame_points(0, rows)
