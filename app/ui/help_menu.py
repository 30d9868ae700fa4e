"""The Help menu: the action search (F3), a sheet of every keyboard shortcut made from the menus
themselves (so it never disagrees with them), and the read-me that comes with the studio."""

from __future__ import annotations

import html
from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDialog, QTextBrowser, QVBoxLayout

from app.ui.search_actions import menu_actions, open_search, shortcut_text

#: The read-me beside the packages (a source checkout's; an installed wheel may not carry it).
README = Path(__file__).resolve().parents[2] / "README.md"


def shortcut_rows(window) -> list[tuple[str, str]]:
    """``(menu path, keys)`` of every menu action that has a shortcut, in menu order."""
    return [(path, keys) for path, a in menu_actions(window.menuBar()) if (keys := shortcut_text(a))]


def shortcut_sheet(window) -> str:
    """The shortcuts as an HTML table, one row per action (grouped by menu), plus the mouse."""
    rows, menu = [], None
    for path, keys in shortcut_rows(window):
        top, _, rest = path.partition(" ▸ ")
        if top != menu:
            menu = top
            rows.append(f"<tr><th colspan='2' align='left'>{html.escape(top)}</th></tr>")
        rows.append(f"<tr><td>{html.escape(rest)}</td><td><b>{html.escape(keys)}</b></td></tr>")
    mouse = (
        ("Left-drag", "the current brush (Ctrl inverts it; with Select, a new selection)"),
        ("Shift+left-drag", "pan (with Select: add to the selection)"),
        ("Middle-drag or Alt+left-drag", "orbit (Shift: pan)"),
        ("Wheel", "zoom (Ctrl: brush size)"),
    )
    rows.append("<tr><th colspan='2' align='left'>Mouse</th></tr>")
    rows += [f"<tr><td>{html.escape(a)}</td><td>{html.escape(b)}</td></tr>" for a, b in mouse]
    return "<table cellspacing='4'>" + "".join(rows) + "</table>"


def show_shortcuts(window) -> QDialog:
    dialog = QDialog(window)
    dialog.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
    dialog.setWindowTitle("Keyboard shortcuts")
    view = QTextBrowser(dialog)
    view.setHtml(shortcut_sheet(window))
    QVBoxLayout(dialog).addWidget(view)
    dialog.resize(520, 600)
    dialog.show()
    return dialog


def show_readme(window) -> QDialog | None:
    """The read-me, shown in the studio (None where there is none beside it)."""
    if not README.is_file():
        return None
    dialog = QDialog(window)
    dialog.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
    dialog.setWindowTitle("Read me")
    view = QTextBrowser(dialog)
    view.setOpenExternalLinks(True)
    view.setMarkdown(README.read_text(encoding="utf-8", errors="replace"))
    QVBoxLayout(dialog).addWidget(view)
    dialog.resize(720, 640)
    dialog.show()
    return dialog


def add_help_menu(window) -> dict[str, object]:
    """The Help menu (last in the menu bar), its actions by name."""
    from app.ui.qt_utils import add_action, set_available

    menu = window.menuBar().addMenu("&Help")
    actions = {
        "search": add_action(window, menu, "&Search actions…", lambda: open_search(window), "F3"),
        "shortcuts": add_action(window, menu, "&Keyboard shortcuts", lambda: show_shortcuts(window)),
        "readme": add_action(window, menu, "&Read me", lambda: show_readme(window)),
    }
    set_available(actions["readme"], README.is_file(), "No README.md beside this installation")
    return actions
