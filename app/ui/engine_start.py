"""A first start without cached kernels: the window shows at once, the kernels compile in other
processes (:mod:`app.ui.kernel_warmup`, one per lane: the engine's and the render hair's side by
side) with their progress in the status bar, and the scene's engine starts when its kernels are
cached. Until then the groom shows as it is, parameter edits are kept for the engine, and a
stroke says in the status bar that the engine is on its way. The engine and the render hair run
on the serial twins of their kernels (:mod:`hairtool.serial_twins`: the warm-up compiles those
first, in half the time) until the warm-up has cached the parallel kernels too.
"""

from __future__ import annotations

import sys

from PySide6.QtCore import QEventLoop, QObject, QProcess, Qt, Signal
from PySide6.QtGui import QGuiApplication
from PySide6.QtWidgets import QProgressBar, QStatusBar

from app.ui import kernel_warmup
from app.ui.kernel_warmup import ENGINE_STEP, LANES, PARALLEL_STEPS, STEPS
from app.ui.scene import Scene
from app.ui.status_line import ElidedLabel

WAIT_MESSAGE = "The hair engine is still being prepared (first start): strokes work in a moment"


class EngineStart(QObject):
    """Runs the warm-up processes and starts ``scene``'s engine when its step is done (or the
    warm-up failed: then the engine compiles in the studio, with a wait cursor and a message).

    ``step_ready(label)`` says which warm-up step's kernels are cached now, ``ended()`` that the
    warm-up is over (every process done or not), so what waits for a step can go ahead."""

    step_ready = Signal(str)
    ended = Signal()

    def __init__(self, scene: Scene, bar: QStatusBar, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.scene, self.bar = scene, bar
        self.label = ElidedLabel("Preparing the hair engine (first start)…", min_width=80)
        self.label.setObjectName("EngineLabel")
        self.progress = QProgressBar()
        self.progress.setObjectName("EngineProgress")
        self.progress.setFixedWidth(140)  # its own width: the percentage inside is never squeezed
        # a step count from the start, never the busy animation: with a GL viewport in the window
        # every frame of it recomposes the whole window on the GL (llvmpipe: most of a core)
        self.progress.setRange(0, len(STEPS))
        self.progress.setValue(0)
        self.progress.setToolTip(
            "numba compiles the engine's kernels once, in the background; later starts load them"
        )
        for w in (self.label, self.progress):
            bar.addPermanentWidget(w)
        self.step = 0  # warm-up steps done, all processes together
        self.done: set[str] = set()
        self.processes = [QProcess(self) for _ in LANES]
        self._failed = False
        self._ended = False
        for process in self.processes:
            process.setProcessChannelMode(QProcess.ProcessChannelMode.ForwardedErrorChannel)
            process.readyReadStandardOutput.connect(lambda p=process: self._read(p))
            process.finished.connect(self._on_finished)
            process.errorOccurred.connect(lambda error, p=process: self._on_error(p, error))
        # the serial twins until the parallel kernels are cached (the warm-up's first steps
        # compile the twins: half the time); the engine and the render hair start later
        kernel_warmup.use_parallel(False)
        scene.engine_starting.connect(self._on_starting)
        scene.engine_started.connect(self._on_started)
        self._waiting_cursor = False
        self._closing = False

    @property
    def process(self) -> QProcess:
        """The first lane's process (the engine's)."""
        return self.processes[0]

    @property
    def running(self) -> bool:
        return any(p.state() != QProcess.ProcessState.NotRunning for p in self.processes)

    def start(self) -> None:
        # --with-parent: each warm-up ends when this process does (its stdin is our pipe)
        for lane, process in enumerate(self.processes, start=1):
            args = ["-m", "app.ui.kernel_warmup", "--lane", str(lane), "--with-parent"]
            process.start(sys.executable, args)

    def stop(self, closing: bool = True) -> None:
        """End the warm-up; the kernels compiled so far stay cached. ``closing`` (the window
        closes): nothing follows, the engine is not started here (it would compile every kernel
        on the GUI thread of a window being closed) and ``ended`` is not emitted."""
        self._closing = self._closing or closing
        if closing:  # nothing of this start runs any more: the process's kernels as by default
            kernel_warmup.use_parallel(True)
        for process in self.processes:
            if process.state() != QProcess.ProcessState.NotRunning:
                process.kill()
                process.waitForFinished(3000)

    def _read(self, process: QProcess) -> None:
        while process.canReadLine():
            parts = bytes(process.readLine()).decode(errors="replace").split(maxsplit=3)
            if len(parts) == 4 and parts[0] == "step" and parts[1].isdigit() and parts[2].isdigit():
                total, label = int(parts[2]), parts[3].strip()
                self.done.add(label)
                self.step = done = len(self.done)
                self.progress.setRange(0, total)
                self.progress.setValue(done)
                self.label.setText(f"Preparing the hair engine (first start): {label} ready, {done}/{total}")
                if label == ENGINE_STEP and not self.scene.engine_ready:
                    self.scene.start_engine()  # what a stroke needs is cached now
                if label in PARALLEL_STEPS and set(PARALLEL_STEPS) <= self.done:
                    kernel_warmup.use_parallel(True)  # the next engine run loads them
                self.step_ready.emit(label)

    def _on_finished(self, code: int, status: QProcess.ExitStatus) -> None:
        if self._closing or self._ended:
            return
        self._failed = self._failed or status != QProcess.ExitStatus.NormalExit or code != 0
        if self.running:  # the other lane still compiles
            return
        self._ended = True  # both lanes may have exited before the first's signal came
        self.ended.emit()
        if self.scene.engine_ready:
            self._remove_progress()
            return
        if self._failed:
            self.bar.showMessage("Preparing the hair engine in the studio: the window pauses once", 8000)
        self.scene.start_engine()

    def _on_error(self, process: QProcess, error: QProcess.ProcessError) -> None:
        if error == QProcess.ProcessError.FailedToStart:
            self._failed = True
            if not self.running:
                self._on_finished(1, QProcess.ExitStatus.CrashExit)

    def _on_starting(self) -> None:
        if ENGINE_STEP not in self.done:  # compiling here, not loading the cache: show the wait
            self.label.setText("Preparing the hair engine…")
            QGuiApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)
            self._waiting_cursor = True
            QGuiApplication.processEvents(QEventLoop.ProcessEventsFlag.ExcludeUserInputEvents)

    def _on_started(self) -> None:
        if self._waiting_cursor:
            QGuiApplication.restoreOverrideCursor()
            self._waiting_cursor = False
        self.bar.showMessage("The hair engine is ready", 4000)
        if ENGINE_STEP not in self.done:  # started before the warm-up got there: compiled here
            self.stop(closing=False)
        if not self.running:
            self._remove_progress()

    def _remove_progress(self) -> None:
        if self.label is None:
            return
        for process in self.processes:
            process.readyReadStandardOutput.disconnect()
        for w in (self.label, self.progress):
            self.bar.removeWidget(w)
            w.deleteLater()
        self.label = self.progress = None
