"""What the studio's controllers need from the window that owns them, as an interface.

The controllers (projects, animation sources, the animation glue, the exporters) are handed
their owner as a :class:`StudioHost` and never import the window, so the window imports them
and no import circle forms (an import-linter contract holds it). ``MainWindow`` is the one
implementation; its Qt methods (status bar, menus, docks) are part of the interface.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from PySide6.QtCore import QSettings, Qt
    from PySide6.QtWidgets import QDockWidget, QMenuBar, QStatusBar, QStyle

    from app.document.animation import Document
    from app.ui.animation_model import AnimationModel
    from app.ui.dialogs import PictureOptions
    from app.ui.file_writes import FileWrites
    from app.ui.jobs import JobRunner
    from app.ui.scene import Scene
    from app.ui.tool_dock import ToolDock
    from app.ui.undo_view import UndoView
    from app.ui.viewport import Viewport
    from hairtool.simulate.options import SimulateOptions


class UnsavedWork(Protocol):
    """The window's project controller, as the other controllers ask it about unsaved work."""

    def confirm_discard(self) -> bool: ...


class StudioHost(Protocol):
    settings: QSettings
    doc: Document
    undo_stack: UndoView
    jobs: JobRunner
    writes: FileWrites
    scene: Scene
    viewport: Viewport
    dock: ToolDock
    animation: AnimationModel
    project: UnsavedWork

    # -- asking the user (tests replace these) --------------------------------------------------
    def show_error(self, title: str, message: str) -> None: ...
    def ask_open_path(self, title: str = ..., filters: str | None = None) -> str | None: ...
    def ask_save_path(self, title: str, filters: str, suggested: str = "") -> str | None: ...
    def ask_save_changes(self) -> str: ...
    def ask_restore_recovery(self, path: str) -> bool: ...
    def ask_simulate_options(self, options: SimulateOptions) -> SimulateOptions | None: ...
    def ask_picture_options(self) -> PictureOptions | None: ...

    # -- the window's own file actions ------------------------------------------------------
    def save(self, wait: bool = True) -> bool: ...

    # -- the window's places ---------------------------------------------------------------------
    def remember_dir(self, path: str | os.PathLike[str]) -> None: ...
    def viewport_pixel_size(self) -> tuple[int, int]: ...
    def statusBar(self) -> QStatusBar: ...
    def menuBar(self) -> QMenuBar: ...
    def style(self) -> QStyle: ...
    def addDockWidget(self, area: Qt.DockWidgetArea, dock: QDockWidget) -> None: ...
    def tabifyDockWidget(self, first: QDockWidget, second: QDockWidget) -> None: ...
