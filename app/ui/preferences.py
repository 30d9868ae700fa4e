"""Preferences kept between sessions (QSettings, group ``preferences``): the keymap preset, the
theme, the brush size a newly opened groom starts with, the kernel cache folder and the autosave
interval (Edit ▸ Preferences…).

One :class:`Preferences` value is read (:func:`load`: a stored value that cannot be read falls
back to its default, naming nothing lost, since preferences are not the artist's work), written
(:func:`store`) and applied to a window (:func:`apply`). The cache folder takes effect at the
next start (:mod:`app.ui.cache_folder`), since the kernels are loaded before any window.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from PySide6.QtCore import QSettings
from PySide6.QtGui import QColor, QKeySequence, QPalette
from PySide6.QtWidgets import (
    QApplication,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QLineEdit,
    QSpinBox,
)

from app.ui.scene import BRUSH_SHARE
from hairtool.errors import ParameterError

GROUP = "preferences"
THEMES = ("dark", "light")
#: Shortcuts of the habit actions (:mod:`app.ui.habits`) per preset. Maya's own keys where they
#: do not collide with the studio's: 1 and 3 are Maya's display-smoothness keys, so its preset
#: leaves the views to the menu and F3; its F / Shift+F (frame selected) are the studio's brush
#: sizing, so frame selected stays on the numpad's period; Ctrl+A is its attribute editor,
#: Ctrl+Space its hide-the-interface.
KEYMAPS: dict[str, dict[str, str]] = {
    "blender": {
        "front": "1", "back": "Ctrl+Num+1", "right": "3", "left": "Ctrl+Num+3", "top": "7",
        "bottom": "Ctrl+Num+7",
        "selected": "Num+.", "sidebar": "N", "timeline": "T", "maximise": "Ctrl+Space", "search": "F3",
    },
    "maya": {
        "front": "", "back": "", "right": "", "left": "", "top": "", "bottom": "",
        "selected": "Num+.", "sidebar": "Ctrl+A", "timeline": "Alt+T", "maximise": "Ctrl+Space",
        "search": "F3",
    },
}  # fmt: skip


@dataclass(frozen=True)
class Preferences:
    """``brush_size``: a newly opened groom's brush radius, of its largest side, in (0, 2];
    ``cache_folder`` "" for the default place; ``autosave_minutes`` at least 1."""

    keymap: str = "blender"
    theme: str = "dark"
    brush_size: float = BRUSH_SHARE
    cache_folder: str = ""
    autosave_minutes: float = 1.0

    def validate(self) -> Preferences:
        checks = (
            ("keymap", self.keymap in KEYMAPS, " or ".join(KEYMAPS)),
            ("theme", self.theme in THEMES, " or ".join(THEMES)),
            ("brush size", _finite(self.brush_size) and 0 < self.brush_size <= 2, "a share in (0, 2]"),
            ("autosave minutes", _finite(self.autosave_minutes) and self.autosave_minutes >= 1, ">= 1"),
        )
        for name, ok, want in checks:
            if not ok:
                raise ParameterError(name, getattr(self, name.replace(" ", "_")), want)
        return self


def _finite(x) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)


def load(settings: QSettings) -> Preferences:
    """The stored preferences; each value that is missing or unreadable is its default."""
    default = Preferences()
    values = {}
    for f in dataclasses.fields(Preferences):
        raw = settings.value(f"{GROUP}/{f.name}")
        if raw is None:
            continue
        try:
            value = type(getattr(default, f.name))(raw)
            dataclasses.replace(default, **{f.name: value}).validate()
        except (TypeError, ValueError, ParameterError):
            continue
        values[f.name] = value
    return dataclasses.replace(default, **values)


def store(settings: QSettings, prefs: Preferences) -> None:
    prefs.validate()
    for f in dataclasses.fields(Preferences):
        settings.setValue(f"{GROUP}/{f.name}", getattr(prefs, f.name))
    settings.sync()


def palette(theme: str) -> QPalette:
    """The studio's palette for ``theme``."""
    p = QPalette()
    if theme == "light":
        return QApplication.style().standardPalette()
    roles = {
        QPalette.ColorRole.Window: "#303236",
        QPalette.ColorRole.WindowText: "#dcdcdc",
        QPalette.ColorRole.Base: "#26282b",
        QPalette.ColorRole.AlternateBase: "#2d2f33",
        QPalette.ColorRole.Text: "#dcdcdc",
        QPalette.ColorRole.Button: "#3a3d42",
        QPalette.ColorRole.ButtonText: "#dcdcdc",
        QPalette.ColorRole.Highlight: "#4772b3",
        QPalette.ColorRole.HighlightedText: "#ffffff",
        QPalette.ColorRole.ToolTipBase: "#26282b",
        QPalette.ColorRole.ToolTipText: "#dcdcdc",
    }
    for role, colour in roles.items():
        p.setColor(role, QColor(colour))
    return p


def apply(window, prefs: Preferences) -> None:
    """Put ``prefs`` to work in ``window``: shortcuts, palette, autosave interval."""
    keys = KEYMAPS[prefs.keymap]
    for name, action in getattr(window, "habit_actions", {}).items():
        if name in keys:
            action.setShortcuts([QKeySequence(keys[name])] if keys[name] else [])
    window.setPalette(palette(prefs.theme))
    project = getattr(window, "project", None)
    if project is not None:
        project.timer.setInterval(int(prefs.autosave_minutes * 60_000))


def apply_brush_size(scene, prefs: Preferences) -> None:
    """Every brush of the scene's groom at the preferred size (of its largest side)."""
    lo, hi = scene.rest.bounds
    extent = float((hi - lo).max())
    scene.tool.reset_radius(prefs.brush_size * extent if extent > 0 else 1.0)
    scene.tool_changed.emit()


class PreferencesDialog(QDialog):
    """Edit ▸ Preferences…: the fields of :class:`Preferences`, OK stores and applies them."""

    def __init__(self, window, prefs: Preferences) -> None:
        super().__init__(window)
        self.setWindowTitle("Preferences")
        self.keymap = QComboBox(self)
        self.keymap.addItems([k.capitalize() for k in KEYMAPS])
        self.keymap.setCurrentIndex(list(KEYMAPS).index(prefs.keymap))
        self.keymap.setToolTip("Shortcuts for the views, panels and search, as in Blender or Maya")
        self.theme = QComboBox(self)
        self.theme.addItems([t.capitalize() for t in THEMES])
        self.theme.setCurrentIndex(THEMES.index(prefs.theme))
        self.brush_size = QDoubleSpinBox(self)
        self.brush_size.setRange(0.1, 200.0)
        self.brush_size.setSuffix(" % of the groom")
        self.brush_size.setValue(prefs.brush_size * 100.0)
        self.brush_size.setToolTip("The brush size a groom starts with when it is opened")
        self.cache = QLineEdit(prefs.cache_folder, self)
        self.cache.setPlaceholderText("the default place")
        self.cache.setToolTip("Where the compiled engine kernels are kept (from the next start)")
        self.autosave = QSpinBox(self)
        self.autosave.setRange(1, 120)
        self.autosave.setSuffix(" min")
        self.autosave.setValue(max(1, round(prefs.autosave_minutes)))
        form = QFormLayout(self)
        for label, widget in (
            ("Keymap", self.keymap),
            ("Theme", self.theme),
            ("Brush size", self.brush_size),
            ("Kernel cache folder", self.cache),
            ("Autosave every", self.autosave),
        ):
            form.addRow(label, widget)
        b = QDialogButtonBox.StandardButton
        buttons = QDialogButtonBox(b.Ok | b.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def value(self) -> Preferences:
        return Preferences(
            keymap=list(KEYMAPS)[self.keymap.currentIndex()],
            theme=THEMES[self.theme.currentIndex()],
            brush_size=self.brush_size.value() / 100.0,
            cache_folder=self.cache.text().strip(),
            autosave_minutes=float(self.autosave.value()),
        ).validate()


def edit_preferences(window) -> Preferences | None:
    """The dialog on the window's stored preferences; OK stores and applies what it says."""
    dialog = PreferencesDialog(window, load(window.settings))
    if dialog.exec() != QDialog.DialogCode.Accepted:
        return None
    prefs = dialog.value()
    store(window.settings, prefs)
    apply(window, prefs)
    return prefs


def install_preferences(window, menu):
    """Edit ▸ Preferences… in ``menu``; the stored preferences applied now, and the brush size
    to each groom opened from now on."""
    from app.ui.qt_utils import add_action

    action = add_action(window, menu, "&Preferences…", lambda: edit_preferences(window), "Ctrl+,")
    apply(window, load(window.settings))
    scene = window.scene
    scene.groom_loaded.connect(lambda: apply_brush_size(scene, load(window.settings)))
    return action
