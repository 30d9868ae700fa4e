"""A one-line progress bar on stderr for long commands: only on a terminal, never with --json or
when stderr is piped (scripts and pipelines read clean output)."""

from __future__ import annotations

import sys
import time
from typing import TextIO

WIDTH = 28


class ProgressBar:
    """``bar(fraction, stage)`` redraws ``stage [#####-----]  40%`` in place; ``bar.close()``
    clears the line. Redraws at most 20 times a second."""

    def __init__(self, enabled: bool | None = None, stream: TextIO | None = None) -> None:
        self.stream = stream or sys.stderr
        self.enabled = self.stream.isatty() if enabled is None else enabled
        self._last = 0.0
        self._shown = False

    def __call__(self, fraction: float | None = None, stage: str = "") -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        if fraction is not None and 0.0 < fraction < 1.0 and now - self._last < 0.05:
            return
        self._last = now
        f = 0.0 if fraction is None else min(max(float(fraction), 0.0), 1.0)
        filled = round(f * WIDTH)
        self.stream.write(f"\r{stage[:24]:<24} [{'#' * filled}{'-' * (WIDTH - filled)}] {f:4.0%}")
        self.stream.flush()
        self._shown = True

    def close(self) -> None:
        if self.enabled and self._shown:
            self.stream.write("\r" + " " * (24 + WIDTH + 9) + "\r")
            self.stream.flush()
            self._shown = False
