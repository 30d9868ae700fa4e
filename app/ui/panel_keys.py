"""Blender's keys for the panels: N shows or hides the settings dock (Blender's sidebar), T the
timeline, and Ctrl+Space gives the whole window to the 3-D view and back (Blender's maximise
area): the docks that were open come back as they were."""

from __future__ import annotations

from PySide6.QtWidgets import QDockWidget


class Maximise:
    """The 3-D view alone in the window, or the docks back (:meth:`toggle`)."""

    def __init__(self, window) -> None:
        self.window = window
        self.hidden: list[QDockWidget] = []  # the docks maximising closed, to reopen

    @property
    def active(self) -> bool:
        return bool(self.hidden)

    def toggle(self) -> None:
        if self.hidden:
            for dock in self.hidden:
                dock.show()
            self.hidden = []
            return
        self.hidden = [d for d in self.window.findChildren(QDockWidget) if d.isVisible()]
        for dock in self.hidden:
            dock.hide()


def toggle_dock(dock: QDockWidget) -> None:
    """Show ``dock`` if hidden, hide it if shown (raised to the front of its tabs when shown)."""
    dock.setVisible(not dock.isVisible())
    if dock.isVisible():
        dock.raise_()


def add_panel_actions(window, menu) -> dict[str, object]:
    """N, T and Ctrl+Space in ``menu`` (the View menu), by name."""
    from app.ui.qt_utils import add_action

    window.maximise = Maximise(window)
    return {
        "sidebar": add_action(window, menu, "Side&bar (settings)", lambda: toggle_dock(window.dock), "N"),
        "timeline": add_action(window, menu, "T&imeline", lambda: toggle_dock(window.timeline), "T"),
        "maximise": add_action(window, menu, "&Maximise view", window.maximise.toggle, "Ctrl+Space"),
    }
