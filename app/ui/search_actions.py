"""F3: search every action of the studio by name, as Blender's menu search does.

The actions are the menus' own (:func:`menu_actions` walks the menu bar), so a new menu entry is
found without being listed twice. Typed words match a path's words in any order, case aside;
Enter runs the highlighted action, Esc closes.
"""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QDialog, QLineEdit, QListWidget, QListWidgetItem, QVBoxLayout

SEP = " ▸ "


def plain(text: str) -> str:
    """A menu text without its mnemonic ampersands (a literal "&&" stays one "&")."""
    return text.replace("&&", "\0").replace("&", "").replace("\0", "&")


def menu_actions(menu_bar) -> list[tuple[str, QAction]]:
    """``(path, action)`` of every command in the menu bar, submenus walked (separators and the
    submenus themselves left out), in menu order, e.g. ``("View ▸ Numpad views ▸ Front", a)``."""
    found: list[tuple[str, QAction]] = []

    def walk(menu, prefix: str) -> None:
        for a in menu.actions():
            if a.isSeparator():
                continue
            path = prefix + plain(a.text())
            if a.menu() is not None:
                walk(a.menu(), path + SEP)
            elif a.text():
                found.append((path, a))

    for top in menu_bar.actions():
        if top.menu() is not None:
            walk(top.menu(), plain(top.text()) + SEP)
    return found


def matches(query: str, actions: list[tuple[str, QAction]]) -> list[tuple[str, QAction]]:
    """The actions whose path holds every word of ``query`` (case-insensitive); all for none."""
    words = query.lower().split()
    return [(p, a) for p, a in actions if all(w in p.lower() for w in words)]


def shortcut_text(action: QAction) -> str:
    """The action's shortcuts as the menus show them (", " between several)."""
    return ", ".join(k.toString(QKeySequence.SequenceFormat.NativeText) for k in action.shortcuts())


class ActionSearch(QDialog):
    """The search box over :func:`menu_actions` of ``window``'s menu bar."""

    def __init__(self, window) -> None:
        super().__init__(window)
        self.setWindowTitle("Search actions")
        self.actions_found = menu_actions(window.menuBar())
        self.query = QLineEdit(self)
        self.query.setPlaceholderText("Type part of an action's name…")
        self.list = QListWidget(self)
        layout = QVBoxLayout(self)
        layout.addWidget(self.query)
        layout.addWidget(self.list)
        self.query.textChanged.connect(self._fill)
        self.query.returnPressed.connect(self.run_current)
        self.list.itemActivated.connect(lambda _item: self.run_current())
        self.resize(460, 360)
        self._fill("")

    def _fill(self, text: str) -> None:
        self.list.clear()
        for path, action in matches(text, self.actions_found):
            keys = shortcut_text(action)
            item = QListWidgetItem(f"{path}    {keys}" if keys else path)
            item.setData(Qt.ItemDataRole.UserRole, action)
            if not action.isEnabled():
                item.setFlags(item.flags() & ~Qt.ItemFlag.ItemIsEnabled)
                item.setToolTip(action.toolTip())
            self.list.addItem(item)
        for i in range(self.list.count()):  # the first that can run is highlighted
            if self.list.item(i).flags() & Qt.ItemFlag.ItemIsEnabled:
                self.list.setCurrentRow(i)
                break

    def run_current(self) -> bool:
        """Close and trigger the highlighted action; False (staying open) when none can run."""
        item = self.list.currentItem()
        if item is None or not item.flags() & Qt.ItemFlag.ItemIsEnabled:
            return False
        action = item.data(Qt.ItemDataRole.UserRole)
        self.accept()
        action.trigger()
        return True


def open_search(window) -> ActionSearch:
    """Show the search (non-modal, focus in its box) and return it."""
    dialog = ActionSearch(window)
    dialog.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
    dialog.show()
    dialog.query.setFocus()
    return dialog
