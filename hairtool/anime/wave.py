"""Periodic anime hair motion (Furukawa & Nakata 2018): the wave of eq. (1) and the cycle it poses.

The shape of a hair line x ∈ [0, π] (root to tip) at time t is

    f(x, t) = −(a/s)·(x/π)^p·(cos(x/k − 2πt/T) + 1/s)                                  (1)

Each bunch chain is the wave's x axis at rest; at every picture time the curve is sampled at the
chain's nodes (x = π × arc length / chain length, y in the same units, so the curve keeps its
drawn aspect: y = 1 is a third of a chain length) and the angle of each sampled segment,
atan2(Δy, Δx), becomes the rotation of that rest segment about the bunch's bend axis. With the
paper's a = 0.8, s = 1.2, k = 1, p = 1 the segments turn between about +27° and −41° over a
cycle, and the tip of a horizontal chain rises 4 % and drops 34 % of the chain length: a lively
but readable wave that sags under its gravity term. Timing is in :mod:`hairtool.anime.schedule`, geometry in
:mod:`hairtool.anime.pose`, error measures in :mod:`hairtool.anime.metrics`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.anime.pose import (
    bend_axes,
    bunch_variation,
    check_guides,
    check_per_bunch,
    nearest_guide,
    pose_numba,
    pose_reference,
    wave_values,
    wave_x,
)
from hairtool.anime.schedule import Schedule, schedule
from hairtool.errors import ParameterError, finite_number
from hairtool.groom import Animation, Groom

F64 = NDArray[np.float64]
MAX_ANIMATION_BYTES = 4 * 1024**3


@dataclass(frozen=True)
class WaveParams:
    """The wave of eq. (1) in an animator's terms (defaults: the paper's Fig. 2, p = 1).

    amplitude (a): how far the hair line swings; the crest-to-trough height at the tip is 2a/s
        in units where the chain is π long. Any finite number; negative flips the wave.
    wavelength (k): spatial period of the wave, 2πk along a chain of length π: k = 1 is about
        half a wave along the bunch, smaller k puts more ripples on it. k > 0.
    gravity (s): weight of the hair: the line sags by a/s² on average and the swing shrinks as
        a/s; s ≠ 0 (negative s lifts the hair, as in an updraft).
    profile (p): how the swing grows from root to tip, (x/π)^p: 0 moves the whole bunch
        equally, 1 grows linearly, 2 keeps the root still and whips the tip. p ≥ 0.
    period (T): seconds per cycle of the motion. T > 0.
    """

    amplitude: float = 0.8  # a
    wavelength: float = 1.0  # k
    gravity: float = 1.2  # s
    profile: float = 1.0  # p
    period: float = 0.45  # T, seconds

    def __post_init__(self) -> None:
        a = finite_number("amplitude", self.amplitude)
        k = finite_number("wavelength", self.wavelength)
        s = finite_number("gravity", self.gravity)
        p = finite_number("profile", self.profile)
        t = finite_number("period", self.period)
        if k <= 0:
            raise ParameterError("wavelength", self.wavelength, "k > 0")
        if s == 0:
            raise ParameterError("gravity", self.gravity, "s ≠ 0")
        if p < 0:
            raise ParameterError("profile", self.profile, "p ≥ 0")
        if t <= 0:
            raise ParameterError("period", self.period, "T > 0 seconds")
        for name, v in (("amplitude", a), ("wavelength", k), ("gravity", s), ("profile", p), ("period", t)):
            object.__setattr__(self, name, v)


def wave(x: ArrayLike, t: ArrayLike, params: WaveParams) -> F64:
    """f(x, t) of eq. (1), broadcast over ``x`` (in [0, π], root to tip) and ``t`` (seconds).

    Parameters
    ----------
    x : array_like
        Positions along the chain, in [0, π].
    t : array_like
        Times in seconds.
    params : WaveParams
        The wave.

    Returns
    -------
    ndarray
        f(x, t), float64.
    """
    xa = np.asarray(x, dtype=np.float64)
    ta = np.asarray(t, dtype=np.float64)
    if not np.all(np.isfinite(xa)) or np.any(xa < 0.0) or np.any(xa > np.pi):
        raise ParameterError("x", "array" if xa.size > 4 else xa.tolist(), "finite values in [0, π]")
    if not np.all(np.isfinite(ta)):
        raise ParameterError("t", "array" if ta.size > 4 else ta.tolist(), "finite times in seconds")
    a, k, s, p, period = params.amplitude, params.wavelength, params.gravity, params.profile, params.period
    return wave_values(xa, ta, a, k, s, p, period)


def segment_angles(chains: Groom, y: ArrayLike) -> F64:
    """``(..., V−S)`` θ_j = atan2(Δy, Δx) of each sampled segment (x from :func:`wave_x`).

    ``y``: ``(..., V)`` wave values at the nodes. The relative rotation of node j is θ_j − θ_{j−1}
    (θ before the first segment is 0, the rest direction); bending by θ_j applies their sum.

    Parameters
    ----------
    chains : Groom
        The chains at rest.
    y : array_like
        ``(..., V)`` wave values.

    Returns
    -------
    ndarray
        ``(..., V−S)`` float64 radians.
    """
    end = chains.topology.segment_end
    x = wave_x(chains)
    ya = np.asarray(y, dtype=np.float64)
    return np.arctan2(ya[..., end] - ya[..., end - 1], x[end] - x[end - 1])


def node_rotations(chains: Groom, y: ArrayLike) -> F64:
    """``(..., V−S)`` the paper's per-node rotations relative to the parent: θ_j − θ_{j−1}.

    Parameters
    ----------
    chains : Groom
        The chains at rest.
    y : array_like
        ``(..., V)`` wave values.

    Returns
    -------
    ndarray
        ``(..., V−S)`` float64 radians.
    """
    theta = segment_angles(chains, y)
    first = np.zeros(chains.topology.segment_end.size, dtype=bool)
    first[chains.topology.root_indices - np.arange(chains.strand_count)] = True
    rel = np.diff(theta, axis=-1, prepend=0.0)
    return np.where(first, theta, rel)


@dataclass(frozen=True)
class Bunches:
    """How strands are grouped and varied: bunch of each strand, and per-bunch axis, scale, phase."""

    of_strand: NDArray[np.int64]  # (S,) bunch index of every strand
    axes: F64  # (B, 3) unit bend axes
    amplitude_scale: F64  # (B,)
    phase: F64  # (B,) in cycles (fractions of T)


def make_bunches(
    groom: Groom,
    *,
    guides: ArrayLike | None = None,
    sway: ArrayLike | None = None,
    amplitude_scale: ArrayLike | None = None,
    phase: ArrayLike | None = None,
    amplitude_spread: float = 0.1,
    phase_spread: float = 0.25,
    seed: int = 0,
) -> Bunches:
    """Group strands into bunches and give each its bend axis and variation.

    Without ``guides`` every strand is a bunch; with them each strand follows its nearest
    guide. ``amplitude_scale``/``phase`` (one value or one per bunch; phase in cycles) override
    the seeded draws of 1 ± ``amplitude_spread`` and [0, ``phase_spread``). Lock step: spreads 0.

    Parameters
    ----------
    groom : Groom
        The strands to group.
    guides : array_like, optional
        Indices of guide strands; each strand follows its nearest (None: every strand alone).
    sway : array_like, optional
        The direction the bunches bend in (None: each bunch's own, from its shape).
    amplitude_scale, phase : array_like, optional
        One value or one per bunch, overriding the seeded draws.
    amplitude_spread : float, default 0.1
        Each bunch's amplitude is 1 ± this, drawn from ``seed``.
    phase_spread : float, default 0.25
        Each bunch's phase offset is drawn from [0, this) cycles.
    seed : int, default 0
        The draws' seed: the same seed, the same bunches.

    Returns
    -------
    Bunches
        The bunch of every strand and each bunch's axis, scale and phase.
    """
    if guides is None:
        of_strand = np.arange(groom.strand_count, dtype=np.int64)
        chains = groom
    else:
        g = check_guides(groom, guides)
        of_strand = nearest_guide(groom, g)
        chains = groom.subset(g)
    n = chains.strand_count
    scale, ph = bunch_variation(n, amplitude_spread, phase_spread, seed)
    if amplitude_scale is not None:
        scale = check_per_bunch("amplitude_scale", amplitude_scale, n)
    if phase is not None:
        ph = check_per_bunch("phase", phase, n)
    axes = bend_axes(chains, sway, planar=groom.is_planar)
    return Bunches(of_strand=of_strand, axes=axes, amplitude_scale=scale, phase=ph)


def pose_pictures(
    groom: Groom,
    params: WaveParams,
    times: ArrayLike,
    bunches: Bunches | None = None,
    *,
    use_numba: bool = True,
) -> F64:
    """``(P, V, 3)`` float64 poses of the groom at wave times ``times`` (seconds), shape ``(P,)``.

    Each strand samples y = scale_b·f(x, t + phase_b·T) at its nodes; its segments turn by the
    sampled angles about its bunch's axis, so segment lengths are kept exactly.
    ``use_numba=False`` runs the plain numpy reference.

    Parameters
    ----------
    groom : Groom
        The rest pose.
    params : WaveParams
        The wave f of eq. (1).
    times : array_like
        ``(P,)`` wave times in seconds.
    bunches : Bunches, optional
        Grouping and variation (None: every strand a bunch, no variation).
    use_numba : bool, default True
        False runs the numpy twin (the tests' oracle).

    Returns
    -------
    ndarray
        ``(P, V, 3)`` float64 poses.
    """
    t = np.asarray(times, dtype=np.float64).reshape(-1)
    if t.size == 0 or not np.all(np.isfinite(t)):
        raise ParameterError("times", t.tolist()[:4], "at least one finite picture time")
    b = make_bunches(groom) if bunches is None else bunches
    if b.of_strand.shape != (groom.strand_count,):
        raise ParameterError(
            "bunches", b.of_strand.shape, f"one bunch index per strand ({groom.strand_count})"
        )
    per = b.of_strand
    wave_args = (params.amplitude, params.wavelength, params.gravity, params.profile, params.period)
    pose = pose_numba if use_numba else pose_reference
    return pose(groom, t, b.axes[per], b.amplitude_scale[per], b.phase[per] * params.period, wave_args)


def cycle_pictures(
    groom: Groom,
    params: WaveParams | None = None,
    *,
    fps: float = 24.0,
    hold: int = 2,
    bunches: Bunches | None = None,
    **variation: Any,
) -> tuple[Schedule, list[Groom]]:
    """The schedule and its N_Pict picture poses as grooms, for still frames and drawings.

    ``bunches`` (from :func:`make_bunches`) or the keywords of :func:`make_bunches` (guides,
    sway, amplitude_scale, phase, amplitude_spread, phase_spread, seed) set the variation.

    Parameters
    ----------
    groom : Groom
        The rest pose.
    params : WaveParams, optional
        The wave (None: the defaults).
    fps : float, default 24.0
        Frames per second.
    hold : int, default 2
        Frames each picture is held.
    bunches : Bunches, optional
        Grouping and variation.
    **variation
        :func:`make_bunches`'s keywords, where ``bunches`` is not given.

    Returns
    -------
    tuple of (Schedule, list of Groom)
        The schedule and one groom per picture.
    """
    params = WaveParams() if params is None else params
    sched = schedule(params.period, fps, hold)
    b = make_bunches(groom, **variation) if bunches is None else bunches
    poses = pose_pictures(groom, params, sched.picture_times, b)
    return sched, [groom.with_points(p) for p in poses]


def cycle_animation(
    groom: Groom,
    params: WaveParams | None = None,
    *,
    fps: float = 24.0,
    hold: int = 2,
    cycles: int = 1,
    frames: int | None = None,
    bunches: Bunches | None = None,
    **variation: Any,
) -> Animation:
    """The groom waving in limited animation: ``cycles`` × N_Frame frames (or ``frames``) at ``fps``.

    Every frame shows the picture the exposure sheet names, so pictures are held on twos, threes…
    ``bunches`` (from :func:`make_bunches`) or the keywords of :func:`make_bunches` (guides,
    sway, amplitude_scale, phase, amplitude_spread, phase_spread, seed) set the per-bunch
    variation; by default every strand is a bunch with a seeded phase and amplitude. The
    groom's attributes (thickness, colours) and source record (up axis, unit, prims) are kept,
    and "up" is the scene's.

    Parameters
    ----------
    groom
        The rest pose; its strands are the chains the wave bends.
    params
        The wave f(x, t) of eq. 1 and its period T; None: the defaults of :class:`WaveParams`.
    fps
        N_FPS, frames per second.
    hold
        N_Dup, frames each picture is held (2: on twos).
    cycles
        How many cycles the shot repeats.
    frames
        The shot's length in frames, instead of ``cycles``.
    bunches
        The strands grouped into bunches with their phase and amplitude.
    **variation
        Keywords of :func:`make_bunches`, when ``bunches`` is None.

    Returns
    -------
    Animation
        The frames at ``fps``, the first of them the first picture.

    Raises
    ------
    ParameterError
        A value is out of range, the schedule breaks for these values, or the animation would
        be too large; the message names the parameter.
    """
    params = WaveParams() if params is None else params
    sched = schedule(params.period, fps, hold)
    if frames is None:
        if int(cycles) != cycles or cycles < 1:
            raise ParameterError("cycles", cycles, "a whole number ≥ 1")
        frames = int(cycles) * sched.n_frames
    exposure = sched.shot_exposure(frames)
    if exposure.size * groom.vertex_count * 12 > MAX_ANIMATION_BYTES:
        raise ParameterError(
            "frames", frames, f"at most {MAX_ANIMATION_BYTES // (groom.vertex_count * 12)} for this groom"
        )
    b = make_bunches(groom, **variation) if bunches is None else bunches
    pictures = pose_pictures(groom, params, sched.picture_times, b).astype(np.float32)
    return groom.animate(pictures[exposure], sched.fps)
