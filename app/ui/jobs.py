"""Long work off the GUI thread, with a progress bar and a Cancel button in the status bar.

Usage (the window owns one runner, ``window.jobs``)::

    def work(progress, cancelled):          # runs in a worker thread: no Qt widgets here
        for i, chunk in enumerate(chunks):
            if cancelled():
                return None                 # or raise Cancelled; the result is dropped
            ...
            progress((i + 1) / len(chunks), f"chunk {i + 1}")
        return result

    window.jobs.run("Solving keys", work, on_done=lambda result: ...)

- ``progress(fraction, text="")``: fraction in [0, 1] or None for a busy bar; thread-safe and
  throttled, call it as often as is convenient.
- ``cancelled()``: True once the user pressed Cancel (or the job was superseded): stop soon.
- ``on_done(result)`` runs on the GUI thread, and only for a job that was not cancelled, so a
  cancelled job never replaces the previous result. ``on_error(exc)`` (GUI thread) gets any
  exception; by default it goes to the runner's ``error_handler`` (the window's
  ``show_error``: one dialog, no traceback). ``on_cancelled()`` (GUI thread) is optional.
- ``group``: a new job of the same group cancels the running one first (e.g. re-solving keys
  while a slider moves); jobs of different groups run side by side.
- ``cancellable=False``: a job that must run to its end (a file being written: it is renamed
  into place whole or not at all); Cancel is not offered and ``cancel`` passes it by.
- ``runner.wait()`` blocks while processing events until no job runs (tests, closing).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from PySide6.QtCore import QElapsedTimer, QObject, QRunnable, Qt, QThreadPool, Signal, Slot
from PySide6.QtWidgets import QApplication, QHBoxLayout, QProgressBar, QToolButton, QWidget

from app.ui.status_line import ElidedLabel
from hairtool.errors import Cancelled, HairtoolError

ProgressFn = Callable[..., None]
CancelledFn = Callable[[], bool]
JobFn = Callable[[ProgressFn, CancelledFn], Any]

_PROGRESS_INTERVAL_S = 0.05  # at most ~20 progress updates per second reach the GUI


@dataclass(eq=False)
class Job:
    """One piece of work; ``state`` is "running", "done", "cancelled" or "failed"."""

    title: str
    group: str | None
    on_done: Callable[[Any], None] | None
    on_error: Callable[[BaseException], None] | None
    on_cancelled: Callable[[], None] | None
    cancellable: bool = True
    state: str = "running"
    fraction: float | None = None
    text: str = ""
    _cancel: threading.Event = field(default_factory=threading.Event)

    def cancel(self) -> None:
        self._cancel.set()

    @property
    def cancelled(self) -> bool:
        return self._cancel.is_set()


class _Bridge(QObject):
    """Lives on the GUI thread; the worker emits, Qt queues the call to the GUI thread."""

    progressed = Signal(object, object, str)  # job, fraction, text
    ended = Signal(object, str, object)  # job, "ok" | "error" | "cancel", result or exception


class _Runnable(QRunnable):
    def __init__(self, job: Job, fn: JobFn, bridge: _Bridge) -> None:
        super().__init__()
        self.job, self.fn, self.bridge = job, fn, bridge
        self._last = 0.0

    def _progress(self, fraction: float | None = None, text: str = "") -> None:
        now = time.perf_counter()
        if now - self._last >= _PROGRESS_INTERVAL_S or (fraction is not None and fraction >= 1.0):
            self._last = now
            self.bridge.progressed.emit(self.job, fraction, str(text))

    def run(self) -> None:
        job = self.job
        try:
            result = self.fn(self._progress, lambda: job.cancelled)
        except Cancelled:
            self.bridge.ended.emit(job, "cancel", None)
        except BaseException as e:  # delivered to on_error on the GUI thread
            self.bridge.ended.emit(job, "error", e)
        else:
            self.bridge.ended.emit(job, "cancel" if job.cancelled else "ok", result)


class JobRunner(QObject):
    """Runs job functions in a thread pool; see the module docstring for the contract."""

    job_started = Signal(object)  # Job
    job_finished = Signal(object)  # Job, whatever its end ("done", "cancelled" or "failed")
    progress_changed = Signal(object)  # Job

    def __init__(
        self, error_handler: Callable[[str, str], None] | None = None, parent: QObject | None = None
    ) -> None:
        super().__init__(parent)
        self.error_handler = error_handler
        self.pool = QThreadPool(self)
        self.pool.setMaxThreadCount(max(2, QThreadPool.globalInstance().maxThreadCount()))
        self._bridge = _Bridge(self)
        self._bridge.progressed.connect(self._on_progress, Qt.ConnectionType.QueuedConnection)
        self._bridge.ended.connect(self._on_ended, Qt.ConnectionType.QueuedConnection)
        self._jobs: list[Job] = []  # still running in a thread (cancelled ones included)

    # -- public ----------------------------------------------------------------------------
    def run(
        self,
        title: str,
        fn: JobFn,
        on_done: Callable[[Any], None] | None = None,
        *,
        on_error: Callable[[BaseException], None] | None = None,
        on_cancelled: Callable[[], None] | None = None,
        group: str | None = None,
        cancellable: bool = True,
    ) -> Job:
        """Start ``fn(progress, cancelled)`` in a worker thread; returns the :class:`Job` at once."""
        if group is not None:
            for old in self.active(group):
                self.cancel(old)
        job = Job(title, group, on_done, on_error, on_cancelled, cancellable)
        self._jobs.append(job)
        self.pool.start(_Runnable(job, fn, self._bridge))
        self.job_started.emit(job)
        return job

    def active(self, group: str | None = None) -> list[Job]:
        """Jobs still running and not cancelled (of one group, or all)."""
        return [j for j in self._jobs if not j.cancelled and (group is None or j.group == group)]

    @property
    def busy(self) -> bool:
        return bool(self.active())

    def cancel(self, job: Job | None = None) -> None:
        """Cancel one job (all when None); their results will be dropped. A job that is not
        ``cancellable`` runs on."""
        for j in [job] if job is not None else list(self._jobs):
            if j.state == "running" and not j.cancelled and j.cancellable:
                j.cancel()
                self.job_finished.emit(j)  # the bar goes away now; the thread ends on its own

    def wait(self, timeout_s: float = 30.0) -> bool:
        """Process events until every job's thread has ended and its result was delivered."""
        clock = QElapsedTimer()
        clock.start()
        while self._jobs:
            if clock.elapsed() > timeout_s * 1000:
                return False
            self.pool.waitForDone(10)
            QApplication.processEvents()
        return True

    def shutdown(self, timeout_s: float = 5.0) -> None:
        """Cancel everything and wait a little (the window calls this when it closes)."""
        self.cancel()
        self.pool.waitForDone(int(timeout_s * 1000))
        QApplication.processEvents()

    # -- worker → GUI thread ------------------------------------------------------------------
    @Slot(object, object, str)
    def _on_progress(self, job: Job, fraction: object, text: str) -> None:
        if job.state == "running" and not job.cancelled:
            job.fraction = None if fraction is None else min(max(float(fraction), 0.0), 1.0)
            job.text = text
            self.progress_changed.emit(job)

    @Slot(object, str, object)
    def _on_ended(self, job: Job, how: str, payload: object) -> None:
        if job in self._jobs:
            self._jobs.remove(job)
        was_cancelled = job.cancelled
        if how == "ok" and not was_cancelled:
            job.state = "done"
            self.job_finished.emit(job)
            if job.on_done is not None:
                job.on_done(payload)
        elif how == "error" and not was_cancelled:
            job.state = "failed"
            self.job_finished.emit(job)
            if job.on_error is not None:
                job.on_error(payload)
            else:
                self.report_error(job, payload)
        else:
            job.state = "cancelled"
            if not was_cancelled:  # raised Cancelled by itself
                job.cancel()
                self.job_finished.emit(job)
            if job.on_cancelled is not None:
                job.on_cancelled()

    def report_error(self, job: Job, error: BaseException) -> None:
        """One dialog through ``error_handler``: the message of a HairtoolError, never a traceback."""
        message = str(error) if isinstance(error, HairtoolError) else f"{type(error).__name__}: {error}"
        if self.error_handler is not None:
            self.error_handler(job.title, message)


class JobStatus(QWidget):
    """Status-bar widget: the newest running job's title, a progress bar and Cancel; hidden when idle."""

    def __init__(self, runner: JobRunner, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.runner = runner
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.label = ElidedLabel(min_width=60)
        self.bar = QProgressBar()
        self.bar.setFixedWidth(140)  # its own width: the percentage inside is never squeezed
        self.bar.setMaximumHeight(16)
        self.bar.setRange(0, 1000)
        self.cancel_button = QToolButton()
        self.cancel_button.setText("Cancel")
        self.cancel_button.setObjectName("JobCancel")
        layout.addWidget(self.label)
        layout.addWidget(self.bar)
        layout.addWidget(self.cancel_button)
        self.cancel_button.clicked.connect(self._cancel_shown)
        runner.job_started.connect(self._refresh)
        runner.job_finished.connect(self._refresh)
        runner.progress_changed.connect(self._refresh)
        self._shown: Job | None = None
        self.setVisible(False)

    def _refresh(self, *_: object) -> None:
        jobs = self.runner.active()
        self._shown = jobs[-1] if jobs else None
        if self._shown is None:
            self.setVisible(False)
            return
        job = self._shown
        more = f" (+{len(jobs) - 1})" if len(jobs) > 1 else ""
        self.label.setText(f"{job.title}{more}" + (f": {job.text}" if job.text else ""))
        if job.fraction is None:
            self.bar.setRange(0, 0)  # busy indicator
        else:
            self.bar.setRange(0, 1000)
            self.bar.setValue(round(job.fraction * 1000))
        self.cancel_button.setVisible(job.cancellable)
        self.setVisible(True)

    def _cancel_shown(self) -> None:
        if self._shown is not None:
            self.runner.cancel(self._shown)
