"""Procedural head motions for the strand simulator: a rigid 4×4 transform per time in seconds.

Motions are written for the head of :mod:`hairtool.samples` (radius 1 at the origin, y up) and
placed on any other head sphere by :func:`head_motion`'s ``centre`` and ``radius``, which
:func:`fit_head` finds from a groom's roots, and in any scene's axes by its ``frame``
(:attr:`hairtool.metadata.Metadata.frame`): a turn or a shake is about the stage's up axis, a
nod about its lateral (x) axis, a hop along up, whatever the up axis. Each named motion
starts and ends at the rest pose, so motions chain ("turn,nod") without jumps; all but "hop"
also start and end at rest velocity. "hop" takes off and lands abruptly: a short event that
good key frames must not miss.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.rotation import axis_angle_matrix

F64 = NDArray[np.float64]
HeadMotion = Callable[[float], F64]

#: The neck pivot the head turns and nods about (below the centre of the unit head).
PIVOT = np.array([0.0, -1.0, 0.0])


def _about_pivot(axis: Sequence[float], angle: float) -> F64:
    m = np.eye(4)
    r = axis_angle_matrix(np.asarray(axis, dtype=np.float64), angle)
    m[:3, :3] = r
    m[:3, 3] = PIVOT - r @ PIVOT
    return m


def _window(u: float) -> float:
    """sin²(πu): 0 with zero slope at both ends of the slot."""
    return float(np.sin(np.pi * u) ** 2)


def still(u: float) -> F64:
    """No motion: the rest pose throughout.

    Parameters
    ----------
    u : float
        The share of the motion's slot, in [0, 1].

    Returns
    -------
    ndarray
        ``(4, 4)`` the identity.
    """
    return np.eye(4)


def turn(u: float) -> F64:
    """Look left then right (yaw about +y, up to about ±55°).

    Parameters
    ----------
    u : float
        The share of the motion's slot, in [0, 1].

    Returns
    -------
    ndarray
        ``(4, 4)`` float64 rigid transform of the unit head.
    """
    return _about_pivot((0.0, 1.0, 0.0), np.radians(70.0) * np.sin(2 * np.pi * u) * _window(u))


def nod(u: float) -> F64:
    """Nod down then up (pitch about +x, up to about ±30°).

    Parameters
    ----------
    u : float
        The share of the motion's slot, in [0, 1].

    Returns
    -------
    ndarray
        ``(4, 4)`` float64 rigid transform of the unit head.
    """
    return _about_pivot((1.0, 0.0, 0.0), np.radians(40.0) * np.sin(2 * np.pi * u) * _window(u))


def shake(u: float) -> F64:
    """Three quick shakes of the head (yaw, up to ±30°).

    Parameters
    ----------
    u : float
        The share of the motion's slot, in [0, 1].

    Returns
    -------
    ndarray
        ``(4, 4)`` float64 rigid transform of the unit head.
    """
    return _about_pivot((0.0, 1.0, 0.0), np.radians(30.0) * np.sin(6 * np.pi * u) * _window(u))


def hop(u: float) -> F64:
    """Stand, jump (0.6 head radii high, airborne for the middle 60 % of the slot), land and stop.

    Parameters
    ----------
    u : float
        The share of the motion's slot, in [0, 1].

    Returns
    -------
    ndarray
        ``(4, 4)`` float64 rigid transform of the unit head.
    """
    m = np.eye(4)
    if 0.2 < u < 0.8:
        s = (u - 0.2) / 0.6
        m[1, 3] = 0.6 * 4.0 * s * (1.0 - s)
    return m


MOTIONS: dict[str, Callable[[float], F64]] = {
    "still": still,
    "turn": turn,
    "nod": nod,
    "shake": shake,
    "hop": hop,
}


def parse_motion(spec: str | Sequence[str]) -> list[str]:
    """ "turn,nod" or ["turn", "nod"] → the checked list of names.

    Parameters
    ----------
    spec : str or sequence of str
        Comma-separated names, or a list of them.

    Returns
    -------
    list of str
        The names, each one :mod:`hairtool.simulate.head_motion` knows (ParameterError otherwise).
    """
    names = [s.strip() for s in spec.split(",")] if isinstance(spec, str) else [str(s).strip() for s in spec]
    if not names or any(n not in MOTIONS for n in names):
        raise ParameterError("motion", spec, f"names from {', '.join(MOTIONS)}, comma-separated")
    return names


def head_motion(
    spec: str | Sequence[str],
    duration: float,
    centre: ArrayLike = (0.0, 0.0, 0.0),
    radius: float = 1.0,
    frame: ArrayLike | None = None,
) -> HeadMotion:
    """A callable t (seconds) → 4×4: the named motions play one after another, equal slots over
    ``duration``; times outside [0, duration] hold the rest pose.

    ``centre`` and ``radius`` place the unit head's motions on another head: the neck pivot
    sits at ``centre + radius·PIVOT`` and a hop rises 0.6·``radius``; angles stay the same.
    ``frame``: the scene's axes as columns (lateral, up, front; default the identity, Y-up):
    each motion M of the reference head becomes frame·M·frameᵀ.

    Parameters
    ----------
    spec : str or sequence of str
        Motion names (:func:`parse_motion`).
    duration : float
        Seconds the motions share.
    centre : array_like, default (0, 0, 0)
        The head's centre.
    radius : float, default 1.0
        The head's radius.
    frame : array_like, optional
        ``(3, 3)`` the scene's axes (None: Y-up).

    Returns
    -------
    HeadMotion
        t → ``(4, 4)``.
    """
    names = parse_motion(spec)
    if not (np.isfinite(duration) and duration > 0):
        raise ParameterError("duration", duration, "a positive number of seconds")
    c = np.asarray(centre, dtype=np.float64)
    if c.shape != (3,) or not np.all(np.isfinite(c)):
        raise ParameterError("head centre", centre, "three finite numbers")
    if not (np.isfinite(radius) and radius > 0):
        raise ParameterError("head radius", radius, "a positive finite number")
    axes = np.eye(3) if frame is None else np.asarray(frame, dtype=np.float64)
    if axes.shape != (3, 3) or not np.allclose(axes @ axes.T, np.eye(3)) or np.linalg.det(axes) < 0:
        raise ParameterError("frame", "matrix", "a 3×3 rotation (the scene's axes)")
    slot = duration / len(names)

    def transform(t: float) -> F64:
        if not 0.0 <= t <= duration:
            return np.eye(4)
        k = min(int(t / slot), len(names) - 1)
        m = MOTIONS[names[k]]((t - k * slot) / slot)
        # In the scene's axes: F·M·Fᵀ. Then x ↦ c + radius·M((x − c)/radius): the same
        # rotation, the translation rescaled.
        r = axes @ m[:3, :3] @ axes.T
        out = np.eye(4)
        out[:3, :3] = r
        out[:3, 3] = c - r @ c + radius * (axes @ m[:3, 3])
        return out

    return transform


def fit_head(roots: ArrayLike) -> tuple[F64, float]:
    """A head sphere (centre, radius) through a groom's roots, by linear least squares.

    Roots in one plane (a 2-D groom) give the circle in that plane. When the roots do not pin
    down a sphere (fewer than four, all on a line, or a fit larger than ten times their spread,
    as for a flat comb), the centre is their centroid and the radius half their spread.

    Parameters
    ----------
    roots : array_like
        ``(S, 3)`` root positions, finite.

    Returns
    -------
    tuple of (ndarray, float)
        The centre ``(3,)`` and the radius.
    """
    p = np.asarray(roots, dtype=np.float64).reshape(-1, 3)
    if p.shape[0] == 0 or not np.all(np.isfinite(p)):
        raise ParameterError("roots", f"{p.shape[0]} points", "at least one finite root")
    mean = p.mean(axis=0)
    q = p - mean  # centred, for conditioning
    spread = float(np.max(np.linalg.norm(q, axis=1)))
    fallback = (mean, spread / 2.0 if spread > 0 else 1.0)
    if p.shape[0] < 4 or spread == 0:
        return fallback
    sv = np.linalg.svd(q, compute_uv=False)
    if sv[1] <= 1e-9 * sv[0]:  # all on a line: no circle, no sphere
        return fallback
    # |q|² = 2 q·c + d with d = r² − |c|²; a flat axis has a zero column, so lstsq keeps c there 0.
    a = np.column_stack([2.0 * q, np.ones(len(q))])
    b = np.einsum("ij,ij->i", q, q)
    (cx, cy, cz, d), *_ = np.linalg.lstsq(a, b, rcond=1e-10)
    c = np.array([cx, cy, cz])
    r2 = d + c @ c
    if not (np.isfinite(r2) and r2 > 0) or np.sqrt(r2) > 10.0 * spread:
        return fallback
    return mean + c, float(np.sqrt(r2))


def check_transform(m: object, t: float) -> F64:
    """A head transform must be a finite rigid 4×4 (rotation + translation).

    Parameters
    ----------
    m : object
        What a motion callable returned.
    t : float
        The time asked, named in a refusal.

    Returns
    -------
    ndarray
        ``(4, 4)`` float64 (ParameterError otherwise).
    """
    a = np.asarray(m, dtype=np.float64)
    if a.shape != (4, 4) or not np.all(np.isfinite(a)):
        raise ParameterError("motion", f"value at t={t:g}", "a finite 4×4 matrix")
    r = a[:3, :3]
    if not np.allclose(r @ r.T, np.eye(3), atol=1e-5) or np.linalg.det(r) < 0:
        raise ParameterError("motion", f"value at t={t:g}", "a rigid transform (rotation, no scale)")
    return a
