"""Posing bunch chains: lengths kept, planarity kept, axes, variation, the cycle as an Animation."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.anime.pose import bend_axes, bend_chains, bunch_variation, nearest_guide, wave_x
from hairtool.anime.schedule import schedule
from hairtool.anime.wave import (
    WaveParams,
    cycle_animation,
    cycle_pictures,
    make_bunches,
    pose_pictures,
    segment_angles,
    wave,
)
from hairtool.errors import ParameterError
from hairtool.groom import Animation, Groom

PAPER = WaveParams()
LOCK_STEP = {"amplitude_spread": 0.0, "phase_spread": 0.0}


def seg_lengths(points: np.ndarray, groom: Groom) -> np.ndarray:
    end = groom.topology.segment_end
    return np.linalg.norm(points[..., end, :] - points[..., end - 1, :], axis=-1)


def chain(direction, n=9, length=np.pi, root=(0.0, 0.0, 0.0)) -> np.ndarray:
    d = np.asarray(direction, dtype=np.float64)
    return np.asarray(root) + np.linspace(0, length, n)[:, None] * d / np.linalg.norm(d)


@pytest.mark.parametrize("groom", [samples.portrait(40, 20), samples.scalp(60, 24), samples.comb(25, 12)])
def test_every_segment_length_is_kept_and_roots_stay(groom):
    times = schedule(PAPER.period).picture_times
    poses = pose_pictures(groom, PAPER, times, make_bunches(groom, seed=4))
    assert poses.shape == (times.size, groom.vertex_count, 3)
    rest = groom.segment_lengths
    np.testing.assert_allclose(
        seg_lengths(poses, groom), np.broadcast_to(rest, (times.size, rest.size)), atol=1e-6
    )
    np.testing.assert_allclose(
        poses[:, groom.topology.root_indices],
        np.broadcast_to(groom.roots, (6, groom.strand_count, 3)),
        atol=1e-6,
    )
    assert not np.allclose(poses[1], poses[0])  # it does move


def test_real_groom_keeps_lengths(grooms_dir):
    from hairtool.io import read_groom

    groom = read_groom(grooms_dir / "sintel_hair.tfx")
    anim = cycle_animation(groom, PAPER)
    assert anim.n_frames == 11 and anim.strand_count == 228
    for f in (0, 5, 10):
        got = anim.frame(f).segment_lengths
        np.testing.assert_allclose(got, groom.segment_lengths, rtol=1e-4, atol=1e-4)


def test_2d_grooms_stay_planar_exactly():
    groom = samples.portrait(50, 16)
    anim = cycle_animation(groom, WaveParams(amplitude=2.0, wavelength=0.3), cycles=2, seed=9)
    assert not np.any(anim.frames[..., 2])
    assert all(anim.frame(f).is_planar for f in range(anim.n_frames))
    # a sway in the plane also keeps it planar; one along z cannot
    anim = cycle_animation(groom, PAPER, sway=(1.0, 0.2, 0.0))
    assert not np.any(anim.frames[..., 2])
    with pytest.raises(ParameterError) as e:
        cycle_animation(groom, PAPER, sway=(0.0, 0.0, 1.0))
    assert e.value.name == "sway"


def test_straight_chain_follows_the_sampled_curve_angles():
    """A straight chain along +x is the wave's x axis: segment j points at angle θ_j in the x-y plane."""
    g = Groom.from_strands([chain([1, 0, 0])])
    times = np.array([0.0, 0.1, 0.3])
    poses = pose_pictures(g, PAPER, times, make_bunches(g, **LOCK_STEP))
    x = wave_x(g)
    y = wave(x[None], times[:, None], PAPER)
    theta = np.arctan2(np.diff(y, axis=1), np.diff(x))
    d = np.diff(poses, axis=1)
    length = g.segment_lengths  # π/8 up to the float32 storage of the rest chain
    np.testing.assert_allclose(length, np.pi / 8, rtol=1e-6)
    np.testing.assert_allclose(d[..., 0], np.cos(theta) * length, atol=1e-12)
    np.testing.assert_allclose(d[..., 1], np.sin(theta) * length, atol=1e-12)
    np.testing.assert_array_equal(d[..., 2], 0.0)


def test_trig_free_pose_matches_the_angle_reference():
    g = samples.scalp(40, 16)
    b = make_bunches(g, seed=2)
    times = schedule(0.45, 24, 3).picture_times
    fast = pose_pictures(g, PAPER, times, b)
    bunch_of_v = b.of_strand[g.topology.strand_index]
    y = b.amplitude_scale[bunch_of_v] * wave(wave_x(g), times[:, None] + b.phase[bunch_of_v] * 0.45, PAPER)
    ref = bend_chains(g, b.axes[b.of_strand], segment_angles(g, y))
    np.testing.assert_allclose(fast, ref, atol=1e-12)


@pytest.mark.parametrize("direction", [[1, 0, 0], [-1, 0, 0], [0, 0, 1], [1, 0.3, -1]])
def test_gravity_pulls_tips_down_on_both_sides(direction):
    """With the default sway (up), the wave's sag −a/s² bends every chain toward −y."""
    g = Groom.from_strands([chain(direction)])
    times = np.linspace(0, PAPER.period, 40, endpoint=False)
    poses = pose_pictures(g, PAPER, times, make_bunches(g, **LOCK_STEP))
    assert poses[:, -1, 1].mean() < g.tips[0, 1] - 0.25


def test_2d_chains_on_both_sides_sag_down():
    g = Groom.from_strands([chain([1, 0, 0]), chain([-1, 0, 0])])
    axes = bend_axes(g)
    np.testing.assert_array_equal(axes, [[0, 0, 1], [0, 0, -1]])
    poses = pose_pictures(g, PAPER, np.linspace(0, 0.45, 12, endpoint=False), make_bunches(g, **LOCK_STEP))
    assert np.all(poses[:, g.topology.tip_indices, 1].mean(axis=0) < -0.25)
    np.testing.assert_allclose(poses[:, :9, 0], -poses[:, 9:, 0], atol=1e-12)  # mirror images


def test_bend_axes_turn_toward_the_sway():
    g = Groom.from_strands([chain([0, -1, 0]), chain([0.2, -1, 0.1]), chain([1, 0, 0]), chain([0, 1e-9, 1])])
    for sway in (None, (1.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.3, 0.5, 0.2)):
        axes = bend_axes(g, sway)
        np.testing.assert_allclose(np.linalg.norm(axes, axis=1), 1.0)
        chord = g.tips - g.roots
        np.testing.assert_allclose(np.sum(axes * chord, axis=1), 0.0, atol=1e-6)  # axis ⟂ chain
        w = np.array([0, 1.0, 0]) if sway is None else np.asarray(sway) / np.linalg.norm(sway)
        turned = np.cross(axes, chord)  # direction a small positive angle moves the chord
        ok = np.abs(np.sum(np.cross(chord, w) ** 2, axis=1)) > 1e-8
        assert np.all(np.sum(turned * w, axis=1)[ok] > 0)
    # a hanging chain has no axis ⟂ gravity from the sway: the view's horizontal (+x) is used
    np.testing.assert_allclose(bend_axes(g)[0], [0, 0, 1], atol=1e-12)
    for bad in ((0, 0, 0), (1, 2), (np.nan, 0, 1)):
        with pytest.raises(ParameterError):
            bend_axes(g, bad)


def test_lock_step_when_asked_otherwise_varied():
    g = samples.comb(16, 10)  # identical straight strands on a grid
    rel = lambda p: p.reshape(p.shape[0], 16, 10, 3) - p.reshape(p.shape[0], 16, 10, 3)[:, :, :1]  # noqa: E731
    t = schedule(0.45).picture_times
    same = rel(pose_pictures(g, PAPER, t, make_bunches(g, **LOCK_STEP)))
    np.testing.assert_allclose(same, np.broadcast_to(same[:, :1], same.shape), atol=1e-12)
    varied = rel(pose_pictures(g, PAPER, t, make_bunches(g)))
    assert np.abs(varied - varied[:, :1]).max() > 1e-3
    given = make_bunches(g, phase=np.linspace(0, 0.5, 16), amplitude_scale=2.0)
    np.testing.assert_array_equal(given.amplitude_scale, 2.0)
    np.testing.assert_allclose(given.phase, np.linspace(0, 0.5, 16))


def test_phase_of_a_whole_cycle_changes_nothing():
    g = samples.scalp(20, 12)
    t = schedule(0.45).picture_times
    a = pose_pictures(g, PAPER, t, make_bunches(g, amplitude_spread=0.0, phase=0.0))
    b = pose_pictures(g, PAPER, t, make_bunches(g, amplitude_spread=0.0, phase=1.0))
    np.testing.assert_allclose(a, b, atol=1e-9)


def test_variation_is_seeded_and_stable_per_bunch():
    s1, p1 = bunch_variation(10, 0.2, 0.5, seed=7)
    s2, p2 = bunch_variation(25, 0.2, 0.5, seed=7)
    np.testing.assert_array_equal(s1, s2[:10])
    np.testing.assert_array_equal(p1, p2[:10])
    assert np.all((s2 >= 0.8) & (s2 <= 1.2)) and np.all((p2 >= 0) & (p2 < 0.5))
    s3, _ = bunch_variation(10, 0.2, 0.5, seed=8)
    assert not np.array_equal(s1, s3)
    g = samples.scalp(30, 10)
    a = cycle_animation(g, PAPER, seed=3).frames
    np.testing.assert_array_equal(a, cycle_animation(g, PAPER, seed=3).frames)
    for name, kwargs in (
        ("amplitude_spread", {"amplitude_spread": 1.5}),
        ("phase_spread", {"phase_spread": -0.1}),
        ("seed", {"seed": -1}),
        ("phase", {"phase": [0.1, 0.2]}),
        ("amplitude_scale", {"amplitude_scale": np.full(30, np.nan)}),
    ):
        with pytest.raises(ParameterError) as e:
            make_bunches(g, **kwargs)
        assert e.value.name == name


def test_guides_lead_bunches_of_their_nearest_strands():
    g = samples.scalp(200, 8, seed=1)
    guides = np.array([5, 17, 60, 150])
    of = nearest_guide(g, guides, chunk=37)
    d = np.linalg.norm(g.roots[:, None].astype(np.float64) - g.roots[guides][None], axis=2)
    np.testing.assert_array_equal(of, np.argmin(d, axis=1))
    np.testing.assert_array_equal(of[guides], np.arange(4))
    b = make_bunches(g, guides=guides)
    assert b.axes.shape == (4, 3) and b.phase.shape == (4,)
    poses = pose_pictures(g, PAPER, [0.1], b)
    np.testing.assert_allclose(seg_lengths(poses, g)[0], g.segment_lengths, atol=1e-6)
    for bad in ([], [0, 0], [-1], [200], [1.5]):
        with pytest.raises(ParameterError) as e:
            make_bunches(g, guides=bad)
        assert e.value.name == "guides"


def test_strands_of_one_bunch_move_alike():
    g = samples.comb(9, 10)  # identical straight strands: one guide leads them all
    anim = cycle_animation(g, PAPER, guides=[4], seed=5)
    rel = (
        anim.frames.reshape(anim.n_frames, 9, 10, 3) - anim.frames.reshape(anim.n_frames, 9, 10, 3)[:, :, :1]
    )
    np.testing.assert_allclose(rel, np.broadcast_to(rel[:, 4:5], rel.shape), atol=1e-5)


def test_cycle_animation_holds_pictures_and_repeats():
    g = samples.portrait(30, 12)
    sched, pictures = cycle_pictures(g, PAPER, seed=1)
    assert len(pictures) == 6 and all(p.topology == g.topology for p in pictures)
    anim = cycle_animation(g, PAPER, cycles=3, seed=1)
    assert isinstance(anim, Animation) and anim.fps == 24.0 and anim.n_frames == 33
    exposure = sched.shot_exposure(33)
    for f in range(33):
        np.testing.assert_array_equal(anim.frames[f], pictures[exposure[f]].points)
    np.testing.assert_array_equal(anim.frames[:11], anim.frames[11:22])
    np.testing.assert_array_equal(anim.frames[0], anim.frames[1])  # on twos
    assert not np.array_equal(anim.frames[1], anim.frames[2])
    assert cycle_animation(g, PAPER, frames=5).n_frames == 5
    given = cycle_animation(g, PAPER, cycles=3, bunches=make_bunches(g, seed=1))
    np.testing.assert_array_equal(given.frames, anim.frames)
    on_threes = cycle_animation(g, WaveParams(period=1.0), fps=24, hold=3)
    assert on_threes.n_frames == 24
    np.testing.assert_array_equal(on_threes.frames[0], on_threes.frames[2])


def test_cycle_keeps_attributes_and_rejects_bad_sizes():
    base = samples.comb(4, 6)
    g = Groom(base.points, base.counts, thickness=np.linspace(1, 2, base.vertex_count))
    anim = cycle_animation(g)
    np.testing.assert_array_equal(anim.thickness, g.thickness)
    with pytest.raises(ParameterError) as e:
        cycle_animation(g, cycles=0)
    assert e.value.name == "cycles"
    with pytest.raises(ParameterError) as e:
        cycle_animation(samples.scalp(10_000, 32), frames=10_000)
    assert e.value.name == "frames"
    with pytest.raises(ParameterError) as e:
        pose_pictures(g, PAPER, [])
    assert e.value.name == "times"
