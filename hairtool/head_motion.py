"""Procedural head motions for the strand simulator: a rigid 4×4 transform per time in seconds.

Units follow :mod:`hairtool.samples`: head radius 1 at the origin, y up. Each named motion
starts and ends at the rest pose, so motions chain ("turn,nod") without jumps; all but "hop"
also start and end at rest velocity. "hop" takes off and lands abruptly: a short event that
good key frames must not miss.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

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
    return np.eye(4)


def turn(u: float) -> F64:
    """Look left then right (yaw about +y, up to about ±55°)."""
    return _about_pivot((0.0, 1.0, 0.0), np.radians(70.0) * np.sin(2 * np.pi * u) * _window(u))


def nod(u: float) -> F64:
    """Nod down then up (pitch about +x, up to about ±30°)."""
    return _about_pivot((1.0, 0.0, 0.0), np.radians(40.0) * np.sin(2 * np.pi * u) * _window(u))


def shake(u: float) -> F64:
    """Three quick shakes of the head (yaw, up to ±30°)."""
    return _about_pivot((0.0, 1.0, 0.0), np.radians(30.0) * np.sin(6 * np.pi * u) * _window(u))


def hop(u: float) -> F64:
    """Stand, jump (0.6 head radii high, airborne for the middle 60 % of the slot), land and stop."""
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
    """ "turn,nod" or ["turn", "nod"] → the checked list of names."""
    names = [s.strip() for s in spec.split(",")] if isinstance(spec, str) else [str(s).strip() for s in spec]
    if not names or any(n not in MOTIONS for n in names):
        raise ParameterError("motion", spec, f"names from {', '.join(MOTIONS)}, comma-separated")
    return names


def head_motion(spec: str | Sequence[str], duration: float) -> HeadMotion:
    """A callable t (seconds) → 4×4: the named motions play one after another, equal slots over
    ``duration``; times outside [0, duration] hold the rest pose."""
    names = parse_motion(spec)
    if not (np.isfinite(duration) and duration > 0):
        raise ParameterError("duration", duration, "a positive number of seconds")
    slot = duration / len(names)

    def transform(t: float) -> F64:
        if not 0.0 <= t <= duration:
            return np.eye(4)
        k = min(int(t / slot), len(names) - 1)
        return MOTIONS[names[k]]((t - k * slot) / slot)

    return transform


def check_transform(m: object, t: float) -> F64:
    """A head transform must be a finite rigid 4×4 (rotation + translation)."""
    a = np.asarray(m, dtype=np.float64)
    if a.shape != (4, 4) or not np.all(np.isfinite(a)):
        raise ParameterError("motion", f"value at t={t:g}", "a finite 4×4 matrix")
    r = a[:3, :3]
    if not np.allclose(r @ r.T, np.eye(3), atol=1e-5) or np.linalg.det(r) < 0:
        raise ParameterError("motion", f"value at t={t:g}", "a rigid transform (rotation, no scale)")
    return a
