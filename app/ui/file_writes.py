"""Files written off the GUI thread, one at a time, in the order asked.

A save takes its snapshot on the GUI thread (the groom's arrays are immutable, so that is cheap)
and hands the writing of it here. The write runs as a job of the window's runner (the status bar
shows it, without Cancel: a file is renamed into place whole or not at all), so the window keeps
answering. Writes queue: a second Save while the first is writing starts once the first has
ended, so two writers never meet on one file and the last one asked for is the one on disk.
:meth:`FileWrites.wait` blocks in a local event loop, the window still answering, until a
write (or every write) has ended: Quit, the Save of the unsaved-changes question and tests.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from PySide6.QtCore import QEventLoop, QObject, Signal

from app.ui.jobs import JobRunner
from hairtool.errors import HairtoolError


def save_failure(path: str | os.PathLike[str], error: BaseException) -> str:
    """Why a write of ``path`` failed, in one line that names the file."""
    reason = str(error) if isinstance(error, HairtoolError) else f"{type(error).__name__}: {error}"
    return reason if str(path) in reason else f"{path}: {reason}"


@dataclass(eq=False)
class FileWrite:
    """One file to write: ``write`` runs in a worker, ``on_written`` / ``on_failed`` on the GUI
    thread. ``state``: "queued", "writing", "written" or "failed" (``error`` then says why)."""

    title: str
    path: Path
    write: Callable[[], None]
    on_written: Callable[[], None]
    on_failed: Callable[[BaseException], None]
    state: str = "queued"
    error: BaseException | None = None

    @property
    def ended(self) -> bool:
        return self.state in ("written", "failed")


class FileWrites(QObject):
    """The window's queue of file writes (``window.writes``); see the module docstring."""

    ended = Signal(object)  # FileWrite, written or failed, after its on_written / on_failed

    def __init__(self, jobs: JobRunner, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.jobs = jobs
        self._queue: list[FileWrite] = []  # the one writing first, then those waiting

    @property
    def pending(self) -> list[FileWrite]:
        """Writes not yet ended: the one writing, then those queued behind it."""
        return list(self._queue)

    def queue(
        self,
        title: str,
        path: Path,
        write: Callable[[], None],
        on_written: Callable[[], None],
        on_failed: Callable[[BaseException], None],
    ) -> FileWrite:
        """Write ``path`` with ``write()`` once the writes asked before have ended."""
        item = FileWrite(title, Path(path), write, on_written, on_failed)
        self._queue.append(item)
        if len(self._queue) == 1:
            self._start(item)
        return item

    def _start(self, item: FileWrite) -> None:
        item.state = "writing"

        def work(progress, cancelled) -> None:
            progress(None, item.path.name)
            item.write()

        self.jobs.run(
            item.title,
            work,
            lambda _: self._end(item, None),
            on_error=lambda e: self._end(item, e),
            on_cancelled=lambda: self._end(item, RuntimeError(f"{item.path}: the write was stopped")),
            cancellable=False,
        )

    def _end(self, item: FileWrite, error: BaseException | None) -> None:
        self._queue.remove(item)
        item.state, item.error = ("written", None) if error is None else ("failed", error)
        try:
            if error is None:
                item.on_written()
            else:
                item.on_failed(error)
        finally:
            if self._queue:
                self._start(self._queue[0])
            self.ended.emit(item)

    def wait(self, item: FileWrite | None = None) -> bool:
        """Run a local event loop until ``item`` (every queued write when None) has ended;
        True when it was written (every one, when None)."""
        items = [item] if item is not None else self.pending
        while not all(i.ended for i in items):
            loop = QEventLoop()
            self.ended.connect(loop.quit)
            try:
                if not all(i.ended for i in items):  # (it may have ended while connecting)
                    loop.exec()
            finally:
                self.ended.disconnect(loop.quit)
        return all(i.state == "written" for i in items)
