"""The limited-animation schedule: the paper's example, hand-worked cases and refused inputs."""

from __future__ import annotations

import csv
import os

import numpy as np
import pytest

from hairtool.anime.schedule import frames_per_cycle, round_half_up, schedule, write_sheet
from hairtool.errors import ParameterError

# (T, fps, hold) -> N_Frame, N_Pict, K, holds, Δt — each worked by hand from N_Frame = [fps·T],
# N_Pict = ⌈N_Frame/N_Dup⌉, K = N_Dup·N_Pict − N_Frame, the last K held N_Dup − 1.
CASES = [
    ((0.45, 24, 2), 11, 6, 1, [2, 2, 2, 2, 2, 1], 0.075),  # the paper's Fig. 2
    ((0.5, 24, 3), 12, 4, 0, [3, 3, 3, 3], 0.125),
    ((0.5, 25, 2), 13, 7, 1, [2, 2, 2, 2, 2, 2, 1], 0.5 / 7),  # 12.5 rounds up
    ((1.0, 24, 3), 24, 8, 0, [3] * 8, 0.125),
    ((0.3, 24, 3), 7, 3, 2, [3, 2, 2], 0.1),  # 7.2 -> 7
    ((0.35, 30, 2), 11, 6, 1, [2, 2, 2, 2, 2, 1], 0.35 / 6),  # 10.5 -> 11
    ((0.58, 25, 2), 15, 8, 1, [2] * 7 + [1], 0.58 / 8),  # 14.5 (14.4999… in binary) -> 15
    ((0.45, 30, 4), 14, 4, 2, [4, 4, 3, 3], 0.1125),  # 13.5 -> 14
    ((0.2, 24, 1), 5, 5, 0, [1] * 5, 0.04),  # 4.8 -> 5, on ones
    ((0.1, 24, 3), 2, 1, 1, [2], 0.1),  # 2.4 -> 2: one picture held 2
    ((0.0625, 24, 2), 2, 1, 0, [2], 0.0625),  # 1.5 -> 2
    ((2.0, 12, 2), 24, 12, 0, [2] * 12, 2.0 / 12),
]


@pytest.mark.parametrize(("args", "n_frames", "n_pict", "k", "holds", "dt"), CASES)
def test_schedule_matches_hand_worked_cases(args, n_frames, n_pict, k, holds, dt):
    s = schedule(*args)
    assert (s.n_frames, s.n_pictures, s.k) == (n_frames, n_pict, k)
    assert s.holds.tolist() == holds
    assert s.dt == pytest.approx(dt, rel=1e-15)
    assert int(s.holds.sum()) == s.n_frames
    assert s.exposure.tolist() == [i for i, h in enumerate(holds) for _ in range(h)]
    np.testing.assert_allclose(s.picture_times, np.arange(n_pict) * dt, rtol=1e-14, atol=1e-15)


def test_paper_example_prints_exact_numbers():
    d = schedule(0.45, 24, 2).to_dict()
    assert d["n_frames"] == 11 and d["n_pictures"] == 6 and d["k"] == 1
    assert d["holds"] == [2, 2, 2, 2, 2, 1]
    assert d["dt"] == 0.075  # the decimal, not 0.07500000000000001
    assert d["exposure"] == [0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5]
    assert d["cycle_seconds"] == pytest.approx(11 / 24)


def test_rounding_is_half_up_on_the_typed_decimals():
    assert round(12.5) == 12 and round_half_up(12.5) == 13
    assert round_half_up(10.799999999999999) == 11
    assert round_half_up(2.4999) == 2
    assert 0.58 * 25 < 14.5  # the float product is below the half …
    assert frames_per_cycle(0.58, 25) == 15  # … but the typed decimals give 14.5 -> 15
    assert frames_per_cycle(1.025, 60) == 62  # 61.5 (61.4999… in binary)
    assert frames_per_cycle(0.5, 25) == 13
    assert frames_per_cycle(0.45, 24) == 11
    assert frames_per_cycle(1 / 48, 24) == 1  # 0.5 frame -> 1


def test_shot_exposure_repeats_the_cycle():
    s = schedule(0.45, 24, 2)
    shot = s.shot_exposure(25)
    assert shot.tolist() == s.exposure.tolist() * 2 + [0, 0, 1]
    assert s.to_dict(frames=4)["exposure"] == [0, 0, 1, 1]


@pytest.mark.parametrize(
    ("args", "name"),
    [
        ((0.02, 24, 2), "period"),  # 0.48 frames -> N_Frame = 0
        ((0.05, 24, 3), "hold"),  # one frame on threes: K = 2 > N_Pict = 1
        ((1 / 24, 24, 3), "hold"),
        ((0.0, 24, 2), "period"),
        ((-1.0, 24, 2), "period"),
        ((float("nan"), 24, 2), "period"),
        ((0.45, 0.0, 2), "fps"),
        ((0.45, float("inf"), 2), "fps"),
        ((0.45, 24, 0), "hold"),
        ((0.45, 24, 2.5), "hold"),
        ((1e9, 24, 2), "period"),
    ],
)
def test_broken_schemes_are_refused_with_the_parameter_named(args, name):
    with pytest.raises(ParameterError) as e:
        schedule(*args)
    assert e.value.name == name


def test_k_greater_than_pictures_message_says_why():
    with pytest.raises(ParameterError, match="K = 2 > N_Pict"):
        schedule(0.05, 24, 3)


def test_shot_length_is_validated():
    s = schedule(0.45, 24, 2)
    for bad in (0, -3, 2.5):
        with pytest.raises(ParameterError):
            s.shot_exposure(bad)


def test_exposure_sheet_csv(tmp_path):
    s = schedule(0.45, 24, 2)
    path = tmp_path / "sheet.csv"
    write_sheet(path, s, frames=13)
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["frame", "picture", "time"]
    assert len(rows) == 14
    assert [int(r[1]) for r in rows[1:]] == s.shot_exposure(13).tolist()
    assert [int(r[0]) for r in rows[1:]] == list(range(13))
    assert float(rows[12][2]) == pytest.approx(11 / 24)
    assert os.listdir(tmp_path) == ["sheet.csv"]  # no temporary file left behind


def test_failed_sheet_write_leaves_the_old_file(tmp_path):
    path = tmp_path / "sheet.csv"
    path.write_text("old")
    with pytest.raises(ParameterError):
        write_sheet(path, schedule(0.45, 24, 2), frames=0)
    assert path.read_text() == "old"
