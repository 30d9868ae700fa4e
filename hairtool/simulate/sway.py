"""Simple hair motion without a simulator: a head turning and nodding, strands swaying and a
short flick, for keyframe tests, benchmarks and demos (deterministic from its parameters).
"""

from __future__ import annotations

import numpy as np

from hairtool.errors import ParameterError
from hairtool.groom import Animation, Groom
from hairtool.rotation import axis_angle_matrix


def sway_animation(
    groom: Groom,
    n_frames: int = 120,
    fps: float = 24.0,
    *,
    turn: float = 0.6,
    sway: float = 0.35,
    flick_frame: int | None = None,
    flick: float = 0.8,
) -> Animation:
    """Frames of ``groom`` under rigid head motion plus a root-to-tip sway.

    The head turns about the scene's up axis by ``turn``·sin (radians) and moves sideways (all
    in the groom's axes, :attr:`hairtool.metadata.Metadata.frame`); every strand bends
    about its root by an angle growing as u² toward the tip (``sway`` radians at the tip,
    lagging behind the head), and at ``flick_frame`` a 3-frame flick of ``flick`` radians
    snaps the tips: the short, important deformation that uniform keys miss.

    Parameters
    ----------
    groom : Groom
        The hair at rest.
    n_frames : int, default 120
        Frames, ≥ 1.
    fps : float, default 24.0
        Frames per second.
    turn : float, default 0.6
        The head's turn, radians.
    sway : float, default 0.35
        The tips' sway, radians.
    flick_frame : int, optional
        Where the flick happens (None: no flick).
    flick : float, default 0.8
        The flick's angle at the tips, radians.

    Returns
    -------
    Animation
        ``n_frames`` frames at ``fps``.
    """
    if int(n_frames) != n_frames or n_frames < 1:
        raise ParameterError("n_frames", n_frames, "a whole number >= 1")
    n = int(n_frames)
    t = np.arange(n) / fps
    top = groom.topology
    frame = groom.metadata.frame
    p0 = groom.points.astype(np.float64) @ frame  # in the reference axes (y up), exactly
    roots = p0[top.root_indices][top.strand_index]
    rel = p0 - roots
    u = groom.arc_param[:, None]
    period = max(t[-1], 1.0 / fps)
    frames = np.empty((n, groom.vertex_count, 3), dtype=np.float32)
    for f in range(n):
        phase = 2.0 * np.pi * t[f] / period
        bend = sway * np.sin(phase - 0.8) + 0.15 * sway * np.sin(3.1 * phase)
        if flick_frame is not None:
            bend += flick * np.exp(-0.5 * ((f - flick_frame) / 1.0) ** 2)
        # bend about z (sideways swing), scaled root-to-tip by u²
        ang = bend * u[:, 0] ** 2
        c, s = np.cos(ang), np.sin(ang)
        bent = np.column_stack([c * rel[:, 0] - s * rel[:, 1], s * rel[:, 0] + c * rel[:, 1], rel[:, 2]])
        head = axis_angle_matrix([0.0, 1.0, 0.0], turn * np.sin(phase))
        shift = np.array([0.3 * np.sin(0.5 * phase), 0.05 * np.sin(2 * phase), 0.0])
        frames[f] = ((roots + bent) @ head.T + shift) @ frame.T
    return groom.animate(frames, fps)
