"""Limited-animation timing for a periodic hair cycle (Furukawa & Nakata 2018, §2).

A cycle of period T seconds at N_FPS frames/s takes N_Frame = [N_FPS·T] frames (nearest, halves
up). Pictures ("drawings") are held for N_Dup frames ("on twos" for N_Dup = 2):
N_Pict = ⌈N_Frame/N_Dup⌉ pictures, drawn at t = 0, Δt, 2Δt, … with Δt = T/N_Pict;
K = N_Dup·N_Pict − N_Frame of them, the last ones, are held one frame less. The cycle then
repeats every N_Frame frames; its length N_Frame/N_FPS differs slightly from T on purpose.

Frames and pictures are numbered from 0 here, as in :class:`hairtool.groom.Animation`.
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from hairtool.errors import ParameterError
from hairtool.io.atomic import atomic_open

MAX_CYCLE_FRAMES = 100_000
MAX_SHOT_FRAMES = 10_000_000


def _decimal(value: float) -> Decimal:
    """The decimal a person typed: ``repr`` of a float is its shortest round-tripping form."""
    return Decimal(repr(float(value)))


def round_half_up(value: float) -> int:
    """Nearest integer, halves away from zero: 12.5 → 13 (Python's ``round`` gives 12).

    Parameters
    ----------
    value : float
        A finite number.

    Returns
    -------
    int
        The nearest integer.
    """
    return int(_decimal(value).quantize(Decimal(1), rounding=ROUND_HALF_UP))


def frames_per_cycle(period: float, fps: float) -> int:
    """N_Frame = [N_FPS·T], halves up, robust to binary fractions: 0.5 s × 25 fps = 12.5 → 13.

    A float product can land just below a half (0.58 × 25 is 14.499999999999998 in binary) and
    round the wrong way. The product of the typed decimals is exact, and snapping it to 1e-9
    frame first also rounds computed periods such as 1/48 s at 24 fps (0.4999…) to 1 frame.

    Parameters
    ----------
    period : float
        T in seconds.
    fps : float
        N_FPS.

    Returns
    -------
    int
        N_Frame.
    """
    n = _decimal(period) * _decimal(fps)
    if n > MAX_CYCLE_FRAMES * 10:  # far beyond any cycle: no rounding subtleties to settle
        return int(n)
    return int(n.quantize(Decimal("1e-9")).quantize(Decimal(1), rounding=ROUND_HALF_UP))


def _check_positive(name: str, value: float, what: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, what) from None
    if not math.isfinite(v) or v <= 0:
        raise ParameterError(name, value, what)
    return v


def _check_count(name: str, value: int, low: int, high: int, what: str) -> int:
    try:
        ok = int(value) == value
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok or not low <= int(value) <= high:
        raise ParameterError(name, value, what)
    return int(value)


@dataclass(frozen=True)
class Schedule:
    """The timing of one cycle: which picture is exposed on which frame, and when pictures are drawn."""

    period: float  # T, seconds
    fps: float  # N_FPS
    hold: int  # N_Dup, frames per picture ("on twos" = 2)
    n_frames: int  # N_Frame, frames per cycle
    n_pictures: int  # N_Pict, pictures per cycle
    k: int  # K, pictures held one frame less

    @property
    def dt(self) -> float:
        """Δt = T/N_Pict in seconds: the wave time between consecutive pictures."""
        return float(_decimal(self.period) / self.n_pictures)

    @cached_property
    def holds(self) -> NDArray[np.int64]:
        """``(N_Pict,)`` frames each picture is held: N_Dup for the first N_Pict − K, then N_Dup − 1."""
        h = np.full(self.n_pictures, self.hold, dtype=np.int64)
        if self.k:
            h[-self.k :] -= 1
        h.flags.writeable = False
        return h

    @cached_property
    def picture_times(self) -> NDArray[np.float64]:
        """``(N_Pict,)`` wave times t = i·Δt (seconds) at which the pictures are drawn."""
        t = np.array([float(_decimal(self.period) * i / self.n_pictures) for i in range(self.n_pictures)])
        t.flags.writeable = False
        return t

    @cached_property
    def exposure(self) -> NDArray[np.int64]:
        """``(N_Frame,)`` the picture shown on each frame of one cycle."""
        e = np.repeat(np.arange(self.n_pictures, dtype=np.int64), self.holds)
        e.flags.writeable = False
        return e

    @property
    def cycle_seconds(self) -> float:
        """N_Frame/N_FPS: the cycle's real length on screen (close to, not equal to, T)."""
        return self.n_frames / self.fps

    def shot_exposure(self, frames: int) -> NDArray[np.int64]:
        """``(frames,)`` the picture on each frame of a shot that repeats the cycle.

        Parameters
        ----------
        frames : int
            The shot's length in frames, 1 … ``MAX_SHOT_FRAMES``.

        Returns
        -------
        ndarray
            ``(frames,)`` int64 picture indices, the cycle's exposure repeated.
        """
        n = _check_count("frames", frames, 1, MAX_SHOT_FRAMES, f"a whole number in [1, {MAX_SHOT_FRAMES}]")
        return self.exposure[np.arange(n) % self.n_frames]

    def to_dict(self, frames: int | None = None) -> dict:
        """Plain JSON-ready numbers; ``exposure`` covers ``frames`` (default one cycle).

        Parameters
        ----------
        frames : int, optional
            The shot's length the exposure covers (None: one cycle).

        Returns
        -------
        dict
            Period, fps, hold, counts, picture times and the exposure, as plain numbers and lists.
        """
        exposure = self.exposure if frames is None else self.shot_exposure(frames)
        return {
            "period": self.period,
            "fps": self.fps,
            "hold": self.hold,
            "n_frames": self.n_frames,
            "n_pictures": self.n_pictures,
            "k": self.k,
            "dt": self.dt,
            "cycle_seconds": self.cycle_seconds,
            "holds": self.holds.tolist(),
            "picture_times": self.picture_times.tolist(),
            "shot_frames": int(exposure.size),
            "exposure": exposure.tolist(),
        }


def schedule(period: float, fps: float = 24.0, hold: int = 2) -> Schedule:
    """The limited-animation schedule of a cycle of ``period`` s at ``fps``, ``hold`` frames a picture.

    Refuses inputs for which the scheme breaks: a cycle shorter than half a frame (N_Frame = 0),
    and K > N_Pict, where the pictures cannot share the frames with holds of N_Dup and N_Dup − 1
    (e.g. a one-frame cycle on threes).

    Parameters
    ----------
    period
        T, the cycle's length in seconds, > 0.
    fps
        N_FPS, frames per second, > 0.
    hold
        N_Dup, frames each picture is held (2: on twos).

    Returns
    -------
    Schedule
        N_Frame = round(N_FPS·T) frames, N_Pict = ⌈N_Frame/N_Dup⌉ pictures drawn Δt = T/N_Pict
        apart, and each picture's hold: the first N_Pict − K held N_Dup frames, the last K held
        N_Dup − 1.

    Raises
    ------
    ParameterError
        A value is out of range, or the scheme breaks for these values.
    """
    period = _check_positive("period", period, "a positive, finite number of seconds")
    fps = _check_positive("fps", fps, "a positive, finite frame rate")
    hold = _check_count("hold", hold, 1, 1000, "a whole number of frames in [1, 1000] (2 = on twos)")
    n_frames = frames_per_cycle(period, fps)
    if n_frames == 0:
        raise ParameterError(
            "period",
            period,
            f"at least half a frame: {period:g} s at {fps:g} fps rounds to 0 frames per cycle",
        )
    if n_frames > MAX_CYCLE_FRAMES:
        raise ParameterError("period", period, f"at most {MAX_CYCLE_FRAMES} frames per cycle at {fps:g} fps")
    n_pictures = -(-n_frames // hold)  # N_Pict = ⌈N_Frame/N_Dup⌉
    k = hold * n_pictures - n_frames  # K = N_Dup·N_Pict − N_Frame
    if k > n_pictures:
        raise ParameterError(
            "hold",
            hold,
            f"a hold that fits the cycle: {n_frames} frame(s) per cycle make {n_pictures} picture(s) and "
            f"K = {k} > N_Pict, so holds of {hold} and {hold - 1} frames cannot fill the cycle; "
            "use a shorter hold or a longer period",
        )
    return Schedule(period=period, fps=fps, hold=hold, n_frames=n_frames, n_pictures=n_pictures, k=k)


def write_sheet(path: str | os.PathLike[str], sched: Schedule, frames: int | None = None) -> None:
    """Write the exposure sheet as CSV: ``frame, picture, time`` (time = frame/fps, seconds).

    ``frames`` is the shot length (default one cycle). Written atomically.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.
    sched : Schedule
        The cycle's schedule.
    frames : int, optional
        The shot's length (None: one cycle).
    """
    exposure = sched.exposure if frames is None else sched.shot_exposure(frames)
    with atomic_open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["frame", "picture", "time"])
        for i, pic in enumerate(exposure.tolist()):
            w.writerow([i, pic, repr(round(i / sched.fps, 9))])
