"""Recording drags into an animation: the edited groom sampled at a fixed frame rate.

Recording time runs only while a stroke is held (the artist's pauses between strokes are not
recorded), and frames are sampled and held from timestamped poses: frame k shows the last pose
set at or before k/fps of recording time. A stroke lasting T seconds therefore gives
floor(T·fps) + 1 frames, however often or rarely the mouse moved or the screen redrew.
"""

from __future__ import annotations

import numpy as np

from hairtool.errors import GroomError, ParameterError
from hairtool.groom import Animation, Topology
from hairtool.metadata import Metadata

_EPS = 1e-9  # seconds: a sample exactly on a frame time counts for that frame


class Recorder:
    """Collects poses ``(V, 3)`` with wall-clock times (seconds) into frames at ``fps``."""

    def __init__(self, topology: Topology, fps: float = 24.0, metadata: Metadata | None = None) -> None:
        if not np.isfinite(fps) or fps <= 0:
            raise ParameterError("fps", fps, "a positive frame rate")
        self.topology = topology
        self.metadata = Metadata() if metadata is None else metadata.derived()  # the groom's scene
        self.fps = float(fps)
        self.frames: list[np.ndarray] = []
        self._current: np.ndarray | None = None
        self._elapsed = 0.0  # recording time before the current stroke
        self._stroke_start: float | None = None

    @property
    def recording_time(self) -> float:
        return self._elapsed

    def _fill(self, rec_time: float, inclusive: bool) -> None:
        """Append the held pose for every frame time before (or at) ``rec_time``."""
        while True:
            t = len(self.frames) / self.fps
            if t < rec_time - _EPS or (inclusive and t <= rec_time + _EPS):
                self.frames.append(self._current)
            else:
                return

    def begin_stroke(self, now: float, points: np.ndarray) -> None:
        self._stroke_start = float(now)
        self._current = np.array(points, dtype=np.float32)
        self._fill(self._elapsed, inclusive=True)

    def update(self, now: float, points: np.ndarray) -> None:
        """A new pose at wall time ``now`` (ignored outside a stroke)."""
        if self._stroke_start is None:
            return
        rec_time = self._elapsed + max(0.0, float(now) - self._stroke_start)
        self._fill(rec_time, inclusive=False)
        self._current = np.array(points, dtype=np.float32)

    def end_stroke(self, now: float) -> None:
        if self._stroke_start is None:
            return
        self._elapsed += max(0.0, float(now) - self._stroke_start)
        self._fill(self._elapsed, inclusive=True)
        self._stroke_start = None

    def animation(self) -> Animation:
        """The recorded frames; GroomError when fewer than two were captured."""
        if len(self.frames) < 2:
            raise GroomError("nothing recorded: hold Record and drag the hair for a moment")
        return Animation(np.stack(self.frames), self.topology, self.fps, metadata=self.metadata)
