"""Grooms with uneven strands and every attribute, shared by the format tests."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.groom import Animation, Groom


def make_groom(seed: int = 0, strands: int = 23, attributes: bool = True) -> Groom:
    """Strands of 2..40 points with awkward float32 values (tiny, huge, negative zero)."""
    rng = np.random.default_rng(seed)
    counts = rng.integers(2, 41, strands)
    v = int(counts.sum())
    points = (rng.standard_normal((v, 3)) * 10.0 ** rng.integers(-8, 8, (v, 1))).astype(np.float32)
    points[0] = [-0.0, 1e-38, 3.4e38]
    points[1] = [np.nextafter(np.float32(1), np.float32(2)), 1 / 3, -7.0]
    if not attributes:
        return Groom(points, counts)
    return Groom(
        points,
        counts,
        thickness=rng.uniform(0.001, 0.1, v),
        transparency=rng.uniform(0.0, 1.0, v),
        colors=rng.uniform(0.0, 1.0, (v, 3)),
    )


def make_animation(seed: int = 0, frames: int = 5, fps: float = 30.0) -> Animation:
    g = make_groom(seed, strands=7)
    rng = np.random.default_rng(seed + 1)
    f = g.points[None] + rng.standard_normal((frames, g.vertex_count, 3)).astype(np.float32)
    return Animation(f, g.topology, fps, thickness=g.thickness, colors=g.colors)


@pytest.fixture
def groom() -> Groom:
    return make_groom()


@pytest.fixture
def animation() -> Animation:
    return make_animation()
