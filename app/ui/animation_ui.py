"""Glue between the animation model, the viewport and the window: what the viewport draws for
the current frame, key edits by dragging and dope-sheet edits (each one step of the document's
undo stack), recording drags, the playback actions and the fps read-out."""

from __future__ import annotations

import itertools
import time
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QObject, Qt
from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import QLabel, QStyle, QWidget

from app.ui.animation_model import VIEW_MODES, AnimationModel
from app.ui.engine_start import WAIT_MESSAGE
from app.ui.frame_children import FrameAsk, FrameChildren
from app.ui.qt_utils import add_action, set_available
from app.ui.recording import Recorder
from hairtool.errors import HairtoolError
from hairtool.frozen.align import align
from hairtool.groom import Groom
from hairtool.keys.session import key_edit_block

KEY_EDIT_MISSED = (
    "The brush touched no strand of this key pose: start the drag on the hair, or make it bigger ( ] )"
)

if TYPE_CHECKING:
    from app.ui.host import StudioHost


def refusal(text: str, model: AnimationModel, error: HairtoolError) -> str:
    """One line, in the timeline's words, on why a dope-sheet edit changed nothing."""
    if getattr(error, "name", "") in ("budget", "max_error"):
        worst = " of the worst frame" if model.settings.objective == "worst" else ""
        return (
            f"{text}: not possible, no keys stay within the error budget{worst} with that change "
            "(raise the budget, or undo a pin or an exclusion)"
        )
    return f"{text}: {error}"


class KeyEditBrush:
    """The align brush on a key pose: only at a DP key frame, with the scene's radius, intensity
    and mode (align only: freeze and clump shape static grooms, not captured motion)."""

    def __init__(self, controller: AnimationController) -> None:
        self.c = controller
        self.frame: int | None = None
        self.groom: Groom | None = None

    def begin(self, cursor: np.ndarray) -> bool:
        m = self.c.model
        if not self.c.window.scene.engine_ready:  # the align kernel may still be compiling
            self.c.window.statusBar().showMessage(WAIT_MESSAGE, 4000)
            return False
        if m.animation is None or not m.is_key():
            self.c.window.statusBar().showMessage(
                "Key edits happen at a DP key frame: jump to one with ↑ / ↓", 4000
            )
            return False
        m.pause()
        self.frame = m.frame
        self.groom = m.animation.frame(m.frame)
        self.move(cursor)
        return True

    def move(self, cursor: np.ndarray) -> None:
        if self.groom is None:
            return
        s = self.c.window.scene
        t0 = time.perf_counter()
        self.groom = align(self.groom, cursor, s.radius, s.intensity, s.align_mode)
        s.last_update_ms = (time.perf_counter() - t0) * 1e3
        self.c.model.set_preview(self.frame, self.groom.points)

    def end(self) -> None:
        m, frame, groom = self.c.model, self.frame, self.groom
        self.frame = self.groom = None
        if frame is None or groom is None or m.animation is None:
            return
        m.set_preview(frame, None)
        if np.array_equal(groom.points, m.animation.frames[frame]):
            self.c.window.statusBar().showMessage(KEY_EDIT_MISSED, 6000)
            return
        try:
            start, block = key_edit_block(
                m.animation.frames, m.dp_keys, m.dp_poses.interp, frame, groom.points
            )
        except HairtoolError as e:
            self.c.window.show_error("Cannot edit key", str(e))
            return
        m.edit_frames(start, block, f"Edit key {frame}")


class AnimationController(QObject):
    """Owned by the window; see the module docstring."""

    def __init__(self, window: StudioHost, model: AnimationModel) -> None:
        super().__init__(window)
        self.window, self.model = window, model
        self.viewport, self.scene = window.viewport, window.scene
        self.clock: Callable[[], float] = time.perf_counter
        self.recorder: Recorder | None = None
        self.scene.strand_holders.append(self._holds_strands)
        self.brush = KeyEditBrush(self)
        self._drawn: deque[tuple[float, int]] = deque(maxlen=240)
        self.fps_label = QLabel()
        self.fps_label.setObjectName("FpsLabel")
        for signal in (model.frame_changed, model.display_changed, model.view_mode_changed):
            signal.connect(self.refresh_display)
        model.animation_changed.connect(self._on_animation_changed)
        model.frame_changed.connect(self._update_fps_label)
        model.playing_changed.connect(self._on_playing)
        model.scrubbing_changed.connect(self._on_scrubbing)
        model.fps_changed.connect(self._update_fps_label)
        self.viewport.frame_drawn.connect(self._on_frame_drawn)
        self.viewport.stroke_started.connect(self._on_stroke_started)
        self.scene.points_changed.connect(self._on_scene_points)
        self.viewport.stroke_finished.connect(self._on_stroke_finished)
        # a scrubbed frame's render hair is built in a worker thread and shown when it lands
        self.frames = FrameChildren(self)
        self.frames.landed.connect(self._on_children_landed)
        self._asks = 0  # frames shown or asked for (a landing older than the last is dropped)
        self.scene.drawn_changed.connect(self._drop_frame_children)
        self.actions: dict[str, QAction] = {}
        self._update_fps_label()

    # -- the dope sheet ----------------------------------------------------------------------
    def steer_keys(self, text: str, **edit: object) -> bool:
        """One dope-sheet edit, one step of the document (see :meth:`AnimationModel.steered`); a
        refused one says why in the status bar and changes nothing."""
        m = self.model
        before = (m.settings.pins, m.settings.excludes)
        try:
            after = m.steered(**edit)
            if after == before:
                return False
            m.set_settings(text, pins=after[0], excludes=after[1])  # all or nothing
        except HairtoolError as e:
            self.show_status(refusal(text, m, e))
            return False
        return True

    def close_animation(self) -> bool:
        """Animation ▸ Close animation: one undo step (Undo brings the animation back with its
        edits); unsaved work asks Save / Discard / Cancel first."""
        if self.model.animation is None:
            return False
        return self.model.load_animation(None, confirm=self.window.project.confirm_discard)

    def show_status(self, message: str) -> None:
        self.window.statusBar().showMessage(message, 6000)

    # -- model → viewport ------------------------------------------------------------------
    def refresh_display(self, *_: object) -> None:
        """The current frame to the viewport: at once, or while the timeline is scrubbed with
        render hair, once its children are built off the GUI thread (:meth:`_ask`)."""
        d = self.model.display() if self.recorder is None else None
        self._asks += 1
        if d is None or len(d.points) != self.scene.result.vertex_count:
            self.frames.cancel()
            self.viewport.clear_frame()
        elif self.model.scrubbing and self.scene.has_children:
            self._ask(d, clumped=False)
        else:
            self.frames.cancel()
            m = self.model
            if self.scene.frames_live and not (m.playing or m.scrubbing):
                self.scene.set_frames_live(False)  # a release's clumped frame was overtaken
            self.viewport.show_frame(d.points, d.colors, d.ghost, d.frame)

    def _ask(self, d, *, clumped: bool) -> None:
        """Build frame ``d``'s drawn children in the worker (the latest ask replaces a waiting one):
        the share drawn now, clumped (as Clump children says) or interpolated only."""
        s = self.scene
        clump = s.children_clump() if clumped and s.children_clump_ready else None
        self._asks += 1
        ask = FrameAsk(
            d.frame, d.points, s.result.topology, s.drawn_binding(), clump, bool(s.drawn_guides),
            d.colors, d.ghost, self._asks,
        )  # fmt: skip
        self.frames.ask(ask)

    def _on_children_landed(self, ask: FrameAsk) -> None:
        """A frame's children are built: shown with their guides, unless a frame was shown or
        asked for since (while scrubbing, the newest built is shown, on the way to the latest),
        or the drawn strands changed meanwhile (another share, other children)."""
        m, s = self.model, self.scene
        if self.recorder is not None or m.animation is None:
            return
        if ask.number != self._asks and not m.scrubbing:
            return
        if ask.binding is not s.drawn_binding() or ask.vertex_count != s.drawn_topology.vertex_count:
            return
        if ask.clump is not None and not (m.playing or m.scrubbing):
            s.set_frames_live(False)  # the clumped frame is on screen: the groom's look again
        self.viewport.show_frame(ask.guides, ask.colors, ask.ghost, ask.frame, children=ask.points)

    def _drop_frame_children(self) -> None:
        """Other drawn strands (a share, Clump children, the guides shown): the frame's children
        built for the old ones go; the view builds the frame's own at its next paint."""
        self.viewport.frame_children = None

    def _on_animation_changed(self) -> None:
        anim = self.model.animation
        if anim is not None and anim.topology != self.scene.result.topology:
            # different strands: the scene takes the animation's first frame (its strokes and
            # their undo steps belong to the old strands, as when a file is opened)
            self.window.undo_stack.clear()
            self.scene.load(anim.rest, self.scene.path)
        self.viewport.brush_target = self.brush if anim is not None and self.recorder is None else None
        if anim is not None:
            self.viewport.frame_all()  # the groom, not the empty space its whole motion spans
        self.refresh_display()
        self._update_fps_label()

    # -- playback read-out ------------------------------------------------------------------
    def _on_playing(self, playing: bool) -> None:
        self._drawn.clear()
        self._frames_live()
        self._update_fps_label()

    def _on_scrubbing(self, scrubbing: bool) -> None:
        """The timeline's frame is dragged: render hair at the drag's display share, unclumped, as
        a brush drag draws it. Let go: every child at once, interpolated (a cheap build), and
        clumped when the worker has clumped them (about 2 s for Sintel's on a loaded host)."""
        m, s = self.model, self.scene
        s.set_dragging(scrubbing)
        if scrubbing or m.playing:
            self._frames_live()
            return
        d = m.display() if self.recorder is None else None
        clumps = s.clump_children and s.children_clump_ready and s.has_children
        if not s.frames_live or not clumps or d is None or len(d.points) != s.result.vertex_count:
            self._frames_live()
            self.refresh_display()  # the latest frame, whatever the worker still builds
            return
        self.frames.cancel()  # frames_live stays on: every child at once, interpolated …
        self.viewport.show_frame(d.points, d.colors, d.ghost, d.frame)
        self._ask(d, clumped=True)  # … and clumped when the worker has them

    def _frames_live(self, *_: object) -> None:
        """Playing or scrubbing, the children of the frames are drawn unclumped (Scene.set_frames_live)."""
        live = self.model.playing or self.model.scrubbing
        if live == self.scene.frames_live:
            return
        self.scene.set_frames_live(live)
        if not live and self.scene.clump_children and self.scene.has_children:
            self.refresh_display()  # the frame it stopped on, with its children clumped

    def _on_frame_drawn(self) -> None:
        if self.model.playing and self.viewport.shown_frame is not None:
            self._drawn.append((self.clock(), self.viewport.shown_frame))

    def measured_fps(self) -> float:
        """Distinct frames drawn per second over the last second of playback."""
        if len(self._drawn) < 2:
            return 0.0
        now = self._drawn[-1][0]
        recent = [(t, f) for t, f in self._drawn if now - t <= 1.0]
        changes = sum(1 for a, b in itertools.pairwise(recent) if a[1] != b[1])
        span = recent[-1][0] - recent[0][0]
        return changes / span if span > 0 else 0.0

    def _update_fps_label(self, *_: object) -> None:
        m = self.model
        if m.animation is None:
            self.fps_label.setText("")
            return
        text = f"frame {m.frame}/{m.last_frame}"
        if m.playing:
            text += f" · ▶ {self.measured_fps():.1f} fps (of {m.fps:g})"
        else:
            text += f" · {m.fps:g} fps"
        self.fps_label.setText(text)

    # -- recording ---------------------------------------------------------------------------
    @property
    def recording(self) -> bool:
        return self.recorder is not None

    def set_recording(self, on: bool) -> None:
        """Record toggle: on, drags edit the groom and are captured at the model's fps; off,
        the capture becomes the animation in the timeline."""
        if on == self.recording:
            return
        if on:
            self.model.pause()
            result = self.scene.result
            self.recorder = Recorder(result.topology, self.model.fps, result.metadata)
            self.viewport.brush_target = None
            self.refresh_display()
            self.window.statusBar().showMessage("Recording: drag the hair; toggle Record again to stop")
        else:
            rec, self.recorder = self.recorder, None
            self.window.statusBar().clearMessage()
            try:
                anim = rec.animation()
            except HairtoolError as e:  # a status-bar line, not a dialog: nothing went wrong
                self._on_animation_changed()
                message = str(e)
                self.window.statusBar().showMessage(message[:1].upper() + message[1:], 6000)
            else:
                self.model.load_animation(anim, "recording")
        if "record" in self.actions:
            self.actions["record"].setChecked(self.recording)

    def _holds_strands(self) -> str | None:
        """What of the animation needs the groom's strands as they are (None: nothing)."""
        if self.recorder is not None:
            return "drags are being recorded"
        if self.model.animation is not None:
            return "the timeline holds an animation of these strands"
        return None

    def _on_stroke_started(self) -> None:
        if self.recorder is not None:
            self.recorder.begin_stroke(self.clock(), self.scene.result.points)

    def _on_scene_points(self) -> None:
        if self.recorder is not None:
            self.recorder.update(self.clock(), self.scene.result.points)

    def _on_stroke_finished(self, *_: object) -> None:
        if self.recorder is not None:
            self.recorder.end_stroke(self.clock())

    # -- menu and shortcuts -------------------------------------------------------------------
    def build_menu(self) -> dict[str, QAction]:
        """The Animation menu; returns its actions by name (the timeline's buttons show them)."""
        w, m = self.window, self.model
        menu = w.menuBar().addMenu("A&nimation")  # (Alt+A deselects, as in Blender)
        a = self.actions
        a["play"] = add_action(w, menu, "&Play / Pause", m.toggle_play, "Space")
        a["loop"] = add_action(w, menu, "&Loop", lambda on: m.set_loop(on), "Ctrl+L", checkable=True)
        a["loop"].setChecked(m.loop)
        m.loop_changed.connect(a["loop"].setChecked)
        menu.addSeparator()
        a["step_forward"] = add_action(w, menu, "Next &frame", lambda: m.step(1), "Right")
        a["step_back"] = add_action(w, menu, "Pre&vious frame", lambda: m.step(-1), "Left")
        a["next_key"] = add_action(w, menu, "&Next key", m.next_key, "Up")
        a["previous_key"] = add_action(w, menu, "P&revious key", m.previous_key, "Down")
        a["first"] = add_action(w, menu, "F&irst frame", m.first, ["Home", "Shift+Left"])
        a["last"] = add_action(w, menu, "L&ast frame", m.last, ["End", "Shift+Right"])
        menu.addSeparator()
        a["record"] = add_action(w, menu, "&Record drags", self.set_recording, "Shift+R", checkable=True)
        a["resolve"] = add_action(w, menu, "Re-&solve keys", m.request_solve)
        a["clear"] = add_action(w, menu, "&Close animation", self.close_animation)

        def enable() -> None:  # both need an animation (Re-solve one with frames to key)
            set_available(
                a["resolve"], m.n_frames >= 2, "Re-solve keys needs an animation of two frames or more"
            )
            set_available(a["clear"], m.animation is not None, "No animation to close")

        m.animation_changed.connect(enable)
        enable()
        view = menu.addMenu("&View")
        group = QActionGroup(w)
        for i, (key, label) in enumerate(VIEW_MODES.items()):
            act = add_action(w,
                view, label, lambda _=False, k=key: m.set_view_mode(k), f"Ctrl+{i + 1}", checkable=True
            )
            act.setChecked(key == m.view_mode)
            group.addAction(act)
            a[f"view_{key}"] = act
        m.view_mode_changed.connect(lambda k: a[f"view_{k}"].setChecked(True))
        style, sp = w.style(), QStyle.StandardPixmap
        icons = {
            "play": sp.SP_MediaPlay, "step_forward": sp.SP_MediaSeekForward,
            "step_back": sp.SP_MediaSeekBackward, "first": sp.SP_MediaSkipBackward,
            "last": sp.SP_MediaSkipForward, "loop": sp.SP_BrowserReload,
        }  # fmt: skip
        for name, pixmap in icons.items():
            a[name].setIcon(style.standardIcon(pixmap))
        for name, text in {"next_key": "◆▸", "previous_key": "◂◆", "record": "● Rec"}.items():
            a[name].setIconText(text)
        play, pause = style.standardIcon(sp.SP_MediaPlay), style.standardIcon(sp.SP_MediaPause)
        m.playing_changed.connect(lambda on: a["play"].setIcon(pause if on else play))
        for name in ("step_forward", "step_back", "next_key", "previous_key", "first", "last"):
            a[name].setShortcutVisibleInContextMenu(True)
        a["play"].setShortcuts([QKeySequence("Space")])
        return a

    TRANSPORT_KEYS = ("play", "step_forward", "step_back", "next_key", "previous_key", "first", "last")

    def bind_transport_keys(self, *widgets: QWidget) -> None:
        """Space, arrows and Home/End drive playback only while the focus is in ``widgets`` (the
        viewport, the timeline), so the tool dock's sliders keep their own arrow keys."""
        for name in self.TRANSPORT_KEYS:
            action = self.actions[name]
            action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            for widget in widgets:
                widget.addAction(action)
