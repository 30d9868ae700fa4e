"""The animation model alone (no window, no GL): signals only on real change, frame and key
navigation, settings given with an animation, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from app.ui.animation_model import AnimationModel
from hairtool import samples
from hairtool.errors import GroomError, ParameterError
from hairtool.keys.session import KeySettings
from hairtool.simulate.sway import sway_animation


@pytest.fixture
def model(qapp):
    m = AnimationModel()
    m.load_animation(sway_animation(samples.comb(strands=6, vertices=5), 30, 12.0, flick_frame=20), "sway")
    return m


def test_signals_fire_only_on_real_change(ui, model):
    frames, settings, views = (
        ui.record(model.frame_changed),
        ui.record(model.settings_changed),
        ui.record(model.view_mode_changed),
    )
    model.set_frame(4)
    model.set_frame(4)
    model.set_frame(99)  # clamped to the last frame
    model.set_frame(29)
    assert frames == [(4,), (29,)]
    model.set_settings(interp="linear")
    model.set_key_count(model.dp_keys.size)
    assert settings == [(model.settings,)]  # the count went from "auto" to its value once
    model.set_view_mode("ghost")
    model.set_view_mode("ghost")
    assert views == [("ghost",)]
    assert model.fps == 12.0


def test_frame_and_key_navigation(model):
    keys = model.dp_keys.tolist()
    model.next_key()
    assert model.frame == keys[1]
    model.set_frame(keys[1] + 1)
    model.previous_key()
    assert model.frame == keys[1]
    model.set_frame(0)
    model.step(-1)
    assert model.frame == 29  # loop on: wraps
    model.set_loop(False)
    model.step(5)
    assert model.frame == 29
    assert model.is_key(29) and not model.is_key(keys[1] + 1)


def test_saved_settings_come_with_the_animation_and_bad_input_is_refused(model):
    anim = model.animation
    saved = KeySettings(count=6, interp="hermite", samples=8)
    model.load_animation(anim, "project", settings=saved)
    assert model.settings == saved and model.dp_keys.size == 6 and model.key_solve.table_key[1] == "hermite"
    with pytest.raises(ParameterError):
        model.load_animation(anim, "project", settings=KeySettings(mode="tau", objective="worst"))
    assert model.settings == saved
    with pytest.raises(GroomError):
        model.load_animation(samples.comb(strands=3, vertices=3))
    with pytest.raises(ParameterError):
        model.set_settings(tau=-1.0)
    with pytest.raises(ParameterError):
        model.set_view_mode("wireframe")


def test_display_of_each_view_mode(model):
    model.set_frame(7)
    d = model.display()
    np.testing.assert_array_equal(d.points, model.animation.frames[7])
    assert d.colors is None and d.ghost is None
    model.set_view_mode("error")
    d = model.display()
    assert d.colors.shape == (model.animation.vertex_count, 3)
    model.clear()
    assert model.display() is None and model.n_frames == 0
