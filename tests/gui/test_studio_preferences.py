"""Edit ▸ Preferences: stored with QSettings (a temporary scope here) and read back the same,
unreadable values falling back to their defaults, and each preference at work: the keymap's
shortcuts, the theme's palette, the autosave interval, the brush size of a groom opened next,
and the kernel cache folder at the next start."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PySide6.QtCore import QSettings
from PySide6.QtGui import QPalette
from PySide6.QtWidgets import QDialog

from app.ui import preferences as prefs_mod
from app.ui.cache_folder import KEY, use_preferred_cache_folder
from app.ui.preferences import KEYMAPS, THEMES, Preferences, load, store
from hairtool import samples
from hairtool.errors import ParameterError

pytestmark = pytest.mark.gui

valid = st.builds(
    Preferences,
    keymap=st.sampled_from(list(KEYMAPS)),
    theme=st.sampled_from(THEMES),
    brush_size=st.floats(1e-3, 2.0),
    cache_folder=st.text(st.characters(blacklist_categories=("Cs", "Cc")), max_size=30).map(str.strip),
    autosave_minutes=st.floats(1.0, 600.0),
)


@pytest.fixture
def scratch(tmp_path):
    """A QSettings of its own for each example (a file in a temporary folder)."""
    count = iter(range(10**6))
    return lambda: QSettings(str(tmp_path / f"prefs{next(count)}.ini"), QSettings.Format.IniFormat)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(prefs=valid)
def test_stored_preferences_read_back_the_same(scratch, prefs):
    s = scratch()
    store(s, prefs)
    assert load(QSettings(s.fileName(), QSettings.Format.IniFormat)) == prefs


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    field=st.sampled_from([f.name for f in dataclasses.fields(Preferences) if f.name != "cache_folder"]),
    raw=st.one_of(st.text(max_size=12), st.sampled_from(["nan", "inf", "-1", "0", "99999", "maya"])),
)
def test_an_unreadable_stored_value_falls_back_to_its_default_and_keeps_the_others(scratch, field, raw):
    s = scratch()
    good = Preferences(keymap="maya", theme="light", brush_size=0.3, autosave_minutes=5.0)
    store(s, good)
    s.setValue(f"preferences/{field}", raw)
    got = load(s)
    for f in dataclasses.fields(Preferences):
        if f.name != field:
            assert getattr(got, f.name) == getattr(good, f.name)
    default = getattr(Preferences(), field)
    try:  # the raw text as the field's type, kept only where it is a valid preference
        expected = type(default)(raw)
        dataclasses.replace(Preferences(), **{field: expected}).validate()
    except (TypeError, ValueError, ParameterError):
        expected = default
    assert getattr(got, field) == expected
    got.validate()  # whatever was read is a valid preference


def test_each_preference_is_at_work_in_the_window(make_window, settings_path):
    w = make_window(groom=samples.scalp(strands=80, vertices=8))
    prefs_mod.apply(w, Preferences(keymap="maya", theme="light", autosave_minutes=3.0))
    keys = {name: [k.toString() for k in a.shortcuts()] for name, a in w.habit_actions.items()}
    assert keys["front"] == [] and keys["selected"] == ["Num+."] and keys["sidebar"] == ["Ctrl+A"]
    light = w.palette().color(QPalette.ColorRole.Window).lightness()
    assert w.project.timer.interval() == 180_000
    prefs_mod.apply(w, Preferences())
    keys = {name: [k.toString() for k in a.shortcuts()] for name, a in w.habit_actions.items()}
    assert {n: keys[n] for n in KEYMAPS["blender"]} == {n: [k] for n, k in KEYMAPS["blender"].items()}
    assert w.palette().color(QPalette.ColorRole.Window).lightness() < light
    assert w.project.timer.interval() == 60_000
    # the brush size: a groom opened after the preference changed starts with it
    store(w.settings, Preferences(brush_size=0.25))
    groom = samples.scalp(strands=60, vertices=8, seed=3)
    w.set_groom(groom)
    lo, hi = groom.bounds
    assert w.scene.radius == pytest.approx(0.25 * float(np.max(hi - lo)))


def test_the_dialog_stores_and_applies_what_it_says(make_window, monkeypatch):
    w = make_window(groom=samples.scalp(strands=40, vertices=6))

    def accept(dialog):
        dialog.keymap.setCurrentIndex(list(KEYMAPS).index("maya"))
        dialog.autosave.setValue(7)
        dialog.brush_size.setValue(30.0)
        dialog.cache.setText("  /tmp/kernels ")
        return QDialog.DialogCode.Accepted

    monkeypatch.setattr(prefs_mod.PreferencesDialog, "exec", accept)
    w.habit_actions["preferences"].trigger()
    got = load(w.settings)
    assert got == Preferences(
        keymap="maya", brush_size=0.3, cache_folder="/tmp/kernels", autosave_minutes=7.0
    )
    assert w.project.timer.interval() == 7 * 60_000
    assert w.habit_actions["sidebar"].shortcuts()[0].toString() == "Ctrl+A"


def test_the_cache_folder_is_used_from_the_next_start_unless_the_environment_names_one(scratch, monkeypatch):
    s = scratch()
    # set, then removed: monkeypatch then restores the worker's own value (or none) afterwards,
    # where a bare delenv of an absent name records nothing and the folder chosen below would
    # stay in the environment for every later compile in this process
    monkeypatch.setenv("NUMBA_CACHE_DIR", "")
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    assert use_preferred_cache_folder(s) is None
    s.setValue(KEY, "/somewhere/kernels")
    assert use_preferred_cache_folder(s) == "/somewhere/kernels"
    import os

    assert os.environ["NUMBA_CACHE_DIR"] == "/somewhere/kernels"
    monkeypatch.setenv("NUMBA_CACHE_DIR", "/mine")
    assert use_preferred_cache_folder(s) is None
    assert os.environ["NUMBA_CACHE_DIR"] == "/mine"
