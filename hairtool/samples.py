"""Procedural sample grooms, seeded and sized by parameters.

Units: the head radius is 1, a head of 10 cm: the samples' record says 0.1 m per unit, so
gravity in m/s² (:mod:`hairtool.simulate.dynamics`) and default hair widths in µm land at their
real sizes. The up axis is +y and gravity pulls toward −y, as in TressFX and most DCC scenes;
2-D grooms lie in the z = 0 plane.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from hairtool.errors import ParameterError
from hairtool.groom import Groom
from hairtool.metadata import Metadata

HEAD_RADIUS = 1.0
#: The samples' space: Y-up, one unit a tenth of a metre (the head's radius, 10 cm).
SAMPLE_METADATA = Metadata(up_axis="Y", meters_per_unit=0.1)


def _check_size(strands: int, vertices: int) -> None:
    if int(strands) != strands or not 1 <= strands <= 10_000_000:
        raise ParameterError("strands", strands, "a whole number in [1, 10000000]")
    if int(vertices) != vertices or not 2 <= vertices <= 1024:
        raise ParameterError("vertices", vertices, "a whole number in [2, 1024]")


def _grow(
    roots: np.ndarray,
    normals: np.ndarray,
    lengths: np.ndarray,
    vertices: int,
    gravity: float,
    curl: np.ndarray | None = None,
) -> np.ndarray:
    """Grow strands from roots: out along the normal, bending under gravity, kept off the head.

    ``curl``: ``(S, 2)`` amplitude and phase of a helical wiggle about the growth direction.
    """
    s_count = len(roots)
    seg = (lengths / (vertices - 1))[:, None]
    down = np.array([0.0, -1.0, 0.0])
    pts = np.empty((s_count, vertices, 3))
    pts[:, 0] = roots
    direction = normals.copy()
    for i in range(1, vertices):
        direction = direction + gravity * down
        direction /= np.linalg.norm(direction, axis=1, keepdims=True)
        p = pts[:, i - 1] + seg * direction
        # Keep the strand outside the head sphere (circle in 2-D) with a small clearance.
        r = np.linalg.norm(p, axis=1, keepdims=True)
        inside = r < HEAD_RADIUS * 1.02
        p = np.where(inside, p / np.maximum(r, 1e-9) * HEAD_RADIUS * 1.02, p)
        pts[:, i] = p
        direction = p - pts[:, i - 1]
        direction /= np.maximum(np.linalg.norm(direction, axis=1, keepdims=True), 1e-12)
    if curl is not None:
        # Helical offset perpendicular to the hanging direction, growing from root to tip.
        t = np.linspace(0.0, 1.0, vertices)[None, :]
        amp, phase = curl[:, :1], curl[:, 1:]
        angle = phase + 6.0 * np.pi * t
        radial = np.stack([np.cos(angle), np.zeros_like(angle), np.sin(angle)], axis=-1)
        pts += (amp * t)[..., None] * radial
    return pts


def _parted(normals: np.ndarray) -> np.ndarray:
    """Start directions combed away from a centre parting (x = 0), so no strand stands straight up."""
    side = np.where(normals[:, 0] >= 0.0, 1.0, -1.0)
    out = normals.copy()
    out[:, 0] += 0.6 * side
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def portrait(strands: int = 160, vertices: int = 20, seed: int = 0) -> Groom:
    """2-D strands hanging from the top of a head outline, like the frozen-hair paper's figures."""
    _check_size(strands, vertices)
    rng = np.random.default_rng(seed)
    theta = np.sort(rng.uniform(np.radians(15.0), np.radians(165.0), strands))
    normals = np.column_stack([np.cos(theta), np.sin(theta), np.zeros(strands)])
    roots = normals * HEAD_RADIUS
    lengths = 2.4 * HEAD_RADIUS * rng.uniform(0.85, 1.15, strands)
    pts = _grow(roots, _parted(normals), lengths, vertices, gravity=0.35)
    pts[..., 2] = 0.0
    return Groom(pts.reshape(-1, 3), np.full(strands, vertices), metadata=SAMPLE_METADATA)


def scalp(strands: int = 2000, vertices: int = 24, seed: int = 0) -> Groom:
    """3-D strands rooted on the upper head hemisphere, falling with gravity and a little curl."""
    _check_size(strands, vertices)
    rng = np.random.default_rng(seed)
    # Uniform on the sphere cap y >= 0.1 (area-uniform: y uniform for a sphere).
    y = rng.uniform(0.1, 1.0, strands)
    phi = rng.uniform(0.0, 2.0 * np.pi, strands)
    r = np.sqrt(1.0 - y * y)
    normals = np.column_stack([r * np.cos(phi), y, r * np.sin(phi)])
    roots = normals * HEAD_RADIUS
    lengths = 2.0 * HEAD_RADIUS * rng.uniform(0.8, 1.2, strands)
    normals = _parted(normals)
    curl = np.column_stack([rng.uniform(0.02, 0.06, strands), rng.uniform(0, 2 * np.pi, strands)])
    pts = _grow(roots, normals, lengths, vertices, gravity=0.3, curl=curl)
    return Groom(pts.reshape(-1, 3), np.full(strands, vertices), metadata=SAMPLE_METADATA)


def comb(strands: int = 100, vertices: int = 20, seed: int = 0, spacing: float = 0.05) -> Groom:
    """Straight strands hanging along −y from a square grid of roots in the y = 0 plane.

    ``seed`` jitters the roots by up to a tenth of the spacing (0 jitter for seed 0 keeps the
    grid exact, which tests rely on).
    """
    _check_size(strands, vertices)
    if not np.isfinite(spacing) or spacing <= 0:
        raise ParameterError("spacing", spacing, "a positive number")
    side = int(np.ceil(np.sqrt(strands)))
    ij = np.stack(np.divmod(np.arange(strands), side), axis=1).astype(np.float64)
    roots = np.column_stack([ij[:, 1] * spacing, np.zeros(strands), ij[:, 0] * spacing])
    if seed:
        rng = np.random.default_rng(seed)
        roots[:, [0, 2]] += rng.uniform(-0.1, 0.1, (strands, 2)) * spacing
    length = spacing * 10.0
    t = np.linspace(0.0, 1.0, vertices)
    pts = roots[:, None, :] + t[None, :, None] * np.array([0.0, -length, 0.0])
    return Groom(pts.reshape(-1, 3), np.full(strands, vertices), metadata=SAMPLE_METADATA)


SAMPLES: dict[str, Callable[..., Groom]] = {"portrait": portrait, "scalp": scalp, "comb": comb}
DEFAULT_SAMPLE = "portrait"


def sample(kind: str, strands: int | None = None, vertices: int | None = None, seed: int = 0) -> Groom:
    """Build a named sample groom; omitted sizes take each sample's defaults."""
    try:
        make = SAMPLES[kind]
    except KeyError:
        raise ParameterError("kind", kind, f"one of {', '.join(SAMPLES)}") from None
    kw: dict[str, int] = {"seed": seed}
    if strands is not None:
        kw["strands"] = strands
    if vertices is not None:
        kw["vertices"] = vertices
    return make(**kw)
