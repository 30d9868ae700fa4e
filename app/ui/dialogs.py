"""The export dialogs' options: picture size (the viewport's, 720p, 1080p or custom), transparent
background, working overlays, then the file name."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QSpinBox,
    QWidget,
)

from app.render.offscreen import MAX_SIZE

SIZE_720P = (1280, 720)
SIZE_1080P = (1920, 1080)
PRESETS = {"720p": SIZE_720P, "1080p": SIZE_1080P}
OVERLAYS_TIP = (
    "Draw the brush circle, the X-mirror plane and the mask's tint as the viewport shows them "
    "(off: the picture shows the hair and the head alone)"
)


@dataclass(frozen=True)
class StillOptions:
    path: str
    size: tuple[int, int]
    transparent: bool
    overlays: bool = False


@dataclass(frozen=True)
class PictureOptions:
    """A video's (or PNG sequence's) picture: its size and whether the overlays are drawn."""

    size: tuple[int, int]
    overlays: bool = False


class SizeForm:
    """Size rows for a form: a choice of the viewport's size (the default), 720p, 1080p or custom
    (width × height)."""

    def __init__(self, form: QFormLayout, viewport: tuple[int, int]) -> None:
        self.viewport = viewport
        self.choice = QComboBox()
        self.choice.addItem(f"Viewport ({viewport[0]} × {viewport[1]})", "viewport")
        for key, (w, h) in PRESETS.items():
            self.choice.addItem(f"{key} ({w} × {h})", key)
        self.choice.addItem("Custom", "custom")
        self.width_box, self.height_box = QSpinBox(), QSpinBox()
        for box, value in ((self.width_box, viewport[0]), (self.height_box, viewport[1])):
            box.setRange(1, MAX_SIZE)
            box.setValue(value)
            box.setSuffix(" px")
        form.addRow("Size", self.choice)
        form.addRow("Width", self.width_box)
        form.addRow("Height", self.height_box)
        self.choice.currentIndexChanged.connect(self._on_choice)
        self._on_choice()

    def set_choice(self, key: str) -> None:
        self.choice.setCurrentIndex(self.choice.findData(key))

    def _on_choice(self, *_: object) -> None:
        key = self.choice.currentData()
        custom = key == "custom"
        if not custom:
            w, h = self.viewport if key == "viewport" else PRESETS[key]
            self.width_box.setValue(w)
            self.height_box.setValue(h)
        self.width_box.setEnabled(custom)
        self.height_box.setEnabled(custom)

    def size_px(self) -> tuple[int, int]:
        return self.width_box.value(), self.height_box.value()


def _overlays_box() -> QCheckBox:
    box = QCheckBox("Include overlays (brush circle, mirror plane, mask tint)")
    box.setToolTip(OVERLAYS_TIP)
    return box


def _buttons(dialog: QDialog, form: QFormLayout) -> None:
    buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel)
    buttons.accepted.connect(dialog.accept)
    buttons.rejected.connect(dialog.reject)
    form.addRow(buttons)


class StillDialog(QDialog):
    """Size (the viewport's by default), transparent background and the overlays option."""

    def __init__(self, size: tuple[int, int], parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Export still")
        form = QFormLayout(self)
        self.size_form = SizeForm(form, size)
        self.width_box, self.height_box = self.size_form.width_box, self.size_form.height_box
        self.transparent = QCheckBox("Transparent background (PNG)")
        self.overlays = _overlays_box()
        form.addRow(self.transparent)
        form.addRow(self.overlays)
        _buttons(self, form)

    def size_px(self) -> tuple[int, int]:
        return self.size_form.size_px()


class PictureDialog(QDialog):
    """A video's picture: size and overlays."""

    def __init__(self, size: tuple[int, int], parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Export video")
        form = QFormLayout(self)
        self.size_form = SizeForm(form, size)
        self.overlays = _overlays_box()
        form.addRow(self.overlays)
        _buttons(self, form)

    def options(self) -> PictureOptions:
        return PictureOptions(self.size_form.size_px(), self.overlays.isChecked())


def ask_still_options(
    parent: QWidget, size: tuple[int, int], planar: bool, start_dir: str
) -> StillOptions | None:
    """Modal: None when the user cancels either step."""
    dialog = StillDialog(size, parent)
    if dialog.exec() != QDialog.DialogCode.Accepted:
        return None
    filters = "PNG image (*.png)" + (";;SVG drawing (*.svg)" if planar else "")
    path, _ = QFileDialog.getSaveFileName(parent, "Export still", str(Path(start_dir) / "still.png"), filters)
    if not path:
        return None
    return StillOptions(path, dialog.size_px(), dialog.transparent.isChecked(), dialog.overlays.isChecked())


def ask_picture_options(parent: QWidget, size: tuple[int, int]) -> PictureOptions | None:
    """Modal: a video's size and overlays, or None when cancelled."""
    dialog = PictureDialog(size, parent)
    if dialog.exec() != QDialog.DialogCode.Accepted:
        return None
    return dialog.options()
