"""The figure scripts' sheet helpers and the anime figure run end to end (small panels)."""

from __future__ import annotations

import itertools
import re
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from app.figures import anime
from app.figures.sheet import GAP, LABEL_HEIGHT, grid, label, main_guard
from hairtool.errors import HairtoolError, ParameterError
from hairtool.mocap import ik

ROOT = Path(__file__).resolve().parents[2]


def test_grid_places_panels_in_rows_with_gaps():
    a = np.zeros((10, 20, 4), np.uint8)
    b = np.full((10, 20, 4), 200, np.uint8)
    sheet = grid([a, b, a], columns=2)
    assert sheet.shape == (2 * 10 + 3 * GAP, 2 * 20 + 3 * GAP, 4)
    assert np.all(sheet[GAP : GAP + 10, 2 * GAP + 20 : 2 * GAP + 40] == 200)
    assert np.all(sheet[0, :] == 255)  # white margin
    with pytest.raises(HairtoolError):
        grid([])


def test_label_adds_a_caption_band_with_text():
    img = np.zeros((40, 120, 4), np.uint8)
    img[..., 3] = 255
    out = label(img, "stiffness 7")
    assert out.shape == (40 + LABEL_HEIGHT, 120, 4)
    np.testing.assert_array_equal(out[:40], img)
    band = out[40:, :, :3]
    assert band.min() < 100 and band.max() == 255  # dark glyphs on white


def test_main_guard_turns_errors_into_status_2(capsys):
    def bad():
        raise ParameterError("stiffness", -1, "a positive number")

    assert main_guard(bad) == 2
    assert "stiffness" in capsys.readouterr().err
    assert main_guard(lambda: None) == 0


def test_anime_figure_writes_frames_sheet_and_envelope(tmp_path, capsys):
    anime.make([str(tmp_path), "--size", "96"])
    frames = sorted(tmp_path.glob("anime_picture_*.png"))
    assert len(frames) >= 4
    images = [iio.imread(f) for f in frames]
    assert all(img.shape == (96, 96, 4) for img in images)
    # Consecutive pictures differ: the hair moves through the cycle.
    for a, b in itertools.pairwise(images):
        assert np.abs(a.astype(int) - b.astype(int)).max() > 100
    assert (tmp_path / "anime_contact_sheet.png").is_file()
    assert (tmp_path / "anime_envelope.png").is_file()
    assert str(tmp_path / "anime_contact_sheet.png") in capsys.readouterr().out


def _differing(a: np.ndarray, b: np.ndarray) -> float:
    return float((np.abs(a.astype(int) - b.astype(int)).max(axis=2) > 60).mean())


def test_frozen_figures_show_the_papers_comparisons(tmp_path):
    from app.figures import frozen

    frozen.make([str(tmp_path), "--size", "128"])
    for sheet in ("frozen_fig1_intensity", "frozen_fig2_stiffness", "frozen_fig3_clumping"):
        assert (tmp_path / f"{sheet}.png").is_file()
    fig1a = iio.imread(tmp_path / "frozen_fig1a_intensity_0.8.png")
    fig1b = iio.imread(tmp_path / "frozen_fig1b_intensity_0.2.png")
    assert _differing(fig1a, fig1b) > 0.005
    # Fig. 1 colours roots red and tips blue, as the paper does.
    assert ((fig1a[..., 0] > 180) & (fig1a[..., 2] < 90)).any()
    assert ((fig1a[..., 2] > 180) & (fig1a[..., 0] < 90)).any()
    original = iio.imread(tmp_path / "frozen_fig2a_original.png")
    stiff = iio.imread(tmp_path / "frozen_fig2b_stiffness_7.png")
    soft = iio.imread(tmp_path / "frozen_fig2c_stiffness_3.png")
    # Lower stiffness departs further from the original shape.
    assert _differing(original, soft) > _differing(original, stiff) > 0.005
    unclumped = iio.imread(tmp_path / "frozen_fig3b_aligned_and_frozen_no_clumping.png")
    clumped = iio.imread(tmp_path / "frozen_fig3d_clump_radius_0.12.png")
    assert _differing(unclumped, clumped) > 0.005


def test_the_fig9_jump_figure_edits_one_key_of_the_walk(tmp_path, capsys):
    from app.figures import mocap
    from hairtool.mocap.bvh import read_bvh

    mocap.make([str(tmp_path), "--size", "64"])
    sheet = iio.imread(tmp_path / "mocap_fig9_jump.png")
    panel = 64 + LABEL_HEIGHT
    assert sheet.shape[0] == 2 * panel + 3 * GAP
    top, bottom = sheet[GAP : GAP + 64], sheet[2 * GAP + panel : 2 * GAP + panel + 64]
    red = lambda img: (img[..., 0] > 150) & (img[..., 1] < 100) & (img[..., 2] < 100)  # noqa: E731
    assert not red(top).any() and red(bottom).sum() > 50  # the edited frames, in red, below
    edited = read_bvh(tmp_path / "mocap_fig9_jump.bvh")
    walk = read_bvh(mocap.CAPTURE)
    out = capsys.readouterr().out
    said = r"jump at the key of frame (\d+): frames (\d+)-(\d+) follow \(keys (\d+), \d+, (\d+)\)"
    found = re.search(said, out)
    assert found, out
    key, first, last, lo, hi = map(int, found.groups())
    assert (first, last) == (lo + 1, hi - 1) and lo < key < hi
    # one key's neighbourhood only: the capture bit for bit (to the file's decimals) outside it
    changed = np.flatnonzero(np.any(np.abs(edited.values - walk.values) > 1e-6, axis=1))
    assert key in changed and changed.min() >= first and changed.max() <= last
    assert np.array_equal(edited.offsets, walk.offsets)
    assert np.array_equal(edited.end_offsets, walk.end_offsets)
    # a jump at the key: both heels drawn up (the capture's up is y), fading toward the neighbours
    h = ik.figure_height(walk)
    p0, p1 = walk.joint_positions(), edited.joint_positions()
    for foot in ("LeftFoot", "RightFoot"):
        j = walk.joint_names.index(foot)
        assert p1[key, j, 1] - p0[key, j, 1] > 0.15 * h
    move = np.linalg.norm(p1 - p0, axis=2).max(axis=1)
    assert move[key] > 0.9 * move.max() and move[first] < 0.2 * move[key] and move[last] < 0.2 * move[key]
    assert move[first] < move[(first + key) // 2] < move[key] and move[last] < move[(key + last) // 2]
    misses = [float(v) for v in re.findall(r": ([0-9.e+-]+) of the figure's height from its target", out)]
    assert len(misses) == 4 and max(misses) <= 2e-5  # the manual says: each within 2e-5
    # the manual's Fig. 9 section is this figure: its keys, its command, its picture's layout
    page_path = ROOT / "docs" / "cli" / "key-edits.md"
    page = page_path.read_text()
    assert "python -m app.figures.mocap" in page
    assert f"keys at {lo}, {key} and {hi}" in page and f"the key of frame {key}" in page
    assert f"{mocap.KEYS} keys (cubic Hermite)" in page
    picture = re.search(r"!\[Seed 003's Fig\. 9[^]]*\]\(([^)]+\.png)\)", page)
    assert picture, "the manual shows Fig. 9"
    shown_path = (page_path.parent / picture.group(1)).resolve()
    assert shown_path == (ROOT / "resources" / "figure-keys-jump.png").resolve(), "the script's picture"
    shown = iio.imread(shown_path)
    columns = sheet.shape[1] // (64 + GAP)  # the frames shown, one panel each
    size = (shown.shape[1] - (columns + 1) * GAP) / columns
    assert size == int(size) and shown.shape[0] == 2 * (int(size) + LABEL_HEIGHT) + 3 * GAP


def test_the_character_figure_draws_the_cycle_beside_the_springs(tmp_path, monkeypatch):
    from app.figures import character

    monkeypatch.setattr(character, "resource", lambda name: ROOT / "resources" / name)  # this checkout's
    character.make([str(tmp_path), "--size", "64"])
    sheet = iio.imread(tmp_path / "character_cycle_vs_springs.png")
    assert sheet.shape[1] > 6 * 64 and sheet.shape[0] > 2 * 64  # six drawings over six spring frames
    assert sheet[..., :3].min() < 128  # something is drawn
