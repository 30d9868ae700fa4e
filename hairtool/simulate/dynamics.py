"""Strand dynamics: inextensible strands on a moving head, by dynamic follow-the-leader (DFTL).

Müller, Kim & Chentanez 2012, "Fast simulation of inextensible hair and fur": each substep
predicts positions from velocities and forces, then walks every strand from root to tip and
puts vertex i back at its rest distance L_i from vertex i−1 (the leader); the correction
d_{i+1} applied to the next vertex is fed back into the velocity of vertex i (their eq. 9):
    v_i = (p_i − x_i)/Δt − s_damping · d_{i+1}/Δt.
Roots follow the head rigidly (or an animated groom's own roots, :mod:`hairtool.simulate.driver`).
A light stiffness pulls every vertex toward its rest position
carried by the head (shape matching in the head frame), so a groom keeps its style. (The other
reading, a pull toward each segment's rest direction from its leader, trades energy with the
DFTL velocity correction: still strands then oscillate by themselves. The pull toward a
head-frame target is a plain damped spring and stays still.)
Gravity acts relative to the rest pose (a styled groom is in equilibrium at frame 0): the
effective pull is g − R(t)·R(0)ᵀ·g, so tilting the head lets the hair fall while a still head
leaves it exactly at rest.

Units and axes: the groom's own (its :class:`~hairtool.metadata.Metadata`). Gravity is given in
m/s² and pulls along the stage's −up at g / metersPerUnit scene units/s², so a Z-up metre groom
and the same groom in Y-up centimetres fall alike; wind and gusts are in scene units/s², gusts
blow across the up axis, and the named head motions turn about the scene's up and lateral axes
(:mod:`hairtool.simulate.head_motion`). The result carries the groom's record
(:meth:`~hairtool.groom.Groom.animate`): written back, it lands on the prims it came from.
Every strand is independent, so the numba kernel runs strands in parallel and its result does
not depend on the thread count; :func:`simulate_reference` runs the same steps in numpy.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.groom import Animation, Groom
from hairtool.simulate.driver import RootDriver
from hairtool.simulate.head_motion import check_transform, head_motion

F64 = NDArray[np.float64]

#: Earth's gravity in m/s² (converted to scene units by the groom's metres per unit).
GRAVITY = 9.81


@dataclass(frozen=True)
class Gust:
    """A burst of wind: acceleration ``strength`` · sin²(π (t − start)/duration) along ``direction``."""

    start: float
    duration: float
    direction: tuple[float, float, float]
    strength: float

    def envelope(self, times: ArrayLike) -> F64:
        """sin²(π (t − start)/duration) inside the gust, 0 outside; ``times`` in seconds.

        Parameters
        ----------
        times : array_like
            Times in seconds.

        Returns
        -------
        ndarray
            The envelope at each time, in [0, 1].
        """
        u = (np.asarray(times, dtype=np.float64) - self.start) / self.duration
        return np.where((u > 0.0) & (u < 1.0), np.sin(np.pi * u) ** 2, 0.0)


def gust_schedule(
    count: int,
    clip_duration: float,
    strength: float,
    duration: float,
    seed: int,
    frame: ArrayLike | None = None,
) -> list[Gust]:
    """``count`` seeded gusts with horizontal directions, starting after the first tenth of the clip.

    ``frame``: the scene's axes (:attr:`hairtool.metadata.Metadata.frame`; default Y-up), so
    "horizontal" is across the stage's up axis.

    Parameters
    ----------
    count : int
        Gusts, ≥ 0.
    clip_duration : float
        The clip's length in seconds.
    strength : float
        Each gust's strength in units/s².
    duration : float
        Each gust's length in seconds.
    seed : int
        The draws' seed.
    frame : array_like, optional
        ``(3, 3)`` the scene's axes (None: Y-up).

    Returns
    -------
    list of Gust
        The gusts, by start time.
    """
    if int(count) != count or not 0 <= count <= 10_000:
        raise ParameterError("gusts", count, "a whole number in [0, 10000]")
    if not (np.isfinite(strength) and strength >= 0):
        raise ParameterError("gust_strength", strength, "a finite number ≥ 0 (units/s²)")
    if not (np.isfinite(duration) and duration > 0):
        raise ParameterError("gust_duration", duration, "a positive number of seconds")
    rng = np.random.default_rng(seed)
    latest = max(clip_duration - duration, 0.1 * clip_duration)
    starts = np.sort(rng.uniform(0.1 * clip_duration, latest, int(count)))
    angles = rng.uniform(0.0, 2.0 * np.pi, int(count))
    scale = rng.uniform(0.75, 1.25, int(count))
    axes = np.eye(3) if frame is None else np.asarray(frame, dtype=np.float64)
    directions = np.column_stack([np.cos(angles), np.zeros(len(angles)), np.sin(angles)]) @ axes.T
    return [
        Gust(float(s), float(duration), tuple(float(v) for v in d), float(strength * k))
        for s, d, k in zip(starts, directions, scale, strict=True)
    ]


# ---------------------------------------------------------------------------------------
# Parameters
# ---------------------------------------------------------------------------------------
def scaled_accelerations(factor: float, gust_strength: float, wind: ArrayLike = (0.0, 0.0, 0.0)) -> dict:
    """Gust strength and the wind vector (units/s²) for a head ``factor`` times larger: they
    scale with the head, so hair on the larger head moves as it did on the smaller one (gravity
    is physical, in m/s², and needs no scaling). The keyword arguments of :func:`simulate` (the
    wind as a vector) that change with scale.

    Parameters
    ----------
    factor : float
        The new head radius over the old.
    gust_strength : float
        The gusts' strength before.
    wind : array_like, default (0, 0, 0)
        The wind vector before.

    Returns
    -------
    dict
        ``gust_strength`` and ``wind`` scaled.
    """
    return {
        "gust_strength": float(gust_strength) * factor,
        "wind": tuple(float(v) * factor for v in np.asarray(wind, dtype=np.float64).reshape(3)),
    }


def _vector(name: str, value: ArrayLike) -> F64:
    a = np.asarray(value, dtype=np.float64)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ParameterError(name, value, "three finite numbers")
    return a


def _number(name: str, value: float, lo: float, hi: float, expected: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, expected) from None
    if not (np.isfinite(v) and lo <= v <= hi):
        raise ParameterError(name, value, expected)
    return v


def _whole(name: str, value: int, lo: int, hi: int) -> int:
    if isinstance(value, bool) or int(value) != value or not lo <= value <= hi:
        raise ParameterError(name, value, f"a whole number in [{lo}, {hi}]")
    return int(value)


@dataclass(frozen=True)
class _Setup:
    rest: F64  # (V, 3) rest points in the head frame
    seg_len: F64  # (V,) rest length of the segment ending at each vertex (0 at roots)
    coll_r: F64  # (V,) collision radius per vertex (0 disables)
    centre: F64  # head-sphere centre in the head frame
    offsets: NDArray[np.int64]


def _schedule(transform: Callable[[float], F64], frames: int, fps: float, substeps: int):
    """Head transforms at every substep time after frame 0: rotations (K, 3, 3), translations (K, 3)."""
    dt = 1.0 / (fps * substeps)
    times = dt * np.arange(1, (frames - 1) * substeps + 1)
    mats = np.stack([check_transform(transform(float(t)), float(t)) for t in times]) if len(times) else None
    m0 = check_transform(transform(0.0), 0.0)
    return times, mats, m0


def _accelerations(times: F64, rotations: F64, r0: F64, g: F64, wind: F64, gusts: list[Gust]) -> F64:
    """(K, 3) external acceleration per substep: relative gravity (``g``, a vector in units/s²)
    + wind + gusts."""
    g_head = r0.T @ g
    acc = g[None, :] - rotations @ g_head + wind[None, :]
    for gust in gusts:
        acc += gust.strength * gust.envelope(times)[:, None] * np.asarray(gust.direction)[None, :]
    return acc


def simulate(
    groom: Groom,
    *,
    motion: str | Sequence[str] | Callable[[float], ArrayLike] = "still",
    frames: int = 120,
    fps: float = 24.0,
    substeps: int = 8,
    gravity: float = GRAVITY,
    damping: float = 2.0,
    stiffness: float = 0.05,
    ftl_damping: float = 0.9,
    wind: tuple[ArrayLike, float] | None = None,
    gusts: int | Sequence[Gust] = 0,
    gust_strength: float = 300.0,
    gust_duration: float = 0.25,
    collide: bool = True,
    head_center: ArrayLike = (0.0, 0.0, 0.0),
    head_radius: float = 1.0,
    seed: int = 0,
    backend: str = "numba",
    progress: Callable[[int, int], object] | None = None,
    driver: RootDriver | None = None,
) -> Animation:
    """Simulate ``groom`` (its pose at time 0) on a moving head; returns ``frames`` frames at ``fps``.

    Parameters
    ----------
    groom : Groom
        The hair at rest, posed at t = 0.
    motion : str, sequence of str or callable, default "still"
        Names from :mod:`hairtool.simulate.head_motion` ("turn,nod" plays them in equal slots),
        placed on the head sphere, or a callable t (s) → rigid 4×4 head transform (world from
        head).
    frames : int, default 120
        Frames to make, 1 … 1,000,000.
    fps : float, default 24.0
        Frames per second.
    substeps : int, default 8
        Solver steps per frame.
    gravity : float, default GRAVITY
        m/s² along the stage's −up (the groom's up axis): g / metersPerUnit in scene units/s².
    damping : float, default 2.0
        Velocity decay per second (v ← v·e^(−damping·Δt)).
    stiffness : float, default 0.05
        Share of each vertex's distance from its rest position in the head frame removed per
        frame.
    ftl_damping : float, default 0.9
        s_damping of Müller et al. eq. 9.
    wind : tuple of (array_like, float), optional
        A constant wind: direction and strength in units/s².
    gusts : int or sequence of Gust, default 0
        A count of seeded gusts (:func:`gust_schedule`) or explicit :class:`Gust` objects.
    gust_strength : float, default 300.0
        A seeded gust's strength in units/s².
    gust_duration : float, default 0.25
        A seeded gust's length in seconds.
    collide : bool, default True
        Keep vertices outside the head sphere (moving with the head); a vertex whose rest pose
        is closer to the centre than the radius is held at that distance.
    head_center : array_like, default (0, 0, 0)
        The head sphere's centre at t = 0 (:func:`~hairtool.simulate.head_motion.fit_head`
        finds one for a real groom).
    head_radius : float, default 1.0
        Its radius.
    seed : int, default 0
        The seed of the gusts: the same seed, the same bytes.
    backend : {"numba", "numpy"}, default "numba"
        The kernel, or its numpy twin (the tests' oracle).
    progress : callable, optional
        ``progress(done, frames)`` after every frame; an exception raised from it stops the
        simulation (how a studio cancels).
    driver : RootDriver, optional
        An animated groom's own root motion (:class:`~hairtool.simulate.driver.RootDriver` of
        the same strands): the roots follow it exactly and the head moves with its rigid fit;
        it replaces ``motion``.

    Returns
    -------
    Animation
        ``frames`` frames of the groom's strands at ``fps``.
    """
    frames = _whole("frames", frames, 1, 1_000_000)
    substeps = _whole("substeps", substeps, 1, 1000)
    fps = _number("fps", fps, 1e-3, 1e5, "a positive frame rate up to 100000")
    gravity = _number("gravity", gravity, -1e4, 1e4, "an acceleration in m/s² within ±10000")
    damping = _number("damping", damping, 0.0, 1e4, "a decay rate in [0, 10000] per second")
    stiffness = _number("stiffness", stiffness, 0.0, 1.0, "a fraction in [0, 1]")
    ftl_damping = _number("ftl_damping", ftl_damping, 0.0, 1.0, "a number in [0, 1]")
    head_radius = _number("head_radius", head_radius, 0.0, 1e9, "a radius ≥ 0")
    centre_world = _vector("head_center", head_center)
    if backend not in ("numba", "numpy"):
        raise ParameterError("backend", backend, "'numba' or 'numpy'")
    if not isinstance(groom, Groom):
        raise ParameterError("groom", type(groom).__name__, "a Groom")
    if frames * groom.vertex_count * 12 > 8 * 2**30:
        raise ParameterError("frames", frames, "an animation under 8 GiB (frames × vertices × 12 bytes)")
    wind_acc = np.zeros(3)
    if wind is not None:
        try:
            direction, strength = wind
        except (TypeError, ValueError):
            raise ParameterError("wind", wind, "(direction, strength)") from None
        d = _vector("wind direction", direction)
        strength = _number("wind strength", strength, 0.0, 1e6, "a number in [0, 1e6] units/s²")
        if strength > 0:
            n = np.linalg.norm(d)
            if n == 0:
                raise ParameterError("wind direction", direction, "a non-zero vector")
            wind_acc = strength * d / n
    duration = (frames - 1) / fps
    if isinstance(gusts, (int, np.integer)) and not isinstance(gusts, bool):
        clip = max(duration, 1.0 / fps)
        gust_list = gust_schedule(int(gusts), clip, gust_strength, gust_duration, seed, groom.metadata.frame)
    else:
        gust_list = list(gusts)
        for g in gust_list:
            if not isinstance(g, Gust):
                raise ParameterError("gusts", gusts, "a count or a list of Gust")
            _vector("gust direction", g.direction)
            _number("gust duration", g.duration, 1e-9, 1e9, "a positive number of seconds")
            _number("gust strength", g.strength, -1e6, 1e6, "a finite acceleration in units/s²")
            _number("gust start", g.start, -1e9, 1e9, "a finite time in seconds")

    if driver is not None:
        if driver.strand_count != groom.strand_count:
            raise ParameterError("driver", f"{driver.strand_count} roots", f"{groom.strand_count} roots")
        transform = driver.transform
    elif callable(motion):
        transform = motion
    else:
        scale = head_radius if head_radius > 0 else 1.0  # the named motions sized to the head
        transform = head_motion(motion, max(duration, 1.0 / fps), centre_world, scale, groom.metadata.frame)
    times, mats, m0 = _schedule(transform, frames, fps, substeps)

    # Rest pose in the head frame.
    inv0 = np.linalg.inv(m0)
    pts = groom.points.astype(np.float64)
    rest = pts @ inv0[:3, :3].T + inv0[:3, 3]
    centre = inv0[:3, :3] @ centre_world + inv0[:3, 3]
    seg_len = np.zeros(groom.vertex_count)
    seg_len[groom.topology.segment_end] = groom.segment_lengths
    dist = np.linalg.norm(rest - centre, axis=1)
    coll_r = np.minimum(head_radius, dist) if collide else np.zeros(groom.vertex_count)
    coll_r[groom.topology.root_indices] = 0.0
    setup = _Setup(rest, seg_len, coll_r, centre, groom.offsets)

    out = np.empty((frames, groom.vertex_count, 3), dtype=np.float32)
    x = pts.copy()
    out[0] = groom.points
    if frames > 1:
        rot = np.ascontiguousarray(mats[:, :3, :3])
        trans = np.ascontiguousarray(mats[:, :3, 3])
        g = -gravity * groom.metadata.units_per_meter * groom.metadata.up
        acc = _accelerations(times, rot, m0[:3, :3], g, wind_acc, gust_list)
        dt = 1.0 / (fps * substeps)
        bend = 1.0 - (1.0 - stiffness) ** (1.0 / substeps)
        decay = float(np.exp(-damping * dt))
        v = np.zeros_like(x)
        step = _frame_kernel if backend == "numba" else _frame_reference
        held = np.zeros((1, 1, 3))  # (no driver: the roots are the rest roots carried by the head)
        for f in range(1, frames):
            k = slice((f - 1) * substeps, f * substeps)
            if driver is not None:
                held = np.ascontiguousarray(np.stack([driver.at(float(t)) for t in times[k]]))
            step(
                x,
                v,
                setup.rest,
                setup.offsets,
                setup.seg_len,
                setup.coll_r,
                setup.centre,
                rot[k],
                trans[k],
                acc[k],
                dt,
                bend,
                ftl_damping,
                decay,
                held,
                driver is not None,
            )
            out[f] = x
            if progress is not None:
                progress(f + 1, frames)
    return groom.animate(out, fps)


def simulate_reference(groom: Groom, **kwargs) -> Animation:
    """:func:`simulate` with the numpy twin of the kernel (slow; the test oracle).

    Parameters
    ----------
    groom : Groom
        The hair at rest.
    **kwargs
        :func:`simulate`'s keywords, ``backend`` aside.

    Returns
    -------
    Animation
        What :func:`simulate` gives, computed by the numpy twin.
    """
    return simulate(groom, backend="numpy", **kwargs)


# ---------------------------------------------------------------------------------------
# One frame of substeps: numba kernel and numpy twin
# ---------------------------------------------------------------------------------------
@njit(cache=True, nogil=True, parallel=True)
def _frame_kernel(
    x, v, rest, offsets, seg_len, coll_r, centre, rot, trans, acc, dt, bend, ftl_damping, decay, held, driven
):
    """Advance positions ``x`` and velocities ``v`` (V, 3) in place through len(rot) substeps;
    ``driven``: the roots at substep k are ``held[k]`` (S, 3), else the rest roots carried by the head."""
    n_strands = offsets.size - 1
    for s in prange(n_strands):
        a = offsets[s]
        n = offsets[s + 1] - a
        p = np.empty((n, 3))
        d = np.zeros((n + 1, 3))
        for k in range(rot.shape[0]):
            r = rot[k]
            cw0 = r[0, 0] * centre[0] + r[0, 1] * centre[1] + r[0, 2] * centre[2] + trans[k, 0]
            cw1 = r[1, 0] * centre[0] + r[1, 1] * centre[1] + r[1, 2] * centre[2] + trans[k, 1]
            cw2 = r[2, 0] * centre[0] + r[2, 1] * centre[1] + r[2, 2] * centre[2] + trans[k, 2]
            for c in range(3):
                if driven:
                    p[0, c] = held[k, s, c]
                else:
                    p[0, c] = r[c, 0] * rest[a, 0] + r[c, 1] * rest[a, 1] + r[c, 2] * rest[a, 2] + trans[k, c]
            for i in range(1, n):
                for c in range(3):
                    v[a + i, c] += dt * acc[k, c]
                    p[i, c] = x[a + i, c] + dt * v[a + i, c]
            for i in range(1, n):
                # Style: pull toward the rest pose carried by the head (shape matching in the head frame).
                for c in range(3):
                    tc = r[c, 0] * rest[a + i, 0] + r[c, 1] * rest[a + i, 1] + r[c, 2] * rest[a + i, 2]
                    p[i, c] += bend * (tc + trans[k, c] - p[i, c])
                # Head sphere: push the vertex out to its collision radius.
                rad = coll_r[a + i]
                if rad > 0.0:
                    dx = p[i, 0] - cw0
                    dy = p[i, 1] - cw1
                    dz = p[i, 2] - cw2
                    dist = np.sqrt(dx * dx + dy * dy + dz * dz)
                    if 1e-12 < dist < rad:
                        f = rad / dist
                        p[i, 0] = cw0 + dx * f
                        p[i, 1] = cw1 + dy * f
                        p[i, 2] = cw2 + dz * f
                # Follow the leader: back to the rest length from vertex i − 1.
                ex = p[i, 0] - p[i - 1, 0]
                ey = p[i, 1] - p[i - 1, 1]
                ez = p[i, 2] - p[i - 1, 2]
                length = np.sqrt(ex * ex + ey * ey + ez * ez)
                if length > 1e-12:
                    f = seg_len[a + i] / length
                    qx, qy, qz = p[i - 1, 0] + ex * f, p[i - 1, 1] + ey * f, p[i - 1, 2] + ez * f
                else:  # coincident with the leader: use the rest segment turned with the head
                    u0 = rest[a + i, 0] - rest[a + i - 1, 0]
                    u1 = rest[a + i, 1] - rest[a + i - 1, 1]
                    u2 = rest[a + i, 2] - rest[a + i - 1, 2]
                    rs0 = r[0, 0] * u0 + r[0, 1] * u1 + r[0, 2] * u2
                    rs1 = r[1, 0] * u0 + r[1, 1] * u1 + r[1, 2] * u2
                    rs2 = r[2, 0] * u0 + r[2, 1] * u1 + r[2, 2] * u2
                    rl = np.sqrt(rs0 * rs0 + rs1 * rs1 + rs2 * rs2)
                    f = seg_len[a + i] / rl if rl > 0.0 else 0.0
                    qx, qy, qz = p[i - 1, 0] + rs0 * f, p[i - 1, 1] + rs1 * f, p[i - 1, 2] + rs2 * f
                d[i, 0], d[i, 1], d[i, 2] = qx - p[i, 0], qy - p[i, 1], qz - p[i, 2]
                p[i, 0], p[i, 1], p[i, 2] = qx, qy, qz
            # Velocities with the DFTL correction (Müller et al. 2012, eq. 9).
            for i in range(1, n):
                for c in range(3):
                    v[a + i, c] = ((p[i, c] - x[a + i, c]) - ftl_damping * d[i + 1, c]) / dt * decay
                    x[a + i, c] = p[i, c]
            for c in range(3):
                x[a, c] = p[0, c]
                v[a, c] = 0.0


def _frame_reference(
    x, v, rest, offsets, seg_len, coll_r, centre, rot, trans, acc, dt, bend, ftl_damping, decay, held, driven
):
    """The numpy twin of :func:`_frame_kernel`: vectorised over strands, one vertex index at a time."""
    counts = np.diff(offsets)
    roots = offsets[:-1]
    free = np.ones(len(x), dtype=bool)
    free[roots] = False
    for k in range(len(rot)):
        r, t = rot[k], trans[k]
        cw = r @ centre + t
        p = x.copy()
        p[roots] = held[k] if driven else rest[roots] @ r.T + t
        v[free] += dt * acc[k]
        p[free] = x[free] + dt * v[free]
        d = np.zeros_like(x)
        for i in range(1, int(counts.max())):
            idx = roots[counts > i] + i
            rs = (rest[idx] - rest[idx - 1]) @ r.T
            p[idx] += bend * (rest[idx] @ r.T + t - p[idx])
            rad = coll_r[idx]
            off = p[idx] - cw
            dist = np.linalg.norm(off, axis=1)
            hit = (rad > 0.0) & (dist > 1e-12) & (dist < rad)
            p[idx[hit]] = cw + off[hit] * (rad[hit] / dist[hit])[:, None]
            e = p[idx] - p[idx - 1]
            length = np.linalg.norm(e, axis=1)
            ok = length > 1e-12
            rl = np.linalg.norm(rs, axis=1)
            direction = np.where(ok[:, None], e, rs)
            scale = np.where(
                ok, seg_len[idx] / np.where(ok, length, 1.0), seg_len[idx] / np.where(rl > 0, rl, 1.0)
            )
            scale = np.where(ok | (rl > 0), scale, 0.0)
            q = p[idx - 1] + direction * scale[:, None]
            d[idx] = q - p[idx]
            p[idx] = q
        # d of the vertex after each one; tips have none.
        d_next = np.zeros_like(x)
        d_next[:-1] = d[1:]
        d_next[offsets[1:] - 1] = 0.0
        v[free] = ((p[free] - x[free]) - ftl_damping * d_next[free]) / dt * decay
        v[roots] = 0.0
        x[:] = p
