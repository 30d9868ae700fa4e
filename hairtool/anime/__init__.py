"""Anime hair cycles (seed 001): a periodic wave f(x, t) on each hair bunch (eq. 1), timed the
way limited animation does it ("on twos"), applied as node rotations.

- :mod:`.wave` the wave, the bunches and the cycle animation;
- :mod:`.schedule` pictures, holds and the exposure sheet;
- :mod:`.pose` the node rotations (numba kernel and numpy twin);
- :mod:`.metrics` the paper's angular and positional errors against reference chains (Table 1);
- :mod:`.settings` an artist's whole choice as one value, and the cycle it makes on a groom.
"""

from hairtool.anime.schedule import Schedule, schedule
from hairtool.anime.settings import AnimeSettings, cycle_for_groom, wave_curves
from hairtool.anime.wave import WaveParams, cycle_animation, make_bunches, pose_pictures, wave

__all__ = [
    "AnimeSettings",
    "Schedule",
    "WaveParams",
    "cycle_animation",
    "cycle_for_groom",
    "make_bunches",
    "pose_pictures",
    "schedule",
    "wave",
    "wave_curves",
]
