"""The anime wave dock: N_Pict curves, the paper's holds, live update, and Apply to groom."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.anime.wave import WaveParams, cycle_animation, wave

pytestmark = pytest.mark.gui


def test_dock_shows_one_curve_per_picture_and_the_papers_holds(qtbot):
    from app.ui.anime_dock import AnimeDock
    from hairtool.anime.settings import AnimeSettings

    dock = AnimeDock(settings=AnimeSettings(wave=WaveParams(period=0.45), fps=24.0, hold=2, cycles=1))
    qtbot.addWidget(dock)
    dock.show()
    qtbot.waitExposed(dock)
    s = dock.schedule
    assert (s.n_frames, s.n_pictures) == (11, 6)
    assert s.holds.tolist() == [2, 2, 2, 2, 2, 1]
    assert len(dock.curves) == 6
    # each curve is f(x, t_i) from the root (x = 0, left) to the tip (x = π, right)
    for i, c in enumerate(dock.curves):
        assert c[0, 0] == 0.0 and c[-1, 0] == pytest.approx(np.pi)
        np.testing.assert_allclose(c[:, 1], wave(c[:, 0], s.picture_times[i], WaveParams()))
    assert dock.strip.exposure.tolist() == [0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5]
    assert "holds 2,2,2,2,2,1" in dock.info.text()
    assert dock.apply_button.isEnabled()


def test_parameters_update_live_and_bad_timing_is_explained_in_the_dock(qtbot):
    from app.ui.anime_dock import AnimeDock

    dock = AnimeDock()
    qtbot.addWidget(dock)
    seen = []
    dock.settings_changed.connect(seen.append)
    dock.hold.setValue(3)  # on threes: 11 frames → 4 pictures, holds 3,3,3,2
    assert len(dock.curves) == 4 and dock.schedule.holds.tolist() == [3, 3, 3, 2]
    assert seen and seen[-1].hold == 3
    before = dock.curves[1].copy()
    dock.a.spin.setValue(1.6)  # typed amplitude: the curves follow at once
    assert seen[-1].wave.amplitude == pytest.approx(1.6)
    np.testing.assert_allclose(dock.curves[1][:, 1], 2 * before[:, 1])
    dock.period.spin.setValue(0.02)  # 0.48 frames at 24 fps: rounds to no frame at all
    assert dock.schedule is None and "0 frames" in dock.error_text()
    dock.period.spin.setValue(0.05)  # one frame on threes: K = 2 > N_Pict = 1
    assert dock.schedule is None and not dock.apply_button.isEnabled()
    assert "hold" in dock.error_text() and dock.curves == []
    assert dock.error_label.text() == dock.error_text()


def test_settings_round_trip_without_echo(qtbot):
    from app.ui.anime_dock import AnimeDock
    from hairtool.anime.settings import AnimeSettings

    dock = AnimeDock()
    qtbot.addWidget(dock)
    seen = []
    dock.settings_changed.connect(seen.append)
    s = AnimeSettings(
        WaveParams(0.5, 2.0, 1.5, 2.0, 0.6), fps=30.0, hold=3, cycles=4, phase_spread=0.0, seed=9
    )
    dock.set_settings(s)
    assert dock.settings() == s and seen == []
    assert AnimeSettings.from_dict(s.to_dict()) == s


def test_apply_to_groom_loads_the_cycle_into_the_animation_model(make_window):
    from app.ui.anime_dock import SOURCE
    from hairtool.anime.settings import AnimeSettings

    groom = samples.portrait(strands=12, vertices=8)
    w = make_window(groom=groom)
    dock = w.sources.dock
    dock.set_settings(AnimeSettings(cycles=2, seed=3))
    dock.apply_button.click()
    model = w.animation
    assert model.source == SOURCE and model.animation.n_frames == 22
    expect = cycle_animation(w.scene.result, WaveParams(), fps=24.0, hold=2, cycles=2, seed=3)
    np.testing.assert_array_equal(model.animation.frames, expect.frames)
    model.set_frame(5)
    assert dock.strip.current == 5


def test_apply_to_selected_strands_moves_only_those(make_window):
    from hairtool.anime.settings import AnimeSettings

    groom = samples.portrait(strands=10, vertices=6)  # the core's side: tests/anime/test_anime_settings.py
    w = make_window(groom=groom)
    w.scene.selection = np.array([5])  # a selection, when the studio has one
    assert w.sources.apply_anime(AnimeSettings(cycles=1))
    moved = np.abs(w.animation.animation.frames - w.scene.result.points[None]).max(axis=(0, 2))
    assert np.flatnonzero(np.maximum.reduceat(moved, groom.offsets[:-1]) > 1e-6).tolist() == [5]
