"""A first start without cached kernels: the window shows at once, the kernels compile in another
process (:mod:`app.ui.kernel_warmup`) with their progress in the status bar, and the scene's engine
starts when they are cached. Until then the groom shows as it is, parameter edits are kept for the
engine, and a stroke says in the status bar that the engine is on its way.
"""

from __future__ import annotations

import sys

from PySide6.QtCore import QEventLoop, QObject, QProcess, Qt, Signal
from PySide6.QtGui import QGuiApplication
from PySide6.QtWidgets import QProgressBar, QStatusBar

from app.ui.kernel_warmup import STEPS
from app.ui.scene import Scene
from app.ui.status_line import ElidedLabel

STARTUP_STEPS = 2  # the warm-up's steps the engine and the first paint need (the rest follow)
WAIT_MESSAGE = "The hair engine is still being prepared (first start): strokes work in a moment"


class EngineStart(QObject):
    """Runs the warm-up process and starts ``scene``'s engine when it is done (or failed: then
    the engine compiles in the studio, with a wait cursor and a message).

    ``step_ready(label)`` says which warm-up step's kernels are cached now, ``ended()`` that the
    warm-up is over (done or not), so what waits for a step can go ahead."""

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
        self.step = 0
        self.process = QProcess(self)
        self.process.setProcessChannelMode(QProcess.ProcessChannelMode.ForwardedErrorChannel)
        self.process.readyReadStandardOutput.connect(self._read)
        self.process.finished.connect(self._on_finished)
        self.process.errorOccurred.connect(self._on_error)
        scene.engine_starting.connect(self._on_starting)
        scene.engine_started.connect(self._on_started)
        self._waiting_cursor = False
        self._closing = False

    @property
    def running(self) -> bool:
        return self.process.state() != QProcess.ProcessState.NotRunning

    def start(self) -> None:
        # --with-parent: the warm-up ends when this process does (its stdin is our pipe)
        self.process.start(sys.executable, ["-m", "app.ui.kernel_warmup", "--with-parent"])

    def stop(self, closing: bool = True) -> None:
        """End the warm-up; the kernels compiled so far stay cached. ``closing`` (the window
        closes): nothing follows, the engine is not started here (it would compile every kernel
        on the GUI thread of a window being closed) and ``ended`` is not emitted."""
        self._closing = self._closing or closing
        if self.running:
            self.process.kill()
            self.process.waitForFinished(3000)

    def _read(self) -> None:
        while self.process.canReadLine():
            parts = bytes(self.process.readLine()).decode(errors="replace").split(maxsplit=3)
            if len(parts) == 4 and parts[0] == "step":
                done, total, label = int(parts[1]), int(parts[2]), parts[3].strip()
                self.step = done
                self.progress.setRange(0, total)
                self.progress.setValue(done)
                self.label.setText(f"Preparing the hair engine (first start): {label} ready, {done}/{total}")
                if done >= STARTUP_STEPS and not self.scene.engine_ready:
                    self.scene.start_engine()  # what a stroke and a paint need is cached now
                self.step_ready.emit(label)

    def _on_finished(self, code: int, status: QProcess.ExitStatus) -> None:
        if self._closing:
            return
        ok = status == QProcess.ExitStatus.NormalExit and code == 0
        self.ended.emit()
        if self.scene.engine_ready:
            self._remove_progress()
            return
        if not ok:
            self.bar.showMessage("Preparing the hair engine in the studio: the window pauses once", 8000)
        self.scene.start_engine()

    def _on_error(self, error: QProcess.ProcessError) -> None:
        if error == QProcess.ProcessError.FailedToStart:
            self._on_finished(1, QProcess.ExitStatus.CrashExit)

    def _on_starting(self) -> None:
        if self.step < STARTUP_STEPS:  # compiling here, not loading the cache: show the wait
            self.label.setText("Preparing the hair engine…")
            QGuiApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)
            self._waiting_cursor = True
            QGuiApplication.processEvents(QEventLoop.ProcessEventsFlag.ExcludeUserInputEvents)

    def _on_started(self) -> None:
        if self._waiting_cursor:
            QGuiApplication.restoreOverrideCursor()
            self._waiting_cursor = False
        self.bar.showMessage("The hair engine is ready", 4000)
        if self.step < STARTUP_STEPS:  # started before the warm-up got there: it compiled here
            self.stop(closing=False)
        if not self.running:
            self._remove_progress()

    def _remove_progress(self) -> None:
        if self.label is None:
            return
        self.process.readyReadStandardOutput.disconnect(self._read)
        for w in (self.label, self.progress):
            self.bar.removeWidget(w)
            w.deleteLater()
        self.label = self.progress = None
