"""The export-still dialog: resolution, transparent background, then the file name."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from PySide6.QtWidgets import (
    QCheckBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QSpinBox,
    QWidget,
)

from app.render.offscreen import MAX_SIZE


@dataclass(frozen=True)
class StillOptions:
    path: str
    size: tuple[int, int]
    transparent: bool


class StillDialog(QDialog):
    """Width and height (the viewport's by default) and the transparent-background option."""

    def __init__(self, size: tuple[int, int], parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Export still")
        form = QFormLayout(self)
        self.width_box, self.height_box = QSpinBox(), QSpinBox()
        for box, value in ((self.width_box, size[0]), (self.height_box, size[1])):
            box.setRange(1, MAX_SIZE)
            box.setValue(value)
            box.setSuffix(" px")
        self.transparent = QCheckBox("Transparent background (PNG)")
        form.addRow("Width", self.width_box)
        form.addRow("Height", self.height_box)
        form.addRow(self.transparent)
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def size_px(self) -> tuple[int, int]:
        return self.width_box.value(), self.height_box.value()


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
    return StillOptions(path, dialog.size_px(), dialog.transparent.isChecked())
