"""An artist's whole anime-cycle choice in one value, and the cycle it makes on a groom.

:class:`AnimeSettings` is what the studio's wave dock edits and the project file stores (the wave
of eq. (1), the timing "on twos", the per-bunch variation); :func:`cycle_for_groom` turns it into
the animation, optionally moving only a selection of strands; :func:`wave_curves` samples f(x, t)
at every picture for drawing.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.anime.schedule import Schedule, schedule
from hairtool.anime.wave import WaveParams, cycle_animation, wave
from hairtool.errors import ParameterError
from hairtool.groom import Animation, Groom, vertex_ids_of

CURVE_SAMPLES = 96  # points per drawn curve: smooth at dock sizes, cheap to redraw live


@dataclass(frozen=True)
class AnimeSettings:
    """Everything the dock edits: the wave, the timing and the per-bunch variation."""

    wave: WaveParams = field(default_factory=WaveParams)
    fps: float = 24.0
    hold: int = 2
    cycles: int = 2
    amplitude_spread: float = 0.1
    phase_spread: float = 0.25
    seed: int = 0

    def to_dict(self) -> dict:
        """Plain JSON (for the project file)."""
        d = dataclasses.asdict(self)
        d["wave"] = dataclasses.asdict(self.wave)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> AnimeSettings:
        """The inverse of :meth:`to_dict`; unknown keys are ParameterErrors naming them.

        Parameters
        ----------
        d : dict
            What :meth:`to_dict` wrote (a project's or a job's settings).

        Returns
        -------
        AnimeSettings
            The settings, checked.
        """
        d = dict(d)
        try:
            w = WaveParams(**dict(d.pop("wave", {})))
            return cls(wave=w, **d)
        except TypeError as e:
            raise ParameterError("anime settings", sorted(d), f"the fields of AnimeSettings ({e})") from None

    def variation(self) -> dict[str, Any]:
        return {
            "amplitude_spread": self.amplitude_spread,
            "phase_spread": self.phase_spread,
            "seed": self.seed,
        }


def wave_curves(settings: AnimeSettings, samples: int = CURVE_SAMPLES) -> tuple[Schedule, NDArray, NDArray]:
    """``(schedule, x (n,), y (N_Pict, n))``: f(x, t_i) of eq. (1) at every picture time t_i.

    Parameters
    ----------
    settings : AnimeSettings
        The wave and its timing.
    samples : int, default CURVE_SAMPLES
        Points along x in [0, π] (the strand from root to tip).

    Returns
    -------
    tuple of (Schedule, ndarray, ndarray)
        The schedule, ``x`` and ``y`` as above: what the studio's wave preview draws.
    """
    sched = schedule(settings.wave.period, settings.fps, settings.hold)
    x = np.linspace(0.0, np.pi, samples)
    y = wave(x[None, :], sched.picture_times[:, None], settings.wave)
    return sched, x, y


def cycle_for_groom(groom: Groom, settings: AnimeSettings, strand_ids: ArrayLike | None = None) -> Animation:
    """The groom waving for ``settings.cycles`` cycles; with ``strand_ids`` only those strands
    move (each is a bunch) and the others hold their pose, so the animation keeps every strand.

    Parameters
    ----------
    groom : Groom
        The rest pose.
    settings : AnimeSettings
        The wave, timing, cycle count and variation.
    strand_ids : array_like, optional
        The strands that move (None: every strand, grouped as :func:`make_bunches` does).

    Returns
    -------
    Animation
        ``settings.cycles`` cycles of held pictures at ``settings.fps``.
    """
    kwargs = dict(fps=settings.fps, hold=settings.hold, cycles=settings.cycles, **settings.variation())
    if strand_ids is None:
        return cycle_animation(groom, settings.wave, **kwargs)
    ids = np.unique(np.asarray(strand_ids, dtype=np.int64).reshape(-1))
    part = cycle_animation(groom.subset(ids), settings.wave, **kwargs)
    frames = np.repeat(groom.points[None], part.n_frames, axis=0)
    frames[:, vertex_ids_of(groom.topology, ids)] = part.frames
    return groom.animate(frames, part.fps)
