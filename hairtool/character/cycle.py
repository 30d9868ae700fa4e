"""The anime cycle (seed 001, eq. 1) on a character's hair chains: node rotations per drawing.

Each chain samples y = scale·f(x, t + phase·T) at its nodes (x = π × arc length / chain length
of the rest chain, as :mod:`hairtool.anime.wave` does for strands); segment j turns by
θ_j = atan2(Δy, Δx) about the chain's bend axis, fixed in the world. The paper's "apply the
node angles to the skeleton" then gives node j the local rotation that turns its world
rotation by θ_j: relative to its parent that is θ_j − θ_{j−1} about the axis. The tip node keeps
its rest rotation. Timing (N_Frame, N_Pict, holds) is :func:`hairtool.anime.schedule`'s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hairtool.anime.pose import wave_values
from hairtool.anime.schedule import Schedule, schedule
from hairtool.anime.wave import WaveParams
from hairtool.character.model import Chain, Character
from hairtool.errors import ParameterError
from hairtool.mocap import quaternion as quat

F64 = NDArray[np.float64]
UP = np.array([0.0, 1.0, 0.0])  # glTF's up


@dataclass(frozen=True)
class ChainWave:
    """One chain's variation: bend axis (world; None = chord × up), amplitude scale, phase (cycles), p."""

    axis: tuple[float, float, float] | None = None
    amplitude_scale: float = 1.0
    phase: float = 0.0
    profile: float | None = None  # p; None = the shared WaveParams' p


def world_rotations(character: Character, local: F64) -> F64:
    """``(..., J, 4)`` world rotations (wxyz) from local ones, parents first (scales ignored).

    Parameters
    ----------
    character : Character
        The character.
    local : ndarray
        ``(..., J, 4)`` wxyz.

    Returns
    -------
    ndarray
        ``(..., J, 4)`` float64.
    """
    nodes = character.nodes
    out = np.empty_like(local)
    for j in nodes.order.tolist():
        p = int(nodes.parents[j])
        out[..., j, :] = local[..., j, :] if p < 0 else quat.multiply(out[..., p, :], local[..., j, :])
    return out


def chain_points(character: Character, chain: Chain, world: F64 | None = None) -> F64:
    """``(..., N, 3)`` world positions of a chain's nodes (rest pose unless ``world`` matrices given).

    Parameters
    ----------
    character : Character
        The character.
    chain : Chain
        One of its hair chains.
    world : ndarray, optional
        ``(..., J, 4, 4)`` world matrices (None: the rest pose).

    Returns
    -------
    ndarray
        ``(..., N, 3)`` float64.
    """
    w = character.nodes.world() if world is None else world
    return np.take(w[..., :3, 3], list(chain.nodes), axis=-2)


def chain_axis(points: F64, wave: ChainWave) -> F64:
    """The unit axis a chain's wave bends about: ``wave.axis`` where given, else from the chain's chord.

    Parameters
    ----------
    points : ndarray
        ``(N, 3)`` the chain's rest positions.
    wave : ChainWave
        Its wave settings.

    Returns
    -------
    ndarray
        ``(3,)`` float64.
    """
    if wave.axis is not None:
        a = np.asarray(wave.axis, dtype=np.float64)
        if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) == 0:
            raise ParameterError("axis", wave.axis, "a non-zero, finite 3-vector")
        return a / np.linalg.norm(a)
    chord = points[-1] - points[0]
    a = np.cross(chord, UP)
    if np.linalg.norm(a) < 1e-6 * max(np.linalg.norm(chord), 1e-30):
        a = np.cross(chord, [1.0, 0.0, 0.0])  # a chain hanging straight down swings sideways
    return a / np.linalg.norm(a)


def segment_angles(points: F64, params: WaveParams, times: F64, wave: ChainWave) -> F64:
    """``(P, N−1)`` θ_j of each segment at each picture time (radians).

    Parameters
    ----------
    points : ndarray
        ``(N, 3)`` the chain's rest positions.
    params : WaveParams
        The wave.
    times : ndarray
        ``(P,)`` seconds.
    wave : ChainWave
        The chain's scale and phase.

    Returns
    -------
    ndarray
        ``(P, N−1)`` float64.
    """
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    x = np.pi * arc / arc[-1]
    p = params.profile if wave.profile is None else wave.profile
    if not np.isfinite(p) or p < 0:
        raise ParameterError("profile", p, "p ≥ 0")
    t = np.asarray(times, dtype=np.float64)[:, None] + wave.phase * params.period
    y = wave.amplitude_scale * wave_values(
        x[None, :], t, params.amplitude, params.wavelength, params.gravity, p, params.period
    )
    return np.arctan2(np.diff(y, axis=1), np.diff(x)[None, :])


def picture_rotations(
    character: Character,
    params: WaveParams,
    times: F64,
    waves: dict[int, ChainWave] | None = None,
) -> F64:
    """``(P, J, 4)`` local rotations (wxyz) of every node at each picture time; chains waved.

    ``waves`` maps a chain's index to its :class:`ChainWave` (default: each chain's own chord axis,
    scale 1, phase 0).

    Parameters
    ----------
    character : Character
        The character.
    params : WaveParams
        The wave.
    times : ndarray
        ``(P,)`` seconds.
    waves : dict of int to ChainWave, optional
        Per-chain settings.

    Returns
    -------
    ndarray
        ``(P, J, 4)`` float64.
    """
    rest = character.nodes.rotation
    rest_world = world_rotations(character, rest)
    out = np.broadcast_to(rest, (len(times), *rest.shape)).copy()
    for c, chain in enumerate(character.chains):
        wave = (waves or {}).get(c, ChainWave())
        pts = chain_points(character, chain)
        axis = chain_axis(pts, wave)
        theta = segment_angles(pts, params, np.asarray(times, dtype=np.float64), wave)  # (P, N−1)
        ids = list(chain.nodes)
        parent_world = np.broadcast_to(rest_world[int(character.nodes.parents[ids[0]])], (len(times), 4))
        if character.nodes.parents[ids[0]] < 0:
            parent_world = np.broadcast_to(quat.identity(), (len(times), 4))
        for k, j in enumerate(ids[:-1]):
            world = quat.multiply(quat.from_axis_angle(axis, theta[:, k]), rest_world[j])
            out[:, j] = quat.multiply(quat.conjugate(parent_world), world)
            parent_world = world
        tip = ids[-1]
        out[:, tip] = rest[tip]
    return out


@dataclass(frozen=True)
class CharacterCycle:
    """The schedule, the drawings' rotations ``(N_Pict, J, 4)``, and the frames that show them."""

    schedule: Schedule
    pictures: F64

    def frames(self, count: int | None = None) -> F64:
        """``(F, J, 4)`` local rotations on every frame: each drawing held as the sheet says.

        Parameters
        ----------
        count : int, optional
            Frames (None: one cycle).

        Returns
        -------
        ndarray
            ``(F, J, 4)`` float64.
        """
        exposure = self.schedule.exposure if count is None else self.schedule.shot_exposure(count)
        return self.pictures[exposure]


def character_cycle(
    character: Character,
    params: WaveParams | None = None,
    *,
    fps: float = 24.0,
    hold: int = 2,
    waves: dict[int, ChainWave] | None = None,
) -> CharacterCycle:
    """The limited-animation cycle of ``character``'s hair chains (the paper's Fig. 2 by default).

    Parameters
    ----------
    character : Character
        The character.
    params : WaveParams, optional
        The wave (None: the paper's Fig. 2).
    fps : float, default 24.0
        Frames per second.
    hold : int, default 2
        Frames each drawing is held.
    waves : dict of int to ChainWave, optional
        Per-chain settings.

    Returns
    -------
    CharacterCycle
        The schedule and the pictures' rotations.
    """
    if not character.chains:
        raise ParameterError("chains", 0, f"at least one hair chain in {character.path}")
    params = WaveParams() if params is None else params
    sched = schedule(params.period, fps, hold)
    return CharacterCycle(sched, picture_rotations(character, params, sched.picture_times, waves))
