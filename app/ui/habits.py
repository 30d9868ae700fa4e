"""Blender's habits in the studio's menus: numpad views and Frame selected, the panel keys
(N, T, Ctrl+Space), the Help menu with the action search (F3) and Edit ▸ Preferences.
Installed once the window's own menus exist, so the search and the shortcut sheet see every
action."""

from __future__ import annotations

from app.ui.help_menu import add_help_menu
from app.ui.panel_keys import add_panel_actions
from app.ui.preferences import install_preferences
from app.ui.view_keys import add_view_actions


def install_habits(window) -> dict[str, object]:
    """Add the actions to ``window`` (View and Help menus); all of them by name."""
    view = next(a.menu() for a in window.menuBar().actions() if a.text() == "&View")
    view.addSeparator()
    actions = add_view_actions(window, view)
    actions |= add_panel_actions(window, view)
    actions |= add_help_menu(window)
    edit = next(a.menu() for a in window.menuBar().actions() if a.text() == "&Edit")
    edit.addSeparator()
    actions["preferences"] = install_preferences(window, edit)  # its keymap sets the keys above
    return actions
