"""Brush moves off the GUI thread, so the cursor never waits for the engine.

Each mouse move of a stroke becomes its samples at once, on the GUI thread (what the log and the
undo keep). The engine runs them in one worker thread: while it works, the moves that come in
wait together, and when it is done they all go to it in one call (coalesced: the engine always
catches up to the latest sample in one run, never a queue of runs behind the mouse). Every
sample reaches the pipeline, in order, so the stroke's log, its undo step and a replay are those
of the same moves made one by one. The view takes a result when it lands (a queued signal);
meanwhile it draws the brush circle over the last image.

Brushes that add or remove strands run on the GUI thread, as before: the render hair that
follows their guides is built from the pipeline's state, which only the GUI thread may read.
Anything else that reads or changes the pipeline waits first (:meth:`MoveEngine.drain`).
"""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np
from PySide6.QtCore import QObject, Qt, Signal, Slot

from app.ui.brush_tool import LABELS
from hairtool.errors import HairtoolError
from hairtool.frozen.brushes import CHANGE_STRANDS


@dataclass(eq=False)
class Move:
    """One mouse move of a stroke: its samples and what the touch test needs."""

    samples: list
    cursor: np.ndarray
    plane_x: float
    pressure: float
    check_touch: bool


@dataclass(eq=False)
class Batch:
    """The moves one engine run takes, and what it gave."""

    moves: list[Move]
    refusals: list[str] = field(default_factory=list)
    touched: bool = False
    ms: float = 0.0
    ran: bool = False  # some samples reached the pipeline (its result is new)
    changed: np.ndarray | None = None  # the strands the run may have moved (None: any)
    error: BaseException | None = None  # anything but a refusal: raised again on the GUI thread
    done: threading.Event = field(default_factory=threading.Event)


class MoveEngine(QObject):
    """The scene's brush moves, run by one worker thread (module docstring).

    ``delay_s``: seconds each run waits first, an injected slow engine (tests, benchmarks).
    ``threaded``: False runs every move on the GUI thread, as a synchronous engine would."""

    landed = Signal()  # a run's result is the scene's now (GUI thread)
    _finished = Signal(object)  # a Batch, from the worker (queued to the GUI thread)

    def __init__(self, scene, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.scene = scene
        self.delay_s = 0.0
        self.threaded = True
        self.touched = False  # some move since :meth:`begin` reached a strand
        self.runs = 0  # engine runs since begin (fewer than the moves when they were coalesced)
        self._pending: list[Move] = []
        self._running: Batch | None = None
        self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="hairtool-moves")
        self._finished.connect(self._on_finished, Qt.ConnectionType.QueuedConnection)

    @property
    def busy(self) -> bool:
        """A run is under way or moves wait for one."""
        return self._running is not None or bool(self._pending)

    def begin(self) -> None:
        """A stroke starts: its touch flag and run count from zero."""
        self.drain()
        self.touched = False
        self.runs = 0

    def move(
        self,
        cursor: np.ndarray,
        direction: np.ndarray,
        view: np.ndarray | None,
        invert: bool,
        start: bool,
        pressure: float,
        add: bool = False,
        eye: np.ndarray | None = None,
    ) -> None:
        """One mouse move of the current brush (as :meth:`app.ui.scene.Scene.brush_move`): its
        samples are made now; the engine runs them when it is free."""
        s = self.scene
        if not self.threaded or s.tool.brush in CHANGE_STRANDS or not s.engine_ready:
            self.drain()
            touched = s.brush_move(
                cursor, direction, view, invert, not self.touched, start, pressure, add, eye
            )
            self.touched = self.touched or touched
            self.runs += 1
            return
        plane = s.mirror_plane_x()
        samples = s.tool.samples(cursor, direction, view, plane, invert, start, pressure, add, eye)
        cursor = np.asarray(cursor, np.float64)
        self._pending.append(Move(samples, cursor, plane, pressure, not self.touched))
        if self._running is None:
            self._launch()

    def _launch(self) -> None:
        batch, self._pending = Batch(self._pending), []
        self._running = batch
        self._worker.submit(self._run, batch)

    def _run(self, batch: Batch) -> None:
        """In the worker thread: the batch's samples in one pipeline call."""
        try:
            t0 = time.perf_counter()
            if self.delay_s > 0:
                time.sleep(self.delay_s)
            self._apply(batch)
            batch.ms = (time.perf_counter() - t0) * 1e3
        except BaseException as e:  # handed to the GUI thread, raised there
            batch.error = e
        batch.done.set()
        try:
            self._finished.emit(batch)
        except RuntimeError:  # the window closed meanwhile, its scene and this engine with it
            pass

    def _apply(self, batch: Batch) -> None:
        pipeline, tool = self.scene.pipeline, self.scene.tool
        samples = [x for m in batch.moves for x in m.samples]
        if samples:
            try:
                pipeline.apply_samples(samples)
                batch.ran = True
                batch.changed = pipeline.changed  # one call: its region is the batch's
            except HairtoolError:
                # a refused move changes nothing: the others go through one by one, as they came
                label = LABELS.get(tool.brush, tool.brush)
                for m in batch.moves:
                    if not m.samples:
                        continue
                    try:
                        pipeline.apply_samples(m.samples)
                        batch.ran = True
                    except HairtoolError as e:
                        batch.refusals.append(f"{label}: {e}")
        points = pipeline.aligned.points
        batch.touched = any(
            tool.touches(points, m.cursor, m.plane_x, m.pressure) for m in batch.moves if m.check_touch
        )

    @Slot(object)  # (a receiver of a signal from another thread is a declared slot: PYSIDE-3124)
    def _on_finished(self, batch: Batch) -> None:
        if batch is self._running:  # (not landed already by drain)
            self._land(batch)
            if self._pending:
                self._launch()

    def _land(self, batch: Batch) -> None:
        """On the GUI thread: the batch's result becomes the scene's (render hair, mask, views)."""
        self._running = None
        self.runs += 1
        if batch.error is not None:
            raise batch.error
        s = self.scene
        if batch.ran:
            result = s.pipeline.result
            s._stroke_step(lambda: result, moved=batch.changed)
        else:  # a comb standing still: nothing ran; the view still follows the cursor
            s.points_changed.emit()
        s.last_update_ms = batch.ms
        self.touched = self.touched or batch.touched
        for why in batch.refusals:
            s.refused.emit(why)
        self.landed.emit()

    def drain(self) -> None:
        """Block until every move given so far has run and landed (a release, an undo, a
        parameter change: whatever reads the pipeline next sees the whole stroke)."""
        while self.busy:
            if self._running is not None:
                self._running.done.wait()
                self._land(self._running)
            if self._pending:  # the rest runs here, in one call, as the worker would have
                batch, self._pending = Batch(self._pending), []
                self._running = batch
                self._run(batch)

    def shutdown(self) -> None:
        """Finish what was given, then end the worker thread (the window closes)."""
        self.drain()
        self._worker.shutdown(wait=True)
