"""A clip's frame rate: the one its file declares, else the rate whose frames hold every key time
(not the closest keys' rate: optimal keys with no 1-frame gap would be resampled too slowly);
and ``simulate --springs --motion animation`` driving the springs by the character's own clip."""

from __future__ import annotations

import dataclasses
import math
from functools import reduce
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.character import load_character
from hairtool.character.cycle import character_cycle
from hairtool.character.export import key_times, write_animated
from hairtool.character.model import Clip, key_rate
from hairtool.character.springs import simulate
from hairtool.cli import main

VRM = Path(__file__).resolve().parents[1] / "data" / "characters" / "bunches.vrm"
CHARACTER = load_character(VRM)


@st.composite
def key_frames(draw):
    """Increasing frame numbers from 0, no two adjacent, whose gaps share no divisor (so the
    frame rate is the only rate on whose frames they all lie)."""
    gaps = draw(st.lists(st.integers(2, 40), min_size=2, max_size=12))
    if reduce(math.gcd, gaps) != 1:
        gaps.append(next(g for g in range(2, 80) if math.gcd(reduce(math.gcd, gaps), g) == 1))
    return np.concatenate([[0], np.cumsum(gaps)]).astype(np.int64)


@settings(max_examples=80, deadline=None)
@given(
    frames=key_frames(), fps=st.sampled_from([12.0, 15.0, 23.976, 24.0, 25.0, 29.97, 30.0, 48.0, 60.0, 120.0])
)
def test_the_rate_of_float32_key_times_is_the_rate_they_were_written_at(frames, fps):
    rate = key_rate(key_times(frames, fps))
    assert rate == fps if fps == round(fps) else abs(rate - fps) < 1e-5 * fps


@settings(max_examples=30, deadline=None)
@given(frames=key_frames(), fps=st.sampled_from([24.0, 30.0]), shift=st.integers(0, 500))
def test_a_clip_that_starts_later_keeps_its_rate(frames, fps, shift):
    times = key_times(frames + shift, fps).astype(np.float64)
    clip = Clip("late", {0: (times, np.tile([1.0, 0.0, 0.0, 0.0], (len(times), 1)))})
    assert clip.frame_rate() == fps


def test_too_few_keys_say_nothing_and_the_fallback_is_used():
    assert key_rate(np.array([0.5])) == 24.0
    assert key_rate(np.array([]), fallback=30.0) == 30.0


def test_reread_optimal_keys_without_a_one_frame_gap_play_at_their_rate(tmp_path):
    spring = simulate(CHARACTER, character_cycle(CHARACTER).frames(12), 24.0)
    out = tmp_path / "keys.glb"
    write_animated(
        VRM,
        out,
        spring,
        CHARACTER.nodes.rotation,
        24.0,
        name="keys",
        step=False,
        key_frames=np.array([0, 3, 5, 8, 11]),
    )
    clip = load_character(out).clips[-1]
    assert clip.fps == 24.0  # declared by our writer
    assert dataclasses.replace(clip, fps=None).frame_rate() == 24.0  # and found without it
    assert len(clip.frames(CHARACTER.nodes, clip.frame_rate())) == 12


def _cycle_file(tmp_path: Path) -> tuple[Path, np.ndarray]:
    cyc = character_cycle(CHARACTER)
    src = tmp_path / "cycle.glb"
    write_animated(VRM, src, cyc.frames(), CHARACTER.nodes.rotation, 24.0, name="cycle", step=True)
    return src, cyc.frames()


def test_springs_driven_by_the_characters_own_animation(tmp_path):
    src, frames = _cycle_file(tmp_path)
    out = tmp_path / "springs.glb"
    assert main(["simulate", str(src), str(out), "--springs", "--motion", "animation:cycle", "--json"]) == 0
    clip = load_character(out).clips[-1]
    assert clip.fps == 24.0
    got = clip.frames(CHARACTER.nodes, 24.0)
    want = simulate(CHARACTER, load_character(src).clips[0].frames(CHARACTER.nodes, 24.0), 24.0)
    assert got.shape == want.shape == (len(frames), CHARACTER.nodes.count, 4)
    np.testing.assert_allclose(np.abs(np.sum(got * want, axis=-1)), 1.0, atol=1e-6)


@pytest.mark.parametrize("motion", ["animation:nope", "animation", "wobble"])
def test_a_missing_animation_is_one_line_and_exit_2(tmp_path, capsys, motion):
    src = tmp_path / "cycle.glb" if motion == "animation:nope" else VRM
    if motion == "animation:nope":
        _cycle_file(tmp_path)
    out = tmp_path / "o.glb"
    assert main(["simulate", str(src), str(out), "--springs", "--motion", motion]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "motion" in err[0]
    assert not out.exists()
