"""The studio's animation model: the loaded animation, playback, and the keyframe state.

No widgets: the timeline dock and the viewport listen to its signals, which fire only when a
value really changes. Key work follows the timeline's needs: one solve per animation and
table setting (features, cost table, layered DP) gives the keys of every count, so the
key-count slider answers at once; per-frame errors of the DP keys and of uniform keys of the
same count follow. Work on large animations runs through the window's :class:`JobRunner`; a
job the user cancels leaves the previous keys, settings and curves as they were.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from PySide6.QtCore import QObject, Qt, QTimer, Signal

from app.ui.jobs import Job, JobRunner
from app.ui.legend import magnitude_colors
from hairtool.errors import GroomError, HairtoolError, ParameterError
from hairtool.groom import Animation
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

    def __init__(self, runner: JobRunner | None = None, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.runner = runner
        self.inline_values = INLINE_VALUES  # tests set 0 to send every solve through the runner
        self.clock: Callable[[], float] = time.perf_counter
        self.animation: Animation | None = None
        # what the keys are solved on when not the animation itself: a capture's skeleton as
        # captured, so its keys stay those of the capture while its key poses are edited
        self.key_source: Animation | None = None
        self.source = ""
        self.generation = 0  # counts loaded animations (undo steps of an older one do nothing)
        self.frame = 0
        self.fps = DEFAULT_FPS
        self.playing = False
        self.scrubbing = False
        self.loop = True
        self.settings = ks.KeySettings()
        self.view_mode = "original"
        self._clear_keys()
        self._committed: _Committed | None = None
        self._solve_job: Job | None = None
        self._analysis_job: Job | None = None
        self._preview: tuple[int, np.ndarray] | None = None
        self._timer = QTimer(self)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._timer.timeout.connect(self._tick)
        self._play_start = (0.0, 0)

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
        self, animation: Animation, source: str = "", *, settings: ks.KeySettings | None = None
    ) -> None:
        """Show ``animation`` in the timeline and viewport and solve its keys.

        ``source`` says where it came from (a path, "recording", "anime cycle", …); the other
        docks call this through ``window.animation.load_animation``. Frame 0, playback stopped,
        playback rate the animation's. The key settings stay, except the count, which goes back
        to the knee of the error curve, the pinned and excluded frames, which belonged to the
        last animation, and an error budget (a figure in the last animation's units: the key mode
        goes back to the count); a reopened project passes its saved ``settings`` instead (one
        solve, with those). ParameterError for invalid settings, before anything changes.
        """
        if not isinstance(animation, Animation):
            raise GroomError(f"expected an Animation, got {type(animation).__name__}")
        if settings is not None:
            new_settings = settings.validate()
            new_settings.constraints.check(animation.n_frames)
        else:
            new_settings = self.settings.replace(count=0, pins=(), excludes=())
            if new_settings.mode == "budget":
                d = ks.KeySettings()
                new_settings = new_settings.replace(mode=d.mode, budget=d.budget)
        self.pause()
        self._cancel_jobs()
        self.generation += 1
        self.animation = animation
        self.key_source = None
        self.source = str(source)
        self.frame = 0
        self._preview = None
        self._clear_keys()
        self._committed = None
        if new_settings != self.settings:
            self.settings = new_settings
            self.settings_changed.emit(new_settings)
        if animation.fps != self.fps:
            self.fps = float(animation.fps)
            self.fps_changed.emit(self.fps)
        self._announce_new_animation()
        if animation.n_frames >= 2:
            self.request_solve()

    def clear(self) -> None:
        """No animation: the viewport shows the scene's groom again."""
        if self.animation is None:
            return
        self.pause()
        self._cancel_jobs()
        self.generation += 1
        self.animation, self.source, self.frame, self._preview = None, "", 0, None
        self.key_source = None
        self._clear_keys()
        self._committed = None
        self._announce_new_animation()

    def reset(self) -> None:
        """A new document: no animation, and the values that belong to a document back to their
        defaults: the frame rate (a BVH's 120 fps is not the next groom's) and the key mode with
        its error budget (a figure in the last animation's units). The method chosen stays
        (interpolation, objective, features, the price per key, which is relative); an
        animation or a project brings its own values."""
        self.clear()
        d = ks.KeySettings()
        new = self.settings.replace(mode=d.mode, count=0, budget=d.budget, pins=(), excludes=())
        if new != self.settings:
            self.settings = new
            self.settings_changed.emit(new)
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

    def replace_frames(self, start: int, block: np.ndarray) -> None:
        """Frames ``start .. start + len(block) − 1`` get new poses (a key edit or its undo).

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
    def set_settings(self, **changes: object) -> None:
        """Change key settings; keys follow at once where the existing solve covers them, else a
        new solve starts. A ParameterError (a bad value, or pins and exclusions the mode cannot
        meet, such as an error budget no key set reaches without an excluded frame) comes before
        anything changes, so a refused edit leaves the keys, settings and curves as they were."""
        new = self.settings.replace(**changes)
        if new == self.settings:
            return
        if self.n_frames < 2:
            self.settings = new
            self.settings_changed.emit(new)
            return
        new.constraints.check(self.n_frames)
        solve = self.key_solve
        if solve is None or self.solve_stale or new.table_key != solve.table_key:
            if self._inline():  # solved here: a refusal can still leave everything as it was
                solve = ks.solve(self.keyed, new)
                keys = solve.keys_for(new)
                self._commit_settings(new)
                self._apply_solve(solve, keys)
            else:
                self._commit_settings(new)
                self.request_solve()
            return
        reshaped = new.constraints != solve.constraints
        keys = solve.keys_for(new)  # all or nothing
        self._commit_settings(new)
        if self._solve_job is not None:  # back to the solved table: the pending solve is moot
            job, self._solve_job = self._solve_job, None
            job.cancel()
            self._busy_update()
        if reshaped:  # the same table, other layers
            self.curve_changed.emit()
        self._show_keys(keys)

    def _commit_settings(self, new: ks.KeySettings) -> None:
        self.settings = new
        self.settings_changed.emit(new)

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
        """Solve keys for the current animation and settings (in the background when large)."""
        anim, settings = self.keyed, self.settings
        if anim is None or anim.n_frames < 2:
            return
        if self._inline():
            solve = ks.solve(anim, settings)
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
            keys = result.keys_for(self.settings)
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
        if not force and self.solved_keys is not None and np.array_equal(keys, self.solved_keys):
            if self.analysis is None and self._analysis_job is None:
                self.request_analysis()
            return
        self.dp_keys = self.solved_keys = keys
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
        c = self._committed
        if c is None:  # nothing complete yet for this animation: no keys
            if self.dp_keys is not None or self.key_solve is not None:
                self._clear_keys()
                self.keys_changed.emit()
                self.curve_changed.emit()
                self.analysis_changed.emit()
                self.display_changed.emit()
            return
        if c.settings != self.settings:
            self.settings = c.settings
            self.settings_changed.emit(c.settings)
        steered = c.solve is not None and c.solve.constraints != c.settings.constraints
        if c.solve is not self.key_solve or steered:
            if steered:  # a later edit re-solved the same table under other pins
                c.solve.constrain(c.settings.constraints)
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
