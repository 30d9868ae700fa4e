"""The batch's progress line on a terminal: jobs done, running and failed, with an ETA.

Redrawn in place (carriage return) when a job finishes and once a second between, from a
small thread, so the ETA counts down through long jobs. Not drawn when the stream is not a
terminal (logs, pipes) or with ``--json``.
"""

from __future__ import annotations

import sys
import threading
import time
from typing import TextIO

BAR_WIDTH = 24


def format_seconds(seconds: float) -> str:
    s = max(0, round(seconds))
    if s < 60:
        return f"{s}s"
    if s < 3600:
        return f"{s // 60}m{s % 60:02d}s"
    return f"{s // 3600}h{s % 3600 // 60:02d}m"


class Progress:
    """Counts of a batch and their line; ``enabled=None`` draws only on a terminal."""

    def __init__(self, stream: TextIO | None = None, enabled: bool | None = None) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = self.stream.isatty() if enabled is None else enabled
        self.total = self.skipped = self.done = self.failed = self.running = 0
        self.to_run = 0
        self._t0 = time.perf_counter()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._ticker: threading.Thread | None = None
        self._width = 0

    def start(self, total: int, skipped: int) -> None:
        self.total, self.skipped, self.to_run = total, skipped, total - skipped
        self._t0 = time.perf_counter()
        if self.enabled and self.to_run:
            self._ticker = threading.Thread(target=self._tick, name="hairtool-batch-progress", daemon=True)
            self._ticker.start()
        self.draw()

    def update(self, *, done: int = 0, failed: int = 0, running: int | None = None) -> None:
        with self._lock:
            self.done += done
            self.failed += failed
            if running is not None:
                self.running = running
        self.draw()

    def eta(self) -> float | None:
        """Seconds left at the rate jobs have finished so far; None before the first one."""
        finished = self.done + self.failed
        if finished == 0:
            return None
        return (time.perf_counter() - self._t0) / finished * (self.to_run - finished)

    def line(self) -> str:
        with self._lock:
            finished = self.done + self.failed + self.skipped
            filled = round(BAR_WIDTH * finished / self.total) if self.total else BAR_WIDTH
            eta = self.eta()
            parts = [
                f"[{'#' * filled}{'.' * (BAR_WIDTH - filled)}] {finished}/{self.total}",
                f"{self.done} done",
                f"{self.running} running",
                f"{self.failed} failed",
            ]
            if self.skipped:
                parts.append(f"{self.skipped} skipped")
            parts.append("ETA " + ("?" if eta is None else format_seconds(eta)))
            return " · ".join(parts)

    def draw(self) -> None:
        if not self.enabled:
            return
        text = self.line()
        pad = max(0, self._width - len(text))
        self._width = len(text)
        self.stream.write("\r" + text + " " * pad)
        self.stream.flush()

    def _tick(self) -> None:
        while not self._stop.wait(1.0):
            self.draw()

    def finish(self) -> None:
        self._stop.set()
        if self._ticker is not None:
            self._ticker.join()
        if self.enabled:
            self.draw()
            self.stream.write("\n")
            self.stream.flush()
