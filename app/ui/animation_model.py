"""The studio's animation model: a view of the document's animation side, with playback.

The animation, its source, the capture and the key settings are the document's
(:class:`app.document.animation.Document`, ``window.doc``); every change of them is a command
on its one undo stack, and this model follows the document through ``doc.observe`` (a new
animation, a key edit, new settings, and their undo and redo alike). What it keeps itself is
what a project does not hold: the frame, playback, scrubbing, the view mode, a dragged key
pose's preview, and the key solve's jobs and caches.

No widgets: the timeline dock and the viewport listen to its signals, which fire only when a
value really changes. Key work follows the timeline's needs: one solve per animation and
table setting (features, cost table, layered DP) gives the keys of every count, so the
key-count slider answers at once; per-frame errors of the DP keys and of uniform keys of the
same count follow. Work on large animations runs through the window's :class:`JobRunner`; a
job the user cancels takes its settings step back, so the keys, settings and curves are the
previous ones.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from PySide6.QtCore import QObject, Qt, QTimer, Signal

from app.document.animation import Document, solving_settings
from app.ui.jobs import Job, JobRunner
from app.ui.legend import magnitude_colors
from hairtool.errors import GroomError, HairtoolError, ParameterError
from hairtool.groom import Animation, Groom
from hairtool.keys import session as ks
from hairtool.keys.dp import keys_cost, uniform_keys
from hairtool.keys.reconstruct import KeyPoses, check_keys, interpolate_at

VIEW_MODES = {
    "original": "Original",
    "reconstruction": "Reconstruction from keys",
    "ghost": "Both (reconstruction in cyan behind)",
    "error": "Colour by key error",
}
DEFAULT_FPS = 24.0  # the playback (and recording) rate of a document without an animation
INLINE_VALUES = 3_000_000  # animations up to this many coordinates are solved on the GUI thread


@dataclass
class Display:
    """What the viewport draws for the current frame: points, optional colours and ghost."""

    frame: int
    points: np.ndarray
    colors: np.ndarray | None = None
    ghost: np.ndarray | None = None


@dataclass
class _Committed:
    """The last complete key state (settings, solve, keys, errors): what a cancel returns to."""

    settings: ks.KeySettings
    solve: ks.KeySession | None
    dp_keys: np.ndarray | None
    analysis: ks.Analysis | None
    solved_keys: np.ndarray | None = None


class AnimationModel(QObject):
    """The current animation (or None), its frame, playback, keys and view mode."""

    animation_changed = Signal()  # a new animation (or None): everything else was reset
    frames_edited = Signal(int, int)  # first and last frame a key edit changed
    frame_changed = Signal(int)
    playing_changed = Signal(bool)
    scrubbing_changed = Signal(bool)  # the timeline's frame is being dragged (button held)
    loop_changed = Signal(bool)
    fps_changed = Signal(float)
    settings_changed = Signal(object)  # KeySettings
    keys_changed = Signal()  # DP keys (and the uniform keys of the same count)
    curve_changed = Signal()  # the error-vs-key-count curve (a new solve)
    analysis_changed = Signal()  # per-frame errors of both reconstructions and the speed
    view_mode_changed = Signal(str)
    display_changed = Signal()  # what is drawn at the current frame changed (not the frame)
    busy_changed = Signal(bool)  # a solve or an error pass is running in the background

    def __init__(
        self, runner: JobRunner | None = None, parent: QObject | None = None, doc: Document | None = None
    ) -> None:
        super().__init__(parent)
        self.runner = runner
        # the document it shows (the window's); a model on its own keeps a document of its own
        self.doc = doc if doc is not None else Document(_no_groom())
        self.inline_values = INLINE_VALUES  # tests set 0 to send every solve through the runner
        self.clock: Callable[[], float] = time.perf_counter
        # what is shown: the document's animation, or a capture's skeleton with its edits
        # (the capture editor shows those through :meth:`replace_frames`)
        self.animation: Animation | None = self.doc.state.animation
        self.frame = 0
        self.fps = DEFAULT_FPS
        self.playing = False
        self.scrubbing = False
        self.loop = True
        self.view_mode = "original"
        self._seen = self.doc.state  # the document's state shown
        self._pending = None  # the settings step a background solve is for (a cancel takes it back)
        self._clear_keys()
        self._committed: _Committed | None = None
        self._solve_job: Job | None = None
        self._analysis_job: Job | None = None
        self._preview: tuple[int, np.ndarray] | None = None
        self._timer = QTimer(self)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._timer.timeout.connect(self._tick)
        self._play_start = (0.0, 0)
        self.doc.observe(self._on_doc)

    # -- the document ----------------------------------------------------------------------
    @property
    def settings(self) -> ks.KeySettings:
        """The key settings (the document's)."""
        return self.doc.state.settings

    @property
    def source(self) -> str:
        return self.doc.state.source

    @property
    def key_source(self) -> Animation | None:
        """A capture's skeleton as captured (its keys stay the capture's while its key poses are
        edited); None for an animation keyed as it is."""
        state = self.doc.state
        return state.animation if state.capture is not None else None

    def _solving(self) -> ks.KeySettings:
        """The settings the keys are solved with (the capture's edit frames pinned)."""
        return solving_settings(self.doc.state)

    def _on_doc(self) -> None:
        """The document changed (a command, an undo, a redo): follow it."""
        old, new = self._seen, self.doc.state
        if new is old:
            return
        self._seen = new
        if new.settings != old.settings:
            self.settings_changed.emit(new.settings)
        if new.take != old.take:  # another animation, or none
            self._show_new_animation()
            return
        if new.animation is not old.animation and new.capture is None:  # a key edit, or its undo
            self._frames_moved(old.animation, new.animation)
        if self.animation is None or self.n_frames < 2:
            return
        if solving_settings(new) != solving_settings(old) or (old.held_keys and not new.held_keys):
            self._settings_moved()
        elif new.held_keys != old.held_keys:
            self.set_edited_keys(np.array(new.held_keys, dtype=np.int64))

    def _clear_keys(self) -> None:
        self.key_solve: ks.KeySession | None = None
        self.solve_stale = False  # the animation was edited after the solve
        self.dp_keys: np.ndarray | None = None  # the keys shown and edited (moved in time)
        self.solved_keys: np.ndarray | None = None  # the solve's, before any key was moved
        self.uniform_keys: np.ndarray | None = None
        self.dp_poses: KeyPoses | None = None
        self.uniform_poses: KeyPoses | None = None
        self.analysis: ks.Analysis | None = None

    # -- the animation -------------------------------------------------------------------
    @property
    def n_frames(self) -> int:
        return 0 if self.animation is None else self.animation.n_frames

    @property
    def keyed(self) -> Animation | None:
        """What keys are solved on: :attr:`key_source`, else the animation."""
        return self.key_source if self.key_source is not None else self.animation

    @property
    def last_frame(self) -> int:
        return max(self.n_frames - 1, 0)

    def load_animation(
        self,
        animation: Animation | None,
        source: str = "",
        *,
        settings: ks.KeySettings | None = None,
        capture=None,
        edits=(),
        channel_edits=(),
        confirm: Callable[[], bool] | None = None,
    ) -> bool:
        """Show ``animation`` (or a ``capture``'s skeleton, with its ``edits``) in the timeline and
        viewport and solve its keys: one undo step of the document
        (:meth:`Document.replace_animation`); None closes the animation.

        ``source`` says where it came from (a path, "recording", "anime cycle", …); the other
        docks call this through ``window.animation.load_animation``. Frame 0, playback stopped,
        playback rate the animation's. The key settings stay, except the count, which goes back
        to the knee of the error curve, the pinned and excluded frames, which belonged to the
        last animation, and an error budget (a figure in the last animation's units: the key mode
        goes back to the count); a reopened project passes its saved ``settings`` instead (one
        solve, with those). ParameterError for invalid settings, before anything changes.
        ``confirm`` asks Save / Discard / Cancel over unsaved work: False on Cancel.
        """
        if animation is not None and not isinstance(animation, Animation):
            raise GroomError(f"expected an Animation, got {type(animation).__name__}")
        if settings is not None:
            settings = settings.validate()
            if animation is not None:
                settings.constraints.check(animation.n_frames)
        # solved here when small (the document's solve, shared: settings no keys meet are refused
        # before anything changes); a long animation's in the background
        inline = animation is not None and (
            self.runner is None or animation.frames.size <= self.inline_values
        )
        return self.doc.replace_animation(
            animation, source, capture, confirm, settings, edits, channel_edits, check=inline
        )

    def _show_new_animation(self) -> None:
        """The document's animation is another one (or none): frame 0, playback stopped, the
        playback rate the animation's, its keys solved."""
        self.pause()
        self._cancel_jobs()
        self._pending = None
        anim = self.doc.state.animation
        self.animation = anim
        self.frame = 0
        self._preview = None
        self._clear_keys()
        self._committed = None
        if anim is not None and anim.fps != self.fps:
            self.fps = float(anim.fps)
            self.fps_changed.emit(self.fps)
        self._announce_new_animation()
        if anim is not None and anim.n_frames >= 2:
            self.request_solve()

    def clear(self) -> None:
        """No animation (one undo step): the viewport shows the scene's groom again."""
        if self.animation is not None:
            self.load_animation(None)

    def reset(self) -> None:
        """A new document: no animation, and the values that belong to a document back to their
        defaults: the frame rate (a BVH's 120 fps is not the next groom's) and the key mode with
        its error budget (a figure in the last animation's units). The method chosen stays
        (interpolation, objective, features, the price per key, which is relative); an
        animation or a project brings its own values. (The window then clears the undo stack.)"""
        d = ks.KeySettings()
        new = self.settings.replace(mode=d.mode, count=0, budget=d.budget, pins=(), excludes=())
        if self.doc.state.animation is not None or new != self.settings:
            self.doc.replace_animation(None, settings=new, check=False)
        if self.fps != DEFAULT_FPS:
            self.fps = DEFAULT_FPS
            self.fps_changed.emit(self.fps)

    def _announce_new_animation(self) -> None:
        """Everything depends on the animation: tell every listener it was reset."""
        self.animation_changed.emit()
        self.frame_changed.emit(0)
        self.keys_changed.emit()
        self.curve_changed.emit()
        self.analysis_changed.emit()
        self.display_changed.emit()

    def edit_frames(self, start: int, block: np.ndarray, text: str, keys: np.ndarray | None = None) -> None:
        """A key edit of the animation's frames ``start .. start + len(block) − 1`` (one undo step
        of the document, :meth:`Document.edit_frames`): the keys stay (or become ``keys``, a key
        moved in time) until the key settings change."""
        anim = self.doc.state.animation
        if anim is None:
            raise GroomError("no animation to edit")
        frames = np.array(anim.frames)
        frames[start : start + len(block)] = block
        held = self.dp_keys if keys is None else keys
        self.doc.edit_frames(anim.with_frames(frames), held.tolist(), text)

    def _frames_moved(self, old: Animation | None, new: Animation | None) -> None:
        """The document's frames changed by a key edit (or its undo, or redo)."""
        rows = np.flatnonzero(np.any(new.frames != old.frames, axis=(1, 2)))
        if rows.size:
            self.replace_frames(int(rows[0]), new.frames[rows[0] : rows[-1] + 1])
        self.animation = new

    def replace_frames(self, start: int, block: np.ndarray) -> None:
        """Frames ``start .. start + len(block) − 1`` are shown with new poses (a key edit of the
        document, or a capture's edits, which the capture editor shows here).

        The keys stay; their poses and the error curves are refreshed; the cost table is marked
        stale and is solved again on the next change of the key settings.
        """
        anim = self.animation
        if anim is None:
            raise GroomError("no animation to edit")
        frames = np.array(anim.frames)
        frames[start : start + len(block)] = block
        self.animation = anim.with_frames(frames)
        self.solve_stale = self.key_solve is not None
        if self.dp_keys is not None:
            self._set_key_poses()
            self.request_analysis()
        self.frames_edited.emit(int(start), int(start + len(block) - 1))
        self.display_changed.emit()

    # -- frames and playback --------------------------------------------------------------
    def set_frame(self, frame: int) -> None:
        """Go to a frame (clamped to the animation); during playback, play on from there."""
        f = self._go(frame)
        if self.playing:
            self._play_start = (self.clock(), f)

    def _go(self, frame: int) -> int:
        f = int(min(max(int(frame), 0), self.last_frame))
        if f != self.frame:
            self.frame = f
            self.frame_changed.emit(f)
        return f

    def step(self, delta: int) -> None:
        """Step by ``delta`` frames; with loop on, stepping past an end wraps around."""
        if self.n_frames == 0:
            return
        f = self.frame + int(delta)
        self.set_frame(f % self.n_frames if self.loop else f)

    def first(self) -> None:
        self.set_frame(0)

    def last(self) -> None:
        self.set_frame(self.last_frame)

    def next_key(self) -> None:
        """The next DP key after the current frame (the last frame when there is none)."""
        keys = self.dp_keys if self.dp_keys is not None else np.array([self.last_frame])
        later = keys[keys > self.frame]
        self.set_frame(int(later[0]) if later.size else self.last_frame)

    def previous_key(self) -> None:
        keys = self.dp_keys if self.dp_keys is not None else np.array([0])
        earlier = keys[keys < self.frame]
        self.set_frame(int(earlier[-1]) if earlier.size else 0)

    def is_key(self, frame: int | None = None) -> bool:
        f = self.frame if frame is None else frame
        return self.dp_keys is not None and bool(np.any(self.dp_keys == f))

    def set_fps(self, fps: float) -> None:
        """Playback (and recording) rate in frames per second."""
        if not np.isfinite(fps) or not 0.1 <= fps <= 1000:
            raise ParameterError("fps", fps, "a frame rate in [0.1, 1000]")
        if fps != self.fps:
            self.fps = float(fps)
            self._play_start = (self.clock(), self.frame)
            if self.playing:
                self._timer.start(self._interval_ms())
            self.fps_changed.emit(self.fps)

    def set_loop(self, on: bool) -> None:
        if bool(on) != self.loop:
            self.loop = bool(on)
            self.loop_changed.emit(self.loop)

    def play(self) -> None:
        """Start playback at the animation's rate; the frame follows the wall clock, so a slow
        redraw drops frames instead of slowing the animation down."""
        if self.playing or self.n_frames < 2:
            return
        if self.frame >= self.last_frame and not self.loop:
            self.set_frame(0)
        self._play_start = (self.clock(), self.frame)
        self.playing = True
        self._timer.start(self._interval_ms())
        self.playing_changed.emit(True)

    def _interval_ms(self) -> int:
        return max(1, int(500.0 / self.fps))  # two ticks per frame, so each frame shows on time

    def set_scrubbing(self, on: bool) -> None:
        """The artist drags the timeline's frame (on) or lets go (off)."""
        if bool(on) != self.scrubbing:
            self.scrubbing = bool(on)
            self.scrubbing_changed.emit(self.scrubbing)

    def pause(self) -> None:
        if self.playing:
            self.playing = False
            self._timer.stop()
            self.playing_changed.emit(False)

    def toggle_play(self) -> None:
        if self.playing:
            self.pause()
        else:
            self.play()

    def _tick(self) -> None:
        t0, f0 = self._play_start
        target = f0 + int((self.clock() - t0) * self.fps)
        if target > self.last_frame:
            if self.loop:
                target %= self.n_frames
            else:
                self._go(self.last_frame)
                self.pause()
                return
        self._go(target)

    # -- key settings ----------------------------------------------------------------------
    def set_settings(self, text: str = "", drag: object = None, **changes: object) -> None:
        """Change key settings: one undo step of the document (the moves of one slider drag,
        the same ``drag``, are one step; ``text`` names it). Keys follow at once where the
        existing solve covers them, else a new solve starts. A ParameterError (a bad value, or
        pins and exclusions the mode cannot meet, such as an error budget no key set reaches
        without an excluded frame) comes before anything changes, so a refused edit leaves the
        keys, settings and curves as they were."""
        new = self.settings.replace(**changes)
        if new == self.settings:
            return
        text = text or "Key settings: " + ", ".join(f"{k} {v}" for k, v in changes.items())
        if self.n_frames < 2:
            self.doc.set_settings(text, drag=drag, check=False, **changes)
            return
        new.constraints.check(self.n_frames)
        solving = solving_settings(dataclasses.replace(self.doc.state, settings=new))
        solve = self.key_solve
        covered = solve is not None and not self.solve_stale and solve.table_key == solving.table_key
        covered = covered and solve.constraints == solving.constraints
        if covered:
            solve.keys_for(solving)  # all or nothing: a refusal here leaves everything as it was
        inline = self._inline()
        self.doc.set_settings(text, drag=drag, check=inline and not covered, **changes)
        if not covered and not inline:
            self._pending = self.doc.stack.top

    def _settings_moved(self) -> None:
        """The document's key settings (or the capture's edit frames) changed: the keys follow."""
        solving = self._solving()
        solve = self.key_solve
        if solve is None or self.solve_stale or solving.table_key != solve.table_key or (
            solving.constraints != solve.constraints
        ):
            self.request_solve()
            return
        keys = solve.keys_for(solving)
        if self._solve_job is not None:  # back to the solved table: the pending solve is moot
            job, self._solve_job = self._solve_job, None
            job.cancel()
            self._busy_update()
        self._show_keys(keys)

    def steered(
        self,
        *,
        pin: int | None = None,
        unpin: int | None = None,
        exclude: int | None = None,
        move: tuple[int, int] | None = None,
    ) -> tuple[tuple[int, ...], tuple[int, ...]]:
        """The pins and exclusions after one dope-sheet edit (not applied): pin or unpin a frame,
        exclude one (which also unpins it), or move a key from one frame to another (the new
        frame pinned, the old one excluded). ParameterError when the ends would be excluded."""
        pins, excl = set(self.settings.pins), set(self.settings.excludes)
        if pin is not None:
            pins.add(pin)
            excl.discard(pin)
        if unpin is not None:
            pins.discard(unpin)
        if exclude is not None:
            excl.add(exclude)
            pins.discard(exclude)
        if move is not None:
            old, new = move
            pins.discard(old)
            excl.discard(new)
            pins.add(new)
            if 0 < old < self.last_frame:  # the ends are always keys: moving one only adds a pin
                excl.add(old)
        new = self.settings.replace(pins=tuple(pins), excludes=tuple(excl))
        new.constraints.check(max(self.n_frames, 2))
        return new.pins, new.excludes

    def key_errors(self) -> tuple[float, float] | None:
        """The objective the solve minimised, of the DP keys and of uniform keys of the same
        count: E = Σ e_ij (total) or max e_ij (worst frame) over the key segments of the cost
        table, in seed 000's feature space (:func:`hairtool.keys.dp.keys_cost`). Pins and
        exclusions can only raise the DP keys' E. None before a solve."""
        s = self.key_solve
        if s is None or self.dp_keys is None or self.uniform_keys is None:
            return None
        dp, uniform = (keys_cost(s.table, k, s.objective) for k in (self.dp_keys, self.uniform_keys))
        return dp, uniform

    def set_key_count(self, count: int) -> None:
        """Exactly ``count`` DP keys (switches to the key-count mode)."""
        self.set_settings(mode="count", count=int(count))

    @property
    def max_keys(self) -> int:
        """The largest key count the slider offers (the layered solve's depth)."""
        if self.key_solve is not None:
            return self.key_solve.kmax
        return int(min(self.n_frames, ks.MAX_CURVE_KEYS))

    @property
    def busy(self) -> bool:
        return self._solve_job is not None or self._analysis_job is not None

    def _inline(self) -> bool:
        return self.runner is None or self.animation.frames.size <= self.inline_values

    def request_solve(self) -> None:
        """Solve keys for the current animation and settings (in the background when large; the
        document's own solve, shared, when not)."""
        anim, settings = self.keyed, self._solving()
        if anim is None or anim.n_frames < 2:
            return
        if self._inline():
            solve = self.doc.session(anim, settings)
            self._apply_solve(solve, solve.keys_for(settings))
            return

        def work(progress, cancelled):
            return ks.solve(anim, settings, progress, cancelled)

        self._solve_job = self.runner.run(
            f"Solving keys ({anim.n_frames} frames)",
            work,
            lambda result: self._solve_landed(job, anim, result),
            on_cancelled=lambda: self._job_cancelled(job),
            on_error=lambda e: self._job_failed(job, e),
            group=f"keys-solve-{id(self)}",
        )
        job = self._solve_job
        self._busy_update()

    def _solve_landed(self, job: Job, anim: Animation, result: ks.KeySession | None) -> None:
        if job is not self._solve_job:
            return
        if anim is not self.keyed or result is None:
            self._solve_job = None
            self._busy_update()
            return
        try:
            keys = result.keys_for(self._solving())
        except HairtoolError as e:  # e.g. a budget these pins cannot meet: back, and say why
            self._job_failed(job, e)
            return
        self._solve_job = None
        self._busy_update()
        self._apply_solve(result, keys)

    def _apply_solve(self, result: ks.KeySession, keys: np.ndarray) -> None:
        self.key_solve = result
        self.solve_stale = False
        self.curve_changed.emit()
        self._show_keys(keys, force=True)

    def _show_keys(self, keys: np.ndarray, force: bool = False) -> None:
        state = self.doc.state
        hold = state.held_keys and state.capture is None
        held = np.array(state.held_keys, dtype=np.int64) if hold else None
        if not force and self.solved_keys is not None and np.array_equal(keys, self.solved_keys):
            if held is not None and not np.array_equal(held, self.dp_keys):
                self.set_edited_keys(held)
            elif self.analysis is None and self._analysis_job is None:
                self.request_analysis()
            return
        self.solved_keys = keys
        self.dp_keys = keys if held is None else held
        self.uniform_keys = uniform_keys(self.n_frames, keys.size)
        self._keys_set()

    def set_edited_keys(self, keys: np.ndarray) -> None:
        """The keys after a key was moved in time (a graph editor's drag, or its undo): shown in
        the dope sheet, and the key poses, the reconstruction and the errors follow, with the
        same count, so the uniform keys stay; :attr:`solved_keys` stays the solve's. The next
        solve that gives other keys replaces them."""
        keys = check_keys(keys, self.n_frames)
        if self.dp_keys is not None and np.array_equal(keys, self.dp_keys):
            return
        self.dp_keys = keys
        if self.uniform_keys is None or self.uniform_keys.size != keys.size:
            self.uniform_keys = uniform_keys(self.n_frames, keys.size)
        self._keys_set()

    def _keys_set(self) -> None:
        """New keys are in place: their poses, the dope sheet, the display and the errors follow."""
        self._set_key_poses()
        self.keys_changed.emit()
        if self.view_mode != "original":
            self.display_changed.emit()
        self.request_analysis()

    def _set_key_poses(self) -> None:
        interp = self.key_solve.table_key[1] if self.key_solve is not None else self.settings.interp
        self.dp_poses = ks.key_poses_of(self.animation, self.dp_keys, interp)
        self.uniform_poses = ks.key_poses_of(self.animation, self.uniform_keys, interp)

    def request_analysis(self) -> None:
        """Per-frame errors of both reconstructions and the motion speed for the current keys."""
        anim, keys = self.animation, self.dp_keys
        if anim is None or keys is None:
            return
        interp = self.dp_poses.interp
        if self._inline():
            self._apply_analysis(anim, keys, ks.analyse(anim, keys, interp))
            return

        def work(progress, cancelled):
            return ks.analyse(anim, keys, interp, progress=progress, cancelled=cancelled)

        self._analysis_job = self.runner.run(
            "Measuring key errors",
            work,
            lambda result: self._analysis_landed(job, anim, keys, result),
            on_cancelled=lambda: self._job_cancelled(job),
            on_error=lambda e: self._job_failed(job, e),
            group=f"keys-errors-{id(self)}",
        )
        job = self._analysis_job
        self._busy_update()

    def _analysis_landed(
        self, job: Job, anim: Animation, keys: np.ndarray, result: ks.Analysis | None
    ) -> None:
        if job is not self._analysis_job:
            return
        self._analysis_job = None
        self._busy_update()
        if anim is self.animation and result is not None:
            self._apply_analysis(anim, keys, result)

    def _apply_analysis(self, anim: Animation, keys: np.ndarray, result: ks.Analysis) -> None:
        if not np.array_equal(keys, self.dp_keys):
            return  # the keys moved on while it ran; their own pass is on its way
        self.analysis = result
        self._committed = _Committed(
            self.settings, self.key_solve, self.dp_keys, result, self.solved_keys
        )
        self.analysis_changed.emit()
        if self.view_mode == "error":
            self.display_changed.emit()

    def _job_cancelled(self, job: Job) -> None:
        """A job the user cancelled (not one superseded by a newer one): back to the last
        complete state, so the keys, settings and curves on screen agree again."""
        if job is self._solve_job:
            self._solve_job = None
        elif job is self._analysis_job:
            self._analysis_job = None
        else:
            return
        self._busy_update()
        self._revert()

    def _job_failed(self, job: Job, error: BaseException) -> None:
        self._job_cancelled(job)
        if self.runner is not None:
            self.runner.report_error(job, error)

    def _revert(self) -> None:
        pending, self._pending = self._pending, None
        if pending is not None and self.doc.stack.top is pending:
            self.doc.stack.undo()  # the settings step goes back (Redo asks for the solve again)
        c = self._committed
        if c is None:  # nothing complete yet for this animation: no keys
            if self.dp_keys is not None or self.key_solve is not None:
                self._clear_keys()
                self.keys_changed.emit()
                self.curve_changed.emit()
                self.analysis_changed.emit()
                self.display_changed.emit()
            return
        if c.solve is not self.key_solve:
            self.key_solve = c.solve
            self.curve_changed.emit()
        if not np.array_equal(c.dp_keys, self.dp_keys):
            self.dp_keys, self.solved_keys = c.dp_keys, c.solved_keys
            self.uniform_keys = uniform_keys(self.n_frames, c.dp_keys.size)
            self._set_key_poses()
            self.keys_changed.emit()
            self.display_changed.emit()
        if c.analysis is not self.analysis:
            self.analysis = c.analysis
            self.analysis_changed.emit()

    def cancel_work(self) -> None:
        """Cancel this model's running solve or error pass (as the Cancel button does)."""
        for job in (self._solve_job, self._analysis_job):
            if job is not None and self.runner is not None:
                self.runner.cancel(job)

    def _cancel_jobs(self) -> None:
        """Drop running work silently (a new animation replaces everything anyway)."""
        jobs = [j for j in (self._solve_job, self._analysis_job) if j is not None]
        self._solve_job = self._analysis_job = None
        for job in jobs:
            self.runner.cancel(job)
        if jobs:
            self._busy_update()

    def _busy_update(self) -> None:
        self.busy_changed.emit(self.busy)

    # -- view ---------------------------------------------------------------------------------
    def set_view_mode(self, mode: str) -> None:
        if mode not in VIEW_MODES:
            raise ParameterError("view mode", mode, f"one of {', '.join(VIEW_MODES)}")
        if mode != self.view_mode:
            self.view_mode = mode
            self.view_mode_changed.emit(mode)
            self.display_changed.emit()

    @property
    def error_scale(self) -> float:
        """Vertex error shown white-hot in the error view: the DP keys' worst vertex overall."""
        if self.analysis is not None:
            return max(float(self.analysis.dp.max.max()), 1e-12)
        return 0.0

    def set_preview(self, frame: int, points: np.ndarray | None) -> None:
        """Show ``points`` at ``frame`` instead of the animation (a key pose being dragged)."""
        self._preview = None if points is None else (int(frame), points)
        self.display_changed.emit()

    def display(self) -> Display | None:
        """The points (and colours, ghost) to draw for the current frame and view mode."""
        anim = self.animation
        if anim is None:
            return None
        f = self.frame
        if self._preview is not None and self._preview[0] == f:
            original = self._preview[1]
        else:
            original = anim.frames[f]
        kp = self.dp_poses
        if self.view_mode == "original" or kp is None:
            return Display(f, original)
        if self._preview is not None and self._preview[0] == f:
            rebuilt = original  # a key pose being dragged: the key curve passes through it
        else:
            rebuilt = interpolate_at(kp, [f], np.float32)[0]
        if self.view_mode == "reconstruction":
            return Display(f, rebuilt)
        if self.view_mode == "ghost":
            return Display(f, original, ghost=rebuilt)
        d = np.sqrt(np.einsum("vi,vi->v", original - rebuilt, original - rebuilt))
        scale = self.error_scale or max(float(d.max()), 1e-12)
        return Display(f, original, colors=magnitude_colors(d / scale))


def _no_groom() -> Groom:
    """The groom of a model's own document (a model without a window: only its animation side
    is used)."""
    from hairtool import samples

    return samples.comb(strands=1, vertices=2)
