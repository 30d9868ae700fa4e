"""An artist's anime-cycle choice as a value (no Qt): it round-trips through the project file's
JSON, and a cycle on a selection moves those strands only."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hairtool import samples
from hairtool.anime.settings import AnimeSettings, cycle_for_groom, wave_curves
from hairtool.anime.wave import WaveParams, cycle_animation
from hairtool.errors import ParameterError


def test_settings_round_trip_through_json():
    wave = WaveParams(0.5, 2.0, 1.5, 2.0, 0.6)
    s = AnimeSettings(wave, fps=30.0, hold=3, cycles=4, phase_spread=0.0, seed=9)
    assert AnimeSettings.from_dict(json.loads(json.dumps(s.to_dict()))) == s
    with pytest.raises(ParameterError, match="anime settings"):
        AnimeSettings.from_dict({**s.to_dict(), "speed": 2})


def test_cycle_for_the_whole_groom_is_the_engines_cycle():
    groom = samples.portrait(strands=12, vertices=8)
    anim = cycle_for_groom(groom, AnimeSettings(cycles=2, seed=3))
    expect = cycle_animation(groom, WaveParams(), fps=24.0, hold=2, cycles=2, seed=3)
    assert anim.n_frames == 22
    np.testing.assert_array_equal(anim.frames, expect.frames)


def test_cycle_on_selected_strands_moves_only_those():
    groom = samples.portrait(strands=10, vertices=6)
    anim = cycle_for_groom(groom, AnimeSettings(cycles=1), [2, 5])
    assert anim.n_frames == 11 and anim.topology == groom.topology
    moved = np.abs(anim.frames - groom.points[None]).max(axis=(0, 2))
    per_strand = np.maximum.reduceat(moved, groom.offsets[:-1])
    assert set(np.flatnonzero(per_strand > 1e-6).tolist()) == {2, 5}


def test_wave_curves_sample_every_picture():
    sched, x, y = wave_curves(AnimeSettings(WaveParams(period=0.5), fps=24.0, hold=2), samples=40)
    assert x.shape == (40,) and y.shape == (sched.picture_times.size, 40)
    assert x[0] == 0.0 and x[-1] == pytest.approx(np.pi)
