"""Projects in the studio: Save Project / Open Project, the unsaved-changes question on close,
autosave to a recovery file, and the offer to restore it after a crash.

The file format is :mod:`hairtool.project`. "Changed since the last save" has one meaning, the
undo stack's clean state: strokes, parameter edits, key edits, dope-sheet steps and a new,
replaced or closed animation are undo steps, and work restored from the recovery file leaves
the clean state for good (``resetClean``) until the next save. Saving, opening and New set it
clean again. The animation side of a project is the document's (``window.doc.state``, written
and read by :mod:`app.document.project_io`).

The recovery file lives beside the settings file (an INI file, as in tests) or in
``QStandardPaths.AppDataLocation``; it is written on a timer from a plain thread (the groom and
animation are immutable arrays, so the GUI never waits for the disk) and removed on a clean
close. Found at start-up with the last session not marked as closed cleanly, it is offered
through ``window.ask_restore_recovery`` (tests replace it).
"""

from __future__ import annotations

import dataclasses
import os
import threading
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, QSettings, QStandardPaths, QTimer, Signal, Slot

from app.document import project_io
from app.render.camera import Camera
from app.ui.file_writes import save_failure
from hairtool import project as pf
from hairtool.errors import FormatError, HairtoolError

if TYPE_CHECKING:
    from app.ui.animation_sources import AnimationSources
    from app.ui.host import StudioHost

RECOVERY_NAME = "recovery" + pf.SUFFIX
AUTOSAVE_MS = 60_000
PROJECT_FILTERS = f"Hairtool project (*{pf.SUFFIX})"


def recovery_folder(settings: QSettings) -> Path:
    """Beside an INI settings file; else the application's data folder."""
    if settings.format() == QSettings.Format.IniFormat and settings.fileName():
        return Path(settings.fileName()).resolve().parent
    return Path(QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation))


def recovery_question(path: str | os.PathLike[str], now: datetime | None = None) -> str:
    """The recovery offer in words: when the work was autosaved (the file's time) and where."""
    saved = datetime.fromtimestamp(Path(path).stat().st_mtime)
    now = now or datetime.now()
    if saved.date() == now.date():
        when = f"today at {saved:%H:%M}"
    else:
        when = f"on {saved.day} {saved:%B %Y} at {saved:%H:%M}"
    return (
        f"Hairtool Studio did not close properly last time. Its work was autosaved {when}.\n"
        f"Restore it? Discard deletes the autosave.\n\n{path}"
    )


class ProjectController(QObject):
    """Owned by the window (``window.project``); see the module docstring."""

    saved = Signal(str)
    opened = Signal(str)
    autosave_failed = Signal(str)  # from the autosave thread, delivered in the window's

    def __init__(self, window: StudioHost, sources: AnimationSources, autosave_ms: int = AUTOSAVE_MS) -> None:
        super().__init__(window)
        self.window, self.sources = window, sources
        self.path: Path | None = None
        self._changes = 0  # counts edits; autosave writes when it moved since the last autosave
        self._autosaved_at = 0
        self._autosave_thread: threading.Thread | None = None
        self.autosave_error: str | None = None
        self.recovery_path = recovery_folder(window.settings) / RECOVERY_NAME
        window.undo_stack.indexChanged.connect(self._changed)
        # The project's path belongs to the document: another groom opened is not this project
        # (opening a project sets it again, after the groom is loaded).
        window.scene.groom_loaded.connect(self._forget_path)
        self.autosave_failed.connect(self._show_autosave_failure)
        self.timer = QTimer(self)
        self.timer.setInterval(max(int(autosave_ms), 1000))
        self.timer.timeout.connect(self.autosave)
        self.timer.start()
        self._offer_pending = self._crashed_before()
        window.settings.setValue("session/clean_exit", False)
        window.settings.sync()
        if self._offer_pending:
            QTimer.singleShot(0, self.offer_recovery)

    def _forget_path(self) -> None:
        self.path = None

    # -- changes ---------------------------------------------------------------------------
    def _changed(self, *_: object) -> None:
        self._changes += 1

    def _mark_unsaved(self) -> None:
        """Work no undo step holds (restored from the recovery file): unsaved until the next save."""
        self.window.undo_stack.resetClean()
        self._changed()

    def has_unsaved_changes(self) -> bool:
        return not self.window.undo_stack.isClean()

    def _mark_saved(self) -> None:
        self.window.undo_stack.setClean()

    # -- building and applying -------------------------------------------------------------------
    def current_project(self) -> pf.Project:
        """The window's state as a project (cheap: arrays are shared, not copied)."""
        w = self.window
        scene, model = w.scene, w.animation
        scene.start_engine()  # a first start's engine may still be on its way: wait for it here
        source = None if scene.path is None or scene.path.suffix == pf.SUFFIX else str(scene.path)
        settings: dict = {
            "timeline": {"frame": model.frame, "view_mode": model.view_mode, "loop": model.loop},
        }
        settings.update(self.sources.to_settings())
        # the animation side: the document's (the capture with its edits, keys a key edit holds)
        state = w.doc.state
        settings.update(project_io.animation_settings(state))
        capture = getattr(w, "capture", None)
        if "capture" in settings and capture is not None:  # the pose tool's chain beside it
            settings["capture"]["chain"] = capture.chain
        return pf.Project.from_pipeline(
            scene.pipeline,
            brush=_brush_settings(scene.tool),
            display={
                "colour_mode": scene.colour_mode,
                "ramp": scene.ramp,
                "line_width": scene.line_width,
                "ortho": bool(w.viewport.camera.ortho),
                "show_guides": scene.show_guides,
                "clump_children": scene.clump_children,
                "drag_percent": scene.drag_percent,
                "release_percent": scene.release_percent,
                "camera": w.viewport.camera.state(),
            },
            animation=state.animation,
            animation_source=state.source,
            key_settings=dataclasses.asdict(state.settings),
            settings=settings,
            groom_source=source,
            children=scene.binding,
            mesh=scene.mesh,
        )

    def apply(self, project: pf.Project, path: str | os.PathLike[str] | None) -> None:
        """Show a project: groom, parameters, strokes, brush, display, animation, keys, docks."""
        w = self.window
        scene, model = w.scene, w.animation
        for job in w.jobs.active("simulate"):  # its result belongs to the scene being replaced
            w.jobs.cancel(job)
        model.reset()  # frame rate and key settings: the project's own, or the defaults
        w.undo_stack.clear()
        # the document's groom side: its strokes replayed (or taken as saved), its render hair
        # clumped as saved (a project from before the switch: off, as it looked then)
        scene.open(project_io.groom_of(project), path)
        _apply_each(
            w,
            (
                lambda: scene.set_radius(float(project.brush["radius"])),
                lambda: scene.set_intensity(float(project.brush["intensity"])),
                lambda: scene.set_align_mode(str(project.brush["align_mode"])),
                *_brush_setters(scene, project.brush),
                lambda: scene.set_colour_mode(str(project.display["colour_mode"])),
                lambda: scene.set_ramp(str(project.display["ramp"])),
                lambda: scene.set_line_width(float(project.display["line_width"])),
                lambda: w.viewport.set_ortho(bool(project.display["ortho"])),
                lambda: scene.set_show_guides(bool(project.display.get("show_guides", True))),
                lambda: scene.set_display_percent(
                    float(project.display.get("drag_percent", scene.drag_percent)),
                    float(project.display.get("release_percent", scene.release_percent)),
                ),
            ),
        )
        if project.animation is not None:
            _apply_each(w, (lambda: self._apply_animation(project, path),))
            timeline = project.settings.get("timeline", {})
            _apply_each(
                w,
                (
                    lambda: model.set_view_mode(str(timeline["view_mode"])),
                    lambda: model.set_loop(bool(timeline["loop"])),
                    lambda: model.set_frame(int(timeline["frame"])),
                ),
            )
        self.sources.apply_settings(project.settings)
        if project.animation is not None and getattr(w, "capture", None) is not None:
            w.capture.apply_settings(project.settings.get("capture"))
        if "camera" in project.display:  # after everything that frames the view again
            _apply_each(w, (lambda: w.viewport.set_camera(Camera.from_state(project.display["camera"])),))
        w.undo_stack.clear()  # an opened project: nothing to undo
        self._mark_saved()

    def _apply_animation(self, project: pf.Project, path: str | os.PathLike[str] | None) -> None:
        """The project's animation side becomes the document's (its settings, its capture with
        the edits, the keys a key edit held); what the document cannot use is reported, and the
        animation comes without it."""
        model = self.window.animation
        try:
            state = project_io.animation_state(project, str(path or "project"))
        except HairtoolError:  # (reported by the caller) the animation comes without what failed
            model.load_animation(project.animation, project.animation_source)
            raise
        what = {"capture": state.capture, "edits": state.edits, "channel_edits": state.channel_edits}
        try:
            model.load_animation(state.animation, state.source, settings=state.settings, **what)
        except HairtoolError:  # settings no keys meet: the animation comes with ours
            model.load_animation(state.animation, state.source, **what)
            raise
        if state.held_keys:
            model.doc.edit_frames(state.animation, state.held_keys, "Keys held")

    # -- save and open ---------------------------------------------------------------------
    def save_project(self, wait: bool = True) -> bool:
        if self.path is None:
            return self.save_project_as(wait)
        return self.save_to(self.path, wait)

    def save_project_as(self, wait: bool = True) -> bool:
        stem = self.window.scene.path.stem if self.window.scene.path is not None else "project"
        path = self.window.ask_save_path("Save project", PROJECT_FILTERS, stem + pf.SUFFIX)
        if not path:
            return False
        if Path(path).suffix.lower() != pf.SUFFIX:
            path = str(path) + pf.SUFFIX
        return self.save_to(path, wait)

    def save_to(self, path: str | os.PathLike[str], wait: bool = True) -> bool:
        """Write the project (atomically, in a worker after the writes already queued: the
        snapshot is taken now); once written, the window adopts it as its current file and the
        snapshot's state is the saved one (edits made meanwhile stay unsaved). A save that fails,
        for whatever reason, says so in a dialog naming the file: the work stays unsaved.
        ``wait``: return once written (True) or failed (False), the window answering meanwhile,
        so that whoever asked (Quit, Open) stays on a failure; else True once queued."""
        w = self.window
        try:
            project = self.current_project()
        except Exception as e:  # (a fault in the snapshot too: never a silent loss of the work)
            w.show_error("Cannot save project", save_failure(path, e))
            return False
        mark = w.undo_stack.mark()

        def written() -> None:
            if w.undo_stack.setCleanAt(mark):  # (not when the document was replaced meanwhile)
                self.path = Path(path)
                w.scene.set_path(self.path)
            w.remember_dir(path)
            w.statusBar().showMessage(f"saved {path}", 5000)
            self.saved.emit(str(path))

        item = w.writes.queue(
            f"Saving {Path(path).name}",
            Path(path),
            lambda: pf.save(path, project),
            written,
            lambda e: w.show_error("Cannot save project", save_failure(path, e)),
        )
        return w.writes.wait(item) if wait else True

    def open_project_dialog(self) -> bool:
        if not self.confirm_discard():
            return False
        path = self.window.ask_open_path("Open project", PROJECT_FILTERS)
        return bool(path) and self.open_project(path)

    def open_project(self, path: str | os.PathLike[str]) -> bool:
        """Open a project; on a bad file the error names it and the scene stays as it was."""
        try:
            project = pf.load(path)
        except HairtoolError as e:
            self.window.show_error("Cannot open project", str(e))
            return False
        self.apply(project, path)
        self.path = Path(path)
        self.window.remember_dir(path)
        self.opened.emit(str(path))
        return True

    # -- closing -----------------------------------------------------------------------------
    def confirm_discard(self) -> bool:
        """Before work is replaced (Open, Open Project, New, a drop, Quit): ask Save / Discard /
        Cancel when it changed since the last save. True to go on (saved or discarded), False to
        stay (Cancel, or a save that was cancelled or failed)."""
        if not self.has_unsaved_changes():
            return True
        answer = self.window.ask_save_changes()
        if answer == "save":
            return self.save_changes()
        return answer == "discard"

    def save_changes(self) -> bool:
        """The save the question's Save runs: the project when the work is one, is untitled or
        holds an animation (Save writes a static groom: an edited capture or a cycle made here
        would be lost), else the groom file's own Save (Save As for a format it cannot write)."""
        w = self.window
        if self.path is not None or w.animation.animation is not None or w.scene.path is None:
            return self.save_project()
        return w.save()

    def shutdown(self) -> None:
        """A clean close: no autosave any more, the recovery file removed, the exit marked clean."""
        self.timer.stop()
        self._join_autosave()
        try:
            self.recovery_path.unlink(missing_ok=True)
        except OSError:
            pass
        self.window.settings.setValue("session/clean_exit", True)
        self.window.settings.sync()

    # -- autosave and recovery -----------------------------------------------------------------
    def _crashed_before(self) -> bool:
        clean = self.window.settings.value("session/clean_exit", True)
        clean = clean if isinstance(clean, bool) else str(clean).lower() == "true"
        return self.recovery_path.is_file() and not clean

    def _join_autosave(self) -> None:
        t = self._autosave_thread
        if t is not None:
            t.join()
            self._autosave_thread = None

    def autosave(self, wait: bool = False) -> bool:
        """Write the recovery file if anything changed since the last autosave (in a thread;
        ``wait`` blocks until it is written). Returns whether a write started."""
        if self._changes == self._autosaved_at or self._offer_pending or not self.window.scene.engine_ready:
            return False  # nothing new, an unanswered recovery offer, or the engine not started
        if self._autosave_thread is not None and self._autosave_thread.is_alive():
            return False  # the previous one is still writing; the next tick catches up
        path, changes = self.recovery_path, self._changes
        try:
            project = self.current_project()
        except Exception as e:  # reported in the status bar; the next tick tries again
            self.autosave_error = save_failure(path, e)
            self._show_autosave_failure(self.autosave_error)
            return False

        def write() -> None:
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                pf.save(path, project)
            except Exception as e:  # the thread never dies silently: the status bar says why
                self.autosave_error = save_failure(path, e)
                self.autosave_failed.emit(self.autosave_error)
            else:
                self.autosave_error = None
                self._autosaved_at = changes

        self._join_autosave()
        self._autosave_thread = threading.Thread(target=write, name="hairtool-autosave", daemon=True)
        self._autosave_thread.start()
        if wait:
            self._join_autosave()
        return True

    @Slot(str)  # (emitted by the autosave thread: a declared slot, PYSIDE-3124)
    def _show_autosave_failure(self, message: str) -> None:
        self.window.statusBar().showMessage(f"Autosave failed: {message}")

    def offer_recovery(self) -> bool:
        """Offer the recovery file left by a session that did not close cleanly; restore it if
        accepted, else remove it. Returns whether it was restored."""
        self._offer_pending = False
        path = self.recovery_path
        if not path.is_file():
            return False
        if not self.window.ask_restore_recovery(str(path)):  # Discard
            path.unlink(missing_ok=True)
            return False
        try:
            project = pf.load(path)
        except FormatError as e:
            self.window.show_error("Cannot restore the recovery file", str(e))
            path.unlink(missing_ok=True)
            return False
        self.apply(project, None)
        self.path = None
        self._mark_unsaved()  # restored work is not saved anywhere yet
        self.window.statusBar().showMessage("restored the autosaved session; save it as a project", 8000)
        return True


def _brush_settings(tool) -> dict:
    """The brush as a project keeps it: the current brush's radius, strength and mode (what
    older projects hold), and every brush's own, the falloff, symmetry, front faces only and
    each brush's collision with the head and pen toggles (pressure scales its radius, its
    strength), add's strands per move, density's spacing, delete's rule and whether brushes keep to the
    selection."""
    falloff = tool.falloff if isinstance(tool.falloff, str) else [list(p) for p in tool.falloff]
    return {
        "radius": tool.radius[tool.brush],
        "intensity": tool.strength[tool.brush],
        "align_mode": tool.align_mode,
        "brush": tool.brush,
        "radii": dict(tool.radius),
        "strengths": dict(tool.strength),
        "subtract": dict(tool.subtract),
        "falloff": falloff,
        "symmetry": tool.symmetry,
        "mirror_x": tool.mirror_x,
        "front_only": tool.front_only,
        "collide": dict(tool.collide),
        "add_count": tool.add_count,
        "spacing": tool.spacing,
        "delete_any_segment": tool.delete_any_segment,
        "only_selected": tool.only_selected,
        "pressure_radius": dict(tool.pressure_radius),
        "pressure_strength": dict(tool.pressure_strength),
    }


def _brush_setters(scene, brush: dict) -> tuple:
    """Setters for :func:`_brush_settings`' fields beyond the first three (each may be missing)."""
    from app.ui.brush_tool import brushes

    names = brushes()

    def per_brush() -> None:
        current = brush["brush"]
        for name in brush["radii"]:
            if name in scene.tool.radius:
                scene.set_brush(name)
                scene.set_radius(float(brush["radii"][name]))
                scene.set_intensity(float(brush["strengths"][name]))
        scene.set_brush(str(current))

    def pens(key: str) -> None:  # each brush's pen toggles (the dock shows the current one's)
        getattr(scene.tool, key).update({k: bool(v) for k, v in brush[key].items() if k in names})
        scene.tool_changed.emit()

    return (
        per_brush,
        lambda: [scene.set_subtract(k, bool(v)) for k, v in brush["subtract"].items()],
        lambda: scene.set_falloff(brush["falloff"]),
        lambda: scene.set_symmetry(bool(brush["symmetry"])),
        lambda: scene.set_mirror_x(None if brush["mirror_x"] is None else float(brush["mirror_x"])),
        lambda: scene.set_front_only(bool(brush["front_only"])),
        lambda: scene.tool.collide.update({k: bool(v) for k, v in brush["collide"].items() if k in names}),
        lambda: scene.set_add_count(int(brush["add_count"])),
        lambda: scene.set_spacing(float(brush["spacing"])),
        lambda: scene.set_delete_any_segment(bool(brush["delete_any_segment"])),
        lambda: scene.set_only_selected(bool(brush["only_selected"])),
        lambda: pens("pressure_radius"),
        lambda: pens("pressure_strength"),
    )


def _apply_each(window: StudioHost, setters) -> None:
    """Apply saved settings one by one; a value this studio refuses is reported, not fatal."""
    problems = []
    for setter in setters:
        try:
            setter()
        except (HairtoolError, KeyError, TypeError, ValueError) as e:
            if not isinstance(e, KeyError):  # a setting the file does not have: keep ours
                problems.append(str(e))
    if problems:
        window.show_error("Some project settings were not applied", "\n".join(problems))
