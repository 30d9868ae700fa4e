"""The studio's main window: viewport in the centre, tool dock, status bar, menus and shortcuts.

Every modal dialog goes through one small ``ask_*`` / ``show_error`` method, so tests replace
them (monkeypatch) and never block.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from PySide6.QtCore import QEvent, QSettings, QSize, Qt
from PySide6.QtGui import QAction, QActionGroup, QDragEnterEvent, QDropEvent, QKeySequence
from PySide6.QtWidgets import (
    QDockWidget,
    QFileDialog,
    QMainWindow,
    QMessageBox,
    QToolBar,
    QWidget,
)

from app.document.animation import Document
from app.document.groom import GroomState
from app.document.groom_file import write_groom_apart
from app.ui import export
from app.ui.animation_io import (
    PROJECT_SUFFIX,
    open_filters,
    read_with_notes,
    save_filters,
    surface_of,
)
from app.ui.animation_model import AnimationModel
from app.ui.animation_ui import AnimationController
from app.ui.brush_tool import LABELS, SHORTCUTS, TIPS, brushes
from app.ui.colouring import displacement_scale
from app.ui.dialogs import PictureOptions, StillOptions, ask_picture_options, ask_still_options
from app.ui.engine_start import WAIT_MESSAGE, EngineStart
from app.ui.file_writes import FileWrites, save_failure
from app.ui.habits import install_habits
from app.ui.jobs import Job, JobRunner, JobStatus
from app.ui.kernel_preload import KernelPreload
from app.ui.kernel_warmup import CLUMPED_HAIR_STEP, RASTER_STEP, RENDER_HAIR_STEP
from app.ui.legend import RampLegend, readable_length
from app.ui.qt_utils import add_action, set_available
from app.ui.render_hair_dialog import DENSE, GrowOptions, ask_grow_options, grow
from app.ui.scene import COLOUR_MODES, Scene
from app.ui.selection_ui import SelectionUI
from app.ui.simulate_dialog import ask_simulate_options
from app.ui.status_line import ElidedLabel, StatusLine
from app.ui.stroke_files import StrokeFiles
from app.ui.timeline_dock import TimelineDock
from app.ui.tool_dock import ToolDock
from app.ui.undo_view import UndoView
from app.ui.up_axis_guess import with_inferred_up_axis
from app.ui.viewport import BRUSH_STEP, Viewport
from app.ui.widgets import WheelGuard, keep_controls_put
from hairtool import io, samples, serial_twins
from hairtool.errors import FormatError, HairtoolError
from hairtool.groom import Animation, Groom
from hairtool.guides.binding import clumps_by_default
from hairtool.guides.files import split_guides
from hairtool.io.obj import Mesh
from hairtool.simulate.options import SimulateOptions

MAX_RECENT = 10
FIRST_SIZE = (1280, 800)  # the window's first-start size, shrunk to fit smaller screens
MISSED_STRANDS = "The brush touched no strand: start the drag on the hair, or make the brush bigger ( ] )"
CLUMP_FULL = "These strands already clump fully: Ctrl+drag (or Erase) loosens them, painting brings them back"
SETTINGS_ORG, SETTINGS_APP = "hairtool", "Hairtool Studio"


def fitting_size(available: QSize) -> tuple[int, int]:
    """The first-start window size: :data:`FIRST_SIZE`, or the screen's free area when smaller."""
    return min(FIRST_SIZE[0], available.width()), min(FIRST_SIZE[1], available.height())


class MainWindow(QMainWindow):
    """``MainWindow(path)`` opens ``path``, or the procedural portrait when None (the
    ``hairtool-studio`` entry point then opens the bundled Sintel scene: :meth:`open_bundled_sample`)."""

    def __init__(
        self,
        path: str | os.PathLike[str] | None = None,
        *,
        settings: QSettings | None = None,
        groom: Groom | None = None,
        parent: QWidget | None = None,
        engine_ready: bool = True,
    ) -> None:
        """``engine_ready=False``: the kernels are not cached yet, so the window shows without the
        engine; :meth:`start_warmup` compiles them in the background and then starts it."""
        super().__init__(parent)
        self.setObjectName("HairtoolStudio")
        self.setStatusBar(StatusLine(self))  # first: messages are never painted over its widgets
        self.settings = settings if settings is not None else QSettings(SETTINGS_ORG, SETTINGS_APP)
        start = groom if groom is not None else samples.sample(samples.DEFAULT_SAMPLE)
        self.doc = Document(start)  # the document: every edit is a step on its one undo stack
        self.undo_stack = UndoView(self.doc.stack, self)
        self._shown_once = False
        self._stroke_points: np.ndarray | None = None
        self._stroke_clump: np.ndarray | None = None  # clump strengths when a clump stroke began
        # long work (key solves, simulation, video export): window.jobs.run(title, fn, on_done)
        self.jobs = JobRunner(lambda title, message: self.show_error(title, message), self)
        # saves and exports of the groom and the project: written in turn, off the GUI thread
        self.writes = FileWrites(self.jobs, self)
        self.last_snapshot_ms = 0.0  # what the last groom save's snapshot cost the GUI thread
        self._waiting_for_writes = False
        self.scene = Scene(start, parent=self, engine_ready=engine_ready, hair=self.doc.hair)
        self.engine_start: EngineStart | None = None
        # the bundled sample's render hair, on a first start bound once its kernels are cached
        self._pending_render_hair: Callable[[], None] | None = None
        self.grow_options = GrowOptions()  # the Grow render hair… dialog's last choices
        self.viewport = Viewport(self.scene, self)
        self.setCentralWidget(self.viewport)
        # the cached kernels loaded while the studio idles (started once the engine runs on them)
        self.kernel_preload = KernelPreload(self.preload_waits, self)
        self.dock = ToolDock(self.scene, self)
        self.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, self.dock)
        self._build_status_bar()
        self._build_menus()
        self._build_animation_ui()
        self._build_part2_menus()
        self.selection = SelectionUI(self)
        self.habit_actions = install_habits(self)  # numpad views, N / T, Ctrl+Space, Help and F3
        self.setAcceptDrops(True)
        self.setDockOptions(
            QMainWindow.DockOption.AnimatedDocks
            | QMainWindow.DockOption.AllowTabbedDocks
            | QMainWindow.DockOption.AllowNestedDocks
        )
        self.resize(*fitting_size(self.screen().availableGeometry().size()))
        self._default_layout = (self.saveState(), self.size())
        self._wheel_guard = WheelGuard(self)
        for dock in self.findChildren(QDockWidget):  # a passing wheel scrolls the dock instead
            keep_controls_put(dock, self._wheel_guard)

        self.viewport.stroke_started.connect(self._on_stroke_started)
        self.viewport.stroke_finished.connect(self._on_stroke_finished)
        self.viewport.cursor_moved.connect(self._on_cursor_moved)
        self.viewport.engine_wait.connect(lambda: self.statusBar().showMessage(WAIT_MESSAGE, 4000))
        self.scene.refused.connect(lambda text: self.statusBar().showMessage(text, 6000))
        self.viewport.frame_drawn.connect(self._update_frame_time)
        self.dock.param_edited.connect(self._on_param_edited)
        self.scene.groom_loaded.connect(self._on_document_changed)
        self.scene.groom_loaded.connect(self._update_counts)
        self.scene.drawn_changed.connect(self._update_counts)
        self.scene.groom_loaded.connect(self._update_legend)
        self.scene.display_changed.connect(self._update_legend)
        for signal in (
            self.animation.animation_changed,
            self.animation.view_mode_changed,
            self.animation.analysis_changed,
        ):
            signal.connect(self._update_legend)
        self.scene.path_changed.connect(self._update_title)
        self.undo_stack.cleanChanged.connect(self._update_title)
        self._update_counts()
        self._update_title()
        self._restore_layout()
        if path is not None:
            self.open_path(path)

    # -- dialogs (tests replace these) ------------------------------------------------------
    def show_error(self, title: str, message: str) -> None:
        QMessageBox.critical(self, title, message)

    def ask_open_path(self, title: str = "Open groom", filters: str | None = None) -> str | None:
        path, _ = QFileDialog.getOpenFileName(self, title, self.last_dir(), filters or open_filters())
        return path or None

    def ask_save_path(self, title: str, filters: str, suggested: str = "") -> str | None:
        start = str(Path(self.last_dir()) / suggested) if suggested else self.last_dir()
        path, _ = QFileDialog.getSaveFileName(self, title, start, filters)
        return path or None

    def ask_still_options(self) -> StillOptions | None:
        return ask_still_options(self, self.viewport_pixel_size(), self.scene.is_planar, self.last_dir())

    def ask_picture_options(self) -> PictureOptions | None:
        """A video's size and overlays (Export animation… to MP4, GIF or PNG frames)."""
        return ask_picture_options(self, self.viewport_pixel_size())

    # -- settings ----------------------------------------------------------------------------
    def last_dir(self) -> str:
        return str(self.settings.value("last_dir", str(Path.home())))

    def remember_dir(self, path: str | os.PathLike[str]) -> None:
        self.settings.setValue("last_dir", str(Path(path).resolve().parent))

    def recent_files(self) -> list[str]:
        value = self.settings.value("recent", [])
        if isinstance(value, str):  # QSettings gives a str for a one-element list
            value = [value]
        return [str(v) for v in value or []]

    def _add_recent(self, path: str | os.PathLike[str]) -> None:
        p = str(Path(path).resolve())
        recent = [p, *(r for r in self.recent_files() if r != p)][:MAX_RECENT]
        self.settings.setValue("recent", recent)
        self.remember_dir(p)

    def _restore_layout(self) -> None:
        geometry = self.settings.value("geometry")
        if geometry is not None:
            self.restoreGeometry(geometry)
        state = self.settings.value("window_state")
        if state is not None:
            self.restoreState(state)

    def start_warmup(self) -> None:
        """Compile the kernels in another process, progress in the status bar, then start the
        engine (a first start: see :mod:`app.ui.engine_start`)."""
        if self.engine_start is None and not self.scene.engine_ready:
            self.engine_start = EngineStart(self.scene, self.statusBar(), self)
            self.engine_start.step_ready.connect(self._on_warmup_step)
            self.engine_start.ended.connect(self._bind_pending_render_hair)
            self.engine_start.ended.connect(self._on_warmup_ended)
            self.engine_start.ended.connect(self.kernel_preload.start)
            self.viewport.wait_for_raster = True
            self.engine_start.start()

    def _on_warmup_step(self, label: str) -> None:
        if label == RENDER_HAIR_STEP:
            self._bind_pending_render_hair()
        elif label == RASTER_STEP:
            self.viewport.set_raster_ready()
        start = self.engine_start
        # the children's clumping on the kernels the warm-up compiled: the parallel ones
        if start is not None and CLUMPED_HAIR_STEP in start.done and serial_twins.parallel_in_use():
            self.scene.set_children_clump_ready()

    def _on_warmup_ended(self) -> None:
        if not self.viewport.raster_ready:  # what is not cached compiles when first used
            self.viewport.set_raster_ready()
        self.scene.set_children_clump_ready()

    def _bind_pending_render_hair(self) -> None:
        pending, self._pending_render_hair = self._pending_render_hair, None
        if pending is not None:
            self.statusBar().set_note("render hair", None)
            pending()

    def reset_layout(self) -> None:
        """Docks back where a first start puts them (tools and anime wave tabbed on the right,
        the timeline below), none floating, and the window at its first-start size."""
        state, size = self._default_layout
        for dock in self.findChildren(QDockWidget):
            dock.setFloating(False)
            dock.show()
        self.restoreState(state)
        self.dock.raise_()
        if not self.isMaximized() and not self.isFullScreen():
            self.resize(size)
        self.timeline.fit_height()
        self.statusBar().showMessage("layout reset", 3000)

    def showEvent(self, event) -> None:
        super().showEvent(event)
        if not self._shown_once:  # docks can only be sized once they are laid out
            self._shown_once = True
            self.timeline.fit_height()
            if self.scene.engine_ready:  # (a first start loads them after its warm-up)
                self.kernel_preload.start()

    def save_layout(self) -> None:
        self.settings.setValue("geometry", self.saveGeometry())
        self.settings.setValue("window_state", self.saveState())
        self.settings.sync()

    def closeEvent(self, event) -> None:
        if not self.wait_for_writes("quitting"):  # a Quit during this wait: the first one goes on
            event.ignore()
            return
        try:
            go_on = self.project.confirm_discard()  # False: Cancel, or a save that failed
        except Exception as e:  # a fault while saving: the window and its work stay
            self.show_error("Cannot close", f"The work could not be saved, so the studio stays open.\n\n{e}")
            go_on = False
        if not go_on:
            event.ignore()
            return
        self.jobs.shutdown()
        # the brush and frame workers end with the window: none of them emits to a closed one
        self.scene.moves.shutdown()
        self.animation_ui.frames.shutdown()
        if self.engine_start is not None:
            self.engine_start.stop()
        self.project.shutdown()
        self.save_layout()
        self.viewport.release_gl()
        super().closeEvent(event)

    def wait_for_writes(self, before: str) -> bool:
        """Let the saves still writing end first, saying so in the status bar (the window still
        answers); False while another caller is already waiting for them."""
        pending = self.writes.pending
        if not pending:
            return True
        if self._waiting_for_writes:
            return False
        names = ", ".join(dict.fromkeys(w.path.name for w in pending))
        self.statusBar().showMessage(f"Waiting for {names} to be written before {before}…")
        self._waiting_for_writes = True
        try:
            self.writes.wait()
        finally:
            self._waiting_for_writes = False
        return True

    # -- menus -------------------------------------------------------------------------------
    def _build_menus(self) -> None:
        bar = self.menuBar()
        file = bar.addMenu("&File")
        new = file.addMenu("&New from sample")
        sintel = self.open_bundled_sample
        add_action(self, new, "Sintel (hair and head)", self._asking(sintel), QKeySequence.StandardKey.New)
        new.addSeparator()
        for kind in samples.SAMPLES:
            add_action(self, new, kind.capitalize(), self._asking(lambda k=kind: self.new_from_sample(k)))
        add_action(self, file, "&Open…", self.open_dialog, QKeySequence.StandardKey.Open)
        self.recent_menu = file.addMenu("Open &Recent")
        self.recent_menu.aboutToShow.connect(self._fill_recent_menu)
        file.addSeparator()
        add_action(self, file, "&Save", lambda: self.save(wait=False), QKeySequence.StandardKey.Save)
        add_action(self, file, "Save &As…", lambda: self.save_as(wait=False), QKeySequence.StandardKey.SaveAs)
        file.addSeparator()
        add_action(self, file, "&Export still…", self.export_still_dialog, "Ctrl+E")
        add_action(self, file, "Export &groom…", lambda: self.export_groom_dialog(wait=False), "Ctrl+Shift+E")
        file.addSeparator()
        self.stroke_files = StrokeFiles(self)
        add_action(self, file, "Export S&trokes…", lambda: self.stroke_files.export_dialog())
        add_action(self, file, "Import / &Replay Strokes…", lambda: self.stroke_files.replay_dialog())
        file.addSeparator()
        add_action(self, file, "&Quit", self.close, QKeySequence.StandardKey.Quit)

        edit = bar.addMenu("&Edit")
        self.undo_action = undo = self.undo_stack.createUndoAction(self, "&Undo")
        undo.setShortcut(QKeySequence.StandardKey.Undo)
        self.redo_action = redo = self.undo_stack.createRedoAction(self, "&Redo")
        redo.setShortcuts([QKeySequence.StandardKey.Redo, QKeySequence("Ctrl+Y")])
        edit.addAction(undo)
        edit.addAction(redo)

        view = bar.addMenu("&View")
        # ("." as Blender's View Selected: F sizes the brush as in Blender; Home is the first frame)
        add_action(self, view, "&Frame all", self.viewport.frame_all, ".")
        self.ortho_action = add_action(self, view, "&2-D view", self.toggle_ortho, "5", checkable=True)
        view.aboutToShow.connect(self._sync_view_menu)
        up = view.addMenu("&Up axis")
        up.setToolTipsVisible(True)
        up_group = QActionGroup(self)
        self.up_axis_actions: dict[str, QAction] = {}
        for axis in ("Y", "Z"):
            a = add_action(self, up, f"{axis} up", lambda _=False, x=axis: self.set_up_axis(x))
            a.setCheckable(True)
            a.setToolTip(
                f"This groom's {axis} axis points up (HAIR, TressFX and OBJ files do not say; a USD "
                "stage does): the view turns, and puff, simulation and anime cycles pull along it"
            )
            up_group.addAction(a)
            self.up_axis_actions[axis] = a
        self.scene.up_axis_changed.connect(self._sync_view_menu)
        self.scene.groom_loaded.connect(self._sync_view_menu)
        self._sync_view_menu()
        colour = view.addMenu("&Colour by")
        group = QActionGroup(self)
        self.colour_actions: dict[str, QAction] = {}
        for i, (key, label) in enumerate(COLOUR_MODES.items()):
            a = add_action(self, colour, label, lambda _=False, k=key: self.scene.set_colour_mode(k),
                             f"Alt+{i + 1}", checkable=True)  # fmt: skip
            group.addAction(a)
            self.colour_actions[key] = a
        colour.aboutToShow.connect(lambda: self.colour_actions[self.scene.colour_mode].setChecked(True))
        view.addSeparator()
        add_action(self, view, "&Reset layout", self.reset_layout)
        view.addAction(self.dock.toggleViewAction())

        brush = bar.addMenu("&Brush")
        self._build_brush_actions(brush)
        brush.addSeparator()
        add_action(self, brush, "&Smaller", lambda: self.viewport.scale_brush(1.0 / BRUSH_STEP), "[")
        add_action(self, brush, "&Bigger", lambda: self.viewport.scale_brush(BRUSH_STEP), "]")
        size = add_action(self, brush, "Si&ze on canvas", lambda: self.viewport.sizing.start("radius"), "F")
        size.setToolTip("Move the mouse to size the brush, click or Enter keeps it, Esc or right-click "
                        "cancels (Blender's F)")  # fmt: skip
        strength = add_action(
            self, brush, "S&trength on canvas", lambda: self.viewport.sizing.start("strength"), "Shift+F"
        )
        strength.setToolTip("Move the mouse to set the strength (farther: stronger), click or Enter "
                            "keeps it, Esc or right-click cancels (Blender's Shift+F)")  # fmt: skip
        sizing = self.viewport.sizing  # (its last word, once it ends, fades as other messages do)
        sizing.message.connect(lambda text: self.statusBar().showMessage(text, 0 if sizing.active else 4000))
        brush.addSeparator()
        self.symmetry_action = add_action(
            self, brush, "&X mirror", lambda on: self.scene.set_symmetry(on), "Shift+X", checkable=True
        )
        self.front_only_action = add_action(
            self, brush, "&Front faces only", lambda on: self.scene.set_front_only(on), checkable=True
        )
        self.scene.tool_changed.connect(self._sync_brush_actions)
        self._sync_brush_actions()

        groom = bar.addMenu("&Groom")
        groom.setToolTipsVisible(True)
        add_action(self, groom, "&Grow render hair…", self.grow_render_hair_dialog, "Ctrl+G")
        self.remove_hair_action = add_action(self, groom, "&Remove render hair", self.remove_render_hair)
        groom.addSeparator()
        add_action(self, groom, "Load head &mesh…", self.load_mesh_dialog)
        self.remove_mesh_action = add_action(self, groom, "Remove &head mesh", self.remove_mesh)
        self.remove_mesh_action.setToolTip("Take the head or scalp mesh off this groom (undoable)")
        self.scene.mesh_changed.connect(self._sync_groom_menu)
        self.scene.drawn_changed.connect(self._sync_groom_menu)
        self.scene.groom_loaded.connect(self._sync_groom_menu)
        self._sync_groom_menu()

    def _build_brush_actions(self, menu) -> None:
        """One checkable action per brush, in the Brush menu and a toolbar, with its key."""
        self.brush_bar = QToolBar("Brushes", self)
        self.brush_bar.setObjectName("BrushToolBar")
        group = QActionGroup(self)
        self.brush_actions: dict[str, QAction] = {}
        for name in brushes():
            label = LABELS.get(name, name)
            a = add_action(self, menu, label, lambda _=False, b=name: self.scene.set_brush(b),
                           SHORTCUTS.get(name), checkable=True)  # fmt: skip
            a.setToolTip(f"{label} ({SHORTCUTS.get(name, '')}): {TIPS.get(name, '')}")
            group.addAction(a)
            self.brush_bar.addAction(a)
            self.brush_actions[name] = a
        self.addToolBar(Qt.ToolBarArea.TopToolBarArea, self.brush_bar)
        view = next(a.menu() for a in self.menuBar().actions() if a.text() == "&View")
        view.addAction(self.brush_bar.toggleViewAction())

    def _sync_brush_actions(self) -> None:
        tool = self.scene.tool
        self.brush_actions[tool.brush].setChecked(True)
        for action, on in ((self.symmetry_action, tool.symmetry), (self.front_only_action, tool.front_only)):
            if action.isChecked() != on:
                action.setChecked(on)

    # -- animation (timeline, playback, keys, recording) ---------------------------------------
    def _build_animation_ui(self) -> None:
        """``self.animation`` (the model other docks load animations into), the timeline dock,
        the Animation menu and the fps read-out in the status bar."""
        self.animation = AnimationModel(self.jobs, self, doc=self.doc)
        self.animation_ui = AnimationController(self, self.animation)
        actions = self.animation_ui.build_menu()
        steer = self.animation_ui.steer_keys
        self.timeline = TimelineDock(
            self.animation, actions, lambda t, m: self.show_error(t, m), self, steer=steer
        )
        self.addDockWidget(Qt.DockWidgetArea.BottomDockWidgetArea, self.timeline)
        self.animation_ui.bind_transport_keys(self.viewport, self.timeline)
        self.statusBar().addPermanentWidget(self.animation_ui.fps_label)
        view = next(a.menu() for a in self.menuBar().actions() if a.text() == "&View")
        view.addAction(self.timeline.toggleViewAction())

    # -- part 2: projects, anime dock, simulation, animation and keys export -----------------
    def _build_part2_menus(self) -> None:
        """``self.project`` (save/open, autosave, recovery), ``self.sources`` (anime dock,
        simulation), ``self.exporter`` (animation and keys export) and their menu entries."""
        from app.ui.animation_export import AnimationExporter
        from app.ui.animation_sources import AnimationSources
        from app.ui.capture_edit import CaptureEditor
        from app.ui.character_studio import CharacterStudio
        from app.ui.graph_editor import GraphEditorDock
        from app.ui.project_ui import ProjectController

        self.sources = AnimationSources(self)
        self.character = CharacterStudio(self)
        self.capture = CaptureEditor(self)
        self.graph_editor = GraphEditorDock(self)
        self.exporter = AnimationExporter(self)
        self.project = ProjectController(self, self.sources)
        menus = {a.text(): a.menu() for a in self.menuBar().actions()}
        file = menus["&File"]
        quit_action = file.actions()[-1]
        made: dict[str, QAction] = {}
        for text, slot, key in (
            ("Open &Project…", self.project.open_project_dialog, "Ctrl+Shift+O"),
            ("Save Pro&ject", lambda: self.project.save_project(wait=False), "Ctrl+Alt+S"),
            ("Save Project As…", lambda: self.project.save_project_as(wait=False), None),
            (None, None, None),
            ("Export &Animation…", self.exporter.export_animation_dialog, "Ctrl+Alt+E"),
            ("Export &Keys…", self.exporter.export_keys_dialog, None),
            (None, None, None),
        ):
            if text is None:
                file.insertSeparator(quit_action)
                continue
            action = QAction(text, self)
            if key is not None:
                action.setShortcut(QKeySequence(key))
            action.triggered.connect(lambda _=False, f=slot: f())
            file.insertAction(quit_action, action)
            made[text] = action
        self.exporter.bind_actions(made["Export &Animation…"], made["Export &Keys…"])
        self.character.build_menus(file, quit_action, new_menu=menus["&File"].actions()[0].menu())
        file.setToolTipsVisible(True)  # a greyed-out entry's tooltip says why
        animation = menus["A&nimation"]
        animation.addSeparator()
        add_action(self, animation, "&Simulate…", self.sources.simulate_dialog, "Ctrl+Alt+M")
        menus["&View"].addAction(self.sources.dock.toggleViewAction())
        menus["&View"].addAction(self.graph_editor.toggleViewAction())

    def ask_save_changes(self) -> str:
        """The one question before changed work is replaced (Open, Open Project, New, a drop,
        Quit): "save", "discard" or "cancel" (tests replace this)."""
        name = self.scene.path.name if self.scene.path is not None else "The untitled groom"
        buttons = QMessageBox.StandardButton
        box = QMessageBox(
            QMessageBox.Icon.Question,
            "Unsaved changes",
            f"{name} has changes that are not saved. Save them first?",
            buttons.Save | buttons.Discard | buttons.Cancel,
            self,
        )
        box.setInformativeText("Discard loses them; Cancel goes back to the work.")
        box.setDefaultButton(buttons.Save)
        box.setEscapeButton(buttons.Cancel)
        answer = box.exec()
        return {buttons.Save: "save", buttons.Discard: "discard"}.get(buttons(answer), "cancel")

    def ask_restore_recovery(self, path: str) -> bool:
        """Restore the autosave a crashed session left (True), or discard it (tests replace this)."""
        from app.ui.project_ui import recovery_question

        buttons = QMessageBox.StandardButton
        box = QMessageBox(QMessageBox.Icon.Question, "Restore autosaved work", recovery_question(path),
                          buttons.NoButton, self)  # fmt: skip
        restore = box.addButton("Restore", QMessageBox.ButtonRole.AcceptRole)
        box.addButton(buttons.Discard)
        box.setDefaultButton(restore)
        box.exec()
        return box.clickedButton() is restore

    def _asking(self, action: Callable[[], object]) -> Callable[..., None]:
        """A menu action that replaces the work: it runs once changed work was saved or discarded."""

        def run(*_: object) -> None:
            if self.project.confirm_discard():
                action()

        return run

    def ask_simulate_options(self, options: SimulateOptions) -> SimulateOptions | None:
        """The Simulate… dialog: SimulateOptions or None (tests replace this)."""
        return ask_simulate_options(self, options, self.scene.result)

    def toggle_ortho(self) -> None:
        """2-D (orthographic front view) ⇄ 3-D (perspective), whatever the menu's check mark says."""
        self.viewport.set_ortho(not self.viewport.camera.ortho)
        self._sync_view_menu()

    def _sync_view_menu(self) -> None:
        self.ortho_action.setChecked(self.viewport.camera.ortho)
        self.up_axis_actions[self.scene.up_axis].setChecked(True)

    def set_up_axis(self, axis: str) -> None:
        """View ▸ Up axis: which axis of this groom points up (one undo step; kept in projects
        and written to USD as the stage's upAxis)."""
        try:
            self.scene.set_up_axis(axis)
        except HairtoolError as e:
            self.show_error("Cannot set the up axis", str(e))
        self._sync_view_menu()

    def _fill_recent_menu(self) -> None:
        self.recent_menu.clear()
        for path in self.recent_files():
            self.recent_menu.addAction(path, self._asking(lambda p=path: self.open_path(p)))
        self.recent_menu.setEnabled(True)

    # -- status bar --------------------------------------------------------------------------
    def _build_status_bar(self) -> None:
        """Counts, then the message (:class:`StatusLine`), then the read-outs, the jobs' progress,
        the legend and the playback rate; every text shortens itself before it would overlap."""
        bar = self.statusBar()
        self.counts_label = ElidedLabel(min_width=60)
        self.frame_label = ElidedLabel(min_width=40)
        self.frame_label.setObjectName("FrameTime")
        self.cursor_label = ElidedLabel(min_width=40)
        bar.insertWidget(0, self.counts_label)
        bar.addWidget(self.frame_label)  # beside the message: both shorten when space is short
        bar.addPermanentWidget(self.cursor_label)
        self.job_status = JobStatus(self.jobs)
        bar.addPermanentWidget(self.job_status)
        self.legend = RampLegend()
        bar.addPermanentWidget(self.legend)

    def _update_legend(self, *_: object) -> None:
        """The distance ramp's legend, in the groom's units, while distances colour the strands."""
        mpu = self.scene.rest.metadata.meters_per_unit
        m = self.animation
        if m.animation is not None and m.view_mode == "error" and m.error_scale > 0:
            self.legend.show_scale(
                "Key error", *readable_length(m.error_scale, mpu),
                "distance of each vertex from its reconstruction from the DP keys; "
                "the top of the ramp is the keys' worst vertex over the whole animation",
            )  # fmt: skip
        elif m.animation is None and self.scene.colour_mode == "displacement":
            self.legend.show_scale(
                "Moved", *readable_length(displacement_scale(self.scene), mpu),
                "distance of each vertex from its rest position; the top of the ramp is the "
                "median strand length (grey: not moved)",
            )  # fmt: skip
        else:
            self.legend.hide()

    def _update_counts(self) -> None:
        g, b = self.scene.result, self.scene.children_binding()
        text = f"{g.strand_count:,} strands · {g.vertex_count:,} vertices"
        if b is not None:
            text = f"{g.strand_count:,} guides · {b.child_count:,} children · {b.vertex_count:,} vertices"
        self.counts_label.setText(text)

    def _on_document_changed(self) -> None:
        """Another groom opened: the status line forgets the last one (its messages, its frame
        times: the pipeline time of its last stroke is not this groom's)."""
        self.statusBar().clear_document()
        self.scene.last_update_ms = 0.0
        self.frame_label.setText("")
        self.cursor_label.setText("")

    def preload_waits(self) -> bool:
        """A button is held in the viewport or on the timeline's frame (scrubbing): the kernel
        preload waits, so a drag's frames never wait for a kernel's load (20-40 ms each)."""
        return self.viewport.is_dragging() or self.animation.scrubbing

    def event(self, event: QEvent) -> bool:
        if event.type() == QEvent.Type.StatusTip:  # a menu entry's tip: through the status line
            if event.tip():
                self.statusBar().showMessage(event.tip(), 4000)
            return True
        return super().event(event)

    def _update_frame_time(self) -> None:
        v, s = self.viewport, self.scene
        total = s.last_update_ms + v.last_upload_ms + v.last_draw_ms
        self.frame_label.detail = (
            f"the last update: engine pipeline {s.last_update_ms:.1f} ms, upload to the GPU "
            f"{v.last_upload_ms:.1f} ms, draw {v.last_draw_ms:.1f} ms"
        )
        self.frame_label.setText(f"update {total:.1f} ms")

    def _on_cursor_moved(self, cursor) -> None:
        if cursor is None:
            self.cursor_label.setText("")
        else:
            self.cursor_label.setText("cursor ({:.3f}, {:.3f}, {:.3f})".format(*cursor))

    def _update_title(self) -> None:
        name = self.scene.path.name if self.scene.path is not None else "untitled"
        dirty = "" if self.undo_stack.isClean() else " *"
        self.setWindowTitle(f"{name}{dirty} — Hairtool Studio")

    # -- editing -------------------------------------------------------------------------------
    def _on_stroke_started(self) -> None:
        self._stroke_points = self.scene.result.points.copy()
        self._stroke_clump = self.scene.pipeline.clump_strength if self.scene.brush == "clump" else None

    def _on_stroke_finished(self, before: object, after: object) -> None:
        """The stroke is a step of the document already: what it did is told in the status bar."""
        start, self._stroke_points = self._stroke_points, None
        moved = start is None or not np.array_equal(start, self.scene.result.points)
        if not moved and not self.viewport.stroke_touched:
            self.statusBar().showMessage(MISSED_STRANDS, 6000)
        elif self._stroke_clump is not None and not moved:
            if np.array_equal(self._stroke_clump, self.scene.pipeline.clump_strength):
                self.statusBar().showMessage(CLUMP_FULL, 6000)
        self._stroke_clump = None

    def _on_param_edited(self, name: str, value: object, drag: object) -> None:
        before = self.scene.params
        try:
            after = self.scene.with_param(name, value)
        except HairtoolError as e:
            self.show_error("Invalid parameter", str(e))
            self.dock.refresh_params()
            return
        if after != before:
            self.scene.set_params(after, name, drag)

    # -- files ----------------------------------------------------------------------------------
    def set_groom(
        self, groom: Groom, path: str | os.PathLike[str] | None = None, mesh: Mesh | None = None
    ) -> None:
        """Show a new groom on its own head ``mesh`` (None: none); its strokes start afresh, so
        the undo history is cleared (and an animation on the timeline is closed)."""
        self.animation.reset()  # the last document's frame rate and key settings are not this one's
        self.undo_stack.clear()
        self._pending_render_hair = None  # the bundled sample's children, not this groom's
        self.scene.load(groom, path, mesh=mesh)
        self.undo_stack.setClean()
        self._update_title()

    def new_from_sample(self, kind: str) -> None:
        """A procedural sample groom, as a new untitled scene (no head mesh)."""
        self.set_groom(samples.sample(kind))

    def open_bundled_sample(self) -> bool:
        """The studio's default scene: Sintel's hair on her head, shipped in ``app.resources``.

        It opens untitled, so Save asks where to write instead of touching the shipped file.
        """
        from app import resources
        from hairtool.guides.binding import bind_scalp
        from hairtool.io.obj import read_mesh

        try:
            groom = io.read_groom(resources.path(resources.SINTEL_HAIR))
            mesh = read_mesh(resources.path(resources.SINTEL_HEAD))
        except HairtoolError as e:  # a broken installation: say so, keep the scene
            self.show_error("Cannot open the bundled sample", str(e))
            return False
        self.set_groom(groom, mesh=mesh)
        self.viewport.frame_all()

        def render_hair() -> None:  # Sintel's hair as guides with interpolated render hair, shaded
            self.scene.set_binding(
                bind_scalp(groom, mesh, resources.SINTEL_CHILDREN, seed=resources.SINTEL_CHILD_SEED)
            )
            self.scene.set_colour_mode("hair")

        waiting = "Sintel's guides; her render hair follows once the engine is ready"
        self._with_render_hair(render_hair, waiting)
        return True

    def _with_render_hair(self, bind: Callable[[], None], waiting: str) -> None:
        """Give the scene its render hair now, or, on a first start, once the engine is ready:
        binding and shading would compile here, with the window frozen."""
        if self.scene.engine_ready:
            bind()
        else:
            self._pending_render_hair = bind
            self.statusBar().set_note("render hair", waiting)

    def _open_with_guides(
        self, hair: Groom, guides: Groom, path: str | os.PathLike[str], mesh: Mesh | None = None
    ) -> None:
        """A file of render hair and its guides (as the studio saves it): the brushes work on the
        guides, and the render hair, bound to them exactly, follows (and is what Save writes)."""
        from hairtool.guides.binding import bind_to_guides

        self.set_groom(guides, path, mesh)

        def render_hair() -> None:
            self.scene.set_binding(bind_to_guides(hair, guides))
            self.scene.set_colour_mode("hair")
            self.statusBar().showMessage(
                f"{hair.strand_count:,} render strands follow the {guides.strand_count:,} guides", 5000
            )

        self._with_render_hair(render_hair, "The guides; the render hair follows once the engine is ready")

    # -- render hair ------------------------------------------------------------------------
    def _sync_groom_menu(self) -> None:
        why_not = "No render hair to remove: Groom ▸ Grow render hair… makes some"
        set_available(self.remove_hair_action, self.scene.binding is not None, why_not)
        set_available(self.remove_mesh_action, self.scene.mesh is not None, "No head mesh to remove")

    def ask_grow_options(self, options: GrowOptions) -> GrowOptions | None:
        """The Grow render hair… dialog: GrowOptions or None (tests replace this)."""
        painted = int(self.scene.locked.sum())
        return ask_grow_options(self, options, self.scene.rest, self.scene.mesh, painted)

    def grow_render_hair_dialog(self) -> Job | None:
        options = self.ask_grow_options(self.grow_options)
        return None if options is None else self.grow_render_hair(options)

    def grow_render_hair(self, options: GrowOptions) -> Job:
        """Bind in a worker thread, then show the render hair: one undo step, grown from the
        strands, or picked guides that replace the groom (the strands their render hair)."""
        self.grow_options = options
        dense = options.mode == DENSE
        groom = self.scene.result if dense else self.scene.rest  # dense: the strands as edited
        rest, mesh, painted = self.scene.rest, self.scene.mesh, self.scene.locked.copy()

        def work(progress, cancelled):
            progress(None, "binding the render hair to its guides")
            return grow(options, groom, mesh, painted)

        def done(result) -> None:
            guides, binding = result
            if self.scene.rest is not rest:
                return  # another groom was opened meanwhile
            if dense:
                # one step: the picked guides on the same head, the strands their render hair
                # (an animation of the old strands closes with them; Undo brings both back)
                self.scene.moves.drain()
                clump = clumps_by_default(binding)
                picked = GroomState(guides, self.scene.params, None, mesh, binding, None, clump)
                self.doc.open_groom(picked, text="Grow render hair (picked guides)")
                n, g = binding.child_count, guides.strand_count
                self.statusBar().showMessage(f"{n:,} strands follow {g:,} guides picked among them", 5000)
            else:
                self.scene.set_binding(binding, text="Grow render hair")
            self.scene.set_colour_mode("hair")

        return self.jobs.run("Growing render hair", work, done, group="render-hair")

    def remove_render_hair(self) -> None:
        if self.scene.binding is not None:
            self.scene.set_binding(None, text="Remove render hair")

    def open_dialog(self) -> None:
        """File ▸ Open: asks about changed work first (Cancel opens nothing)."""
        if not self.project.confirm_discard():
            return
        path = self.ask_open_path()
        if path:
            self.open_path(path)

    def open_path(self, path: str | os.PathLike[str]) -> bool:
        """Open a project (``.hairproj``), any readable groom, or an animation (USD time samples,
        ``.npz``, BVH as a skeleton) into the timeline on its first frame, on the file's own
        head mesh (USD: its Mesh prims) or none; on failure the scene is kept."""
        if Path(path).suffix.lower() == PROJECT_SUFFIX:
            ok = self.project.open_project(path)
            if ok:
                self._add_recent(path)
            return ok
        if self.character.handles(path):  # a character with hair bones (app.ui.character_studio)
            ok = self.character.open(path)
            if ok:
                self._add_recent(path)
            return ok
        self.character.close()
        try:
            obj, capture, notes = read_with_notes(path)
            mesh = surface_of(path)
        except HairtoolError as e:
            self.show_error("Cannot open file", str(e))
            return False
        if isinstance(obj, Animation):
            self.set_groom(obj.rest, path, mesh)
            if obj.n_frames > 1:  # (a BVH comes with its capture, whose key poses are edited by IK)
                self.animation.load_animation(obj, str(path), capture=capture)
                self.undo_stack.clear()  # a file opened: nothing to undo, nothing unsaved
        else:
            obj, said = with_inferred_up_axis(path, obj)
            hair, guides = split_guides(obj)
            if guides is None:
                self.set_groom(obj, path, mesh)
            else:
                self._open_with_guides(hair, guides, path, mesh)
            if said is not None:
                notes.append(said)
        if notes:  # what the reader dropped, and the up axis it chose
            self.statusBar().showMessage("; ".join(notes), 10_000)
        self._add_recent(path)
        return True

    def save(self, wait: bool = True) -> bool:
        """Write the groom to its own file (Save As for a format that cannot be written). The
        snapshot is taken now and written in a worker; ``wait``: return once it is written (True)
        or has failed (False), the window answering meanwhile; else True once it is queued."""
        path = self.scene.path
        if path is None or not any(path.suffix.lower() in f.extensions and f.writable for f in io.FORMATS):
            return self.save_as(wait)
        return self._write_groom(path, adopt=True, wait=wait)

    def save_as(self, wait: bool = True) -> bool:
        stem = self.scene.path.stem if self.scene.path is not None else "groom"
        path = self.ask_save_path("Save groom as", save_filters(), f"{stem}.usda")
        return bool(path) and self._write_groom(path, adopt=True, wait=wait)

    def export_groom_dialog(self, wait: bool = True) -> bool:
        stem = self.scene.path.stem if self.scene.path is not None else "groom"
        path = self.ask_save_path("Export edited groom", save_filters(), f"{stem}_edited.usda")
        return bool(path) and self.export_groom(path, wait)

    def export_groom(self, path: str | os.PathLike[str], wait: bool = True) -> bool:
        """Write the edited groom to any writable format; the current file stays the same."""
        return self._write_groom(path, adopt=False, wait=wait)

    def _write_groom(self, path: str | os.PathLike[str], *, adopt: bool, wait: bool) -> bool:
        """Snapshot the groom (and head) now, write it after the writes already queued. Once
        written, a Save makes the snapshot's state the saved one (edits made meanwhile stay
        unsaved) and adopts the file, unless the document was replaced meanwhile."""
        t0 = time.perf_counter()
        build, mesh = self.scene.export_snapshot(), self.scene.mesh
        mark = self.undo_stack.mark() if adopt else None
        self.last_snapshot_ms = (time.perf_counter() - t0) * 1e3

        def written() -> None:
            self.remember_dir(path)
            if mark is not None and self.undo_stack.setCleanAt(mark):
                self.scene.set_path(path)
                self._add_recent(path)
            self.statusBar().showMessage(f"wrote {path}", 5000)

        item = self.writes.queue(
            f"{'Saving' if adopt else 'Exporting'} {Path(path).name}",
            Path(path),
            lambda: write_groom_apart(path, build(), mesh),  # (usd-core holds the GIL: apart)
            written,
            lambda e: self.show_error("Cannot write file", save_failure(path, e)),
        )
        return self.writes.wait(item) if wait else True

    def load_mesh_dialog(self) -> None:
        path = self.ask_open_path("Load head mesh", "Wavefront OBJ (*.obj);;USD meshes (*.usda *.usdc *.usd)")
        if path:
            self.load_mesh(path)

    def load_mesh(self, path: str | os.PathLike[str]) -> bool:
        """Put this groom on the head mesh of an OBJ file (or a USD file's Mesh prims); undoable."""
        from hairtool.io.obj import read_mesh

        try:
            mesh = surface_of(path) if Path(path).suffix.lower() != ".obj" else read_mesh(path)
            if mesh is None:
                raise FormatError(path, "no mesh in this file")
        except HairtoolError as e:
            self.show_error("Cannot load head mesh", str(e))
            return False
        self.remember_dir(path)
        return self.scene.set_mesh(mesh, "Load head mesh")

    def remove_mesh(self) -> None:
        """Take the head mesh off this groom (undoable)."""
        if self.scene.mesh is not None:
            self.scene.set_mesh(None, "Remove head mesh")

    # -- stills ----------------------------------------------------------------------------------
    def viewport_pixel_size(self) -> tuple[int, int]:
        dpr = self.viewport.devicePixelRatioF()
        return max(1, round(self.viewport.width() * dpr)), max(1, round(self.viewport.height() * dpr))

    def export_still_dialog(self) -> bool:
        o = self.ask_still_options()
        return o is not None and self.export_still(o.path, o.size, o.transparent, overlays=o.overlays)

    def export_still(
        self,
        path: str | os.PathLike[str],
        size: tuple[int, int] | None = None,
        transparent: bool = False,
        *,
        overlays: bool = False,
    ) -> bool:
        """PNG (any groom) or SVG (2-D grooms) of what the view draws (render hair at full
        density, an animation frame when one is shown); ``size`` defaults to the viewport's;
        ``overlays``: the brush circle, mirror plane and mask tint too."""
        size = size or self.viewport_pixel_size()
        try:
            with self.viewport.current_context() as ctx:
                export.export_still(
                    path,
                    self.viewport.drawn(mask=overlays),
                    self.viewport.camera,
                    size,
                    transparent=transparent,
                    mesh=self.scene.mesh,
                    planar=self.scene.is_planar,
                    ctx=ctx,
                    overlays=self.viewport.overlays(size) if overlays else None,
                )
        except HairtoolError as e:
            self.show_error("Cannot export still", str(e))
            return False
        self.remember_dir(path)
        self.statusBar().showMessage(f"wrote {path}", 5000)
        return True

    # -- drag and drop ---------------------------------------------------------------------------
    def dragEnterEvent(self, event: QDragEnterEvent) -> None:
        if any(u.isLocalFile() for u in event.mimeData().urls()):
            event.acceptProposedAction()

    def dropEvent(self, event: QDropEvent) -> None:
        files = [u.toLocalFile() for u in event.mimeData().urls() if u.isLocalFile()]
        if files:
            event.acceptProposedAction()
            if self.project.confirm_discard():
                self.open_path(files[0])
