"""A character's hair chains as the viewport shows them: bones over the mesh, each chain a
polyline root → tip (drawn as a strand, so the ramp colours it root to tip as it does hair), and
the chain under the mouse.

The chains are few (tens of chains of a few bones), so picking projects every bone with
:meth:`Camera.project` and takes the nearest on screen, in numpy.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from app.render.camera import Camera
from hairtool.character.cycle import chain_points
from hairtool.character.model import Character
from hairtool.groom import Groom

PICK_RADIUS_PX = 8.0  # how near a click must fall to a bone to select its chain


def chain_lines(character: Character, world: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    """``(N, 3)`` world positions of each chain's nodes root → tip, for node world matrices."""
    return [chain_points(character, chain, world) for chain in character.chains]


def chains_groom(character: Character, world: NDArray[np.float64]) -> Groom:
    """The chains as a groom of one strand per chain, in the character's order."""
    return Groom.from_strands(chain_lines(character, world))


def segment_distances(points: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray:
    """``(S,)`` distance of the 2-D point ``points`` to each segment ``a[s] → b[s]`` ``(S, 2)``."""
    ab = b - a
    length2 = np.sum(ab * ab, axis=1)
    u = np.clip(np.sum((points - a) * ab, axis=1) / np.where(length2 > 0, length2, 1.0), 0.0, 1.0)
    return np.linalg.norm(a + u[:, None] * ab - points, axis=1)


def pick_chain(
    camera: Camera,
    size: tuple[int, int],
    lines: list[NDArray[np.float64]],
    xy: tuple[float, float],
    radius_px: float = PICK_RADIUS_PX,
) -> int | None:
    """The chain whose bones pass nearest the pixel ``xy`` (y down), within ``radius_px``; the
    one nearer the eye where two are as near on screen (None: no bone within reach)."""
    w, h = size
    best: tuple[float, float, int] | None = None
    click = np.asarray(xy, dtype=np.float64)[None, :]
    for c, line in enumerate(lines):
        if len(line) < 2:
            continue
        px = camera.project(line, w, h)
        d = segment_distances(click, px[:-1], px[1:])
        s = int(np.argmin(d))
        if d[s] > radius_px:
            continue
        depth = float(np.min(camera.depth(line[s : s + 2])))
        if np.isfinite(d[s]) and (best is None or (round(float(d[s]), 6), depth) < best[:2]):
            best = (round(float(d[s]), 6), depth, c)
    return None if best is None else best[2]
