"""``hairtool-studio [FILE]``: start the desktop application."""

from __future__ import annotations

import sys


def entry() -> None:
    from PySide6.QtWidgets import QApplication, QMainWindow

    app = QApplication(sys.argv)
    window = QMainWindow()
    window.setWindowTitle("Hairtool Studio")
    window.resize(1280, 800)
    window.show()
    sys.exit(app.exec())
